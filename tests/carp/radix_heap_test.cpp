// The radix heap of the heuristic's backward searches: a monotone min-priority queue.

#include <cstdint>
#include <queue>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "carp/src/radix_heap.hpp"

namespace drover::carp {
namespace {

// Interleaved pushes and pops as Dijkstra makes them (every key pushed at least the last one
// popped), against a binary heap: the same keys come out in the same order, every value
// exactly once. Key spreads from equal keys (the unit grid) to the whole 64-bit range.
TEST(RadixHeap, PopsMonotoneKeysInOrderLikeABinaryHeap) {
  std::mt19937_64 random(7);
  for (const std::uint64_t spread : {std::uint64_t{0}, std::uint64_t{1}, std::uint64_t{3},
                                     std::uint64_t{1000000000}, std::uint64_t{1} << 50}) {
    for (int trial = 0; trial < 20; ++trial) {
      RadixHeap<int> heap;
      using Entry = std::pair<std::uint64_t, int>;
      std::priority_queue<Entry, std::vector<Entry>, std::greater<>> reference;
      std::vector<int> seen(2000, 0);
      int pushed = 0;
      std::uint64_t last = trial == 0 ? 0 : random() >> 4;  // also far from 0
      if (last > 0) {  // the first key sets where the heap starts
        heap.push(last, pushed);
        reference.push({last, pushed++});
      }
      while (pushed < 2000 || !reference.empty()) {
        const bool push = pushed < 2000 && (reference.empty() || random() % 3 != 0);
        if (push) {
          const std::uint64_t key = last + (spread == 0 ? 0 : random() % (spread + 1));
          heap.push(key, pushed);
          reference.push({key, pushed++});
          continue;
        }
        ASSERT_FALSE(heap.empty());
        ASSERT_EQ(heap.size(), reference.size());
        const auto item = heap.pop();
        ASSERT_EQ(item.key, reference.top().first) << "spread " << spread << ", trial " << trial;
        reference.pop();
        ASSERT_LE(last, item.key);
        last = item.key;
        EXPECT_EQ(heap.floor(), last);
        ++seen.at(static_cast<std::size_t>(item.value));
      }
      EXPECT_TRUE(heap.empty());
      for (const int count : seen) ASSERT_EQ(count, 1);
      heap.clear();
      EXPECT_EQ(heap.floor(), 0u);
    }
  }
}

}  // namespace
}  // namespace drover::carp
