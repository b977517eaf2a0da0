// The search's open list: DivingMinHeap, which keeps its least recent push out of the heap,
// must give the items in the very order a plain MinHeap does.

#include <cstdint>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "carp/src/min_heap.hpp"

namespace drover::carp {
namespace {

/// A key with few values (many ties, as the search's keys have) and a unique id that
/// makes the order strict, as the search's push sequence does.
struct Item {
  int key = 0;
  int id = 0;
  bool operator>(const Item& o) const { return key != o.key ? key > o.key : id > o.id; }
  bool operator==(const Item&) const = default;
};

// Pushes and pops interleaved at random, with runs of pushes that beat everything queued
// (the search diving) and of pushes that do not, and now and then a rebuild that drops some
// items and re-keys the rest (the arrival floor rising): both heaps give the same items in
// the same order, so the search expands the same states.
TEST(DivingMinHeap, PopsInTheOrderOfAPlainMinHeap) {
  std::mt19937 random(5);
  for (int trial = 0; trial < 50; ++trial) {
    MinHeap<Item> plain;
    DivingMinHeap<Item> diving;
    int next_id = 0, last_key = 0, popped = 0;
    for (int step = 0; step < 3000; ++step) {
      const unsigned roll = random() % 100;
      if (roll < 55 || plain.empty()) {
        // Below the last key popped half the time: a new least item, kept aside.
        const int key = last_key + static_cast<int>(random() % 7) - (roll % 2 == 0 ? 4 : 0);
        const Item item{key, next_id++};
        plain.push(item);
        diving.push(item);
      } else if (roll < 98) {
        ASSERT_FALSE(diving.empty());
        const Item expected = plain.pop();
        ASSERT_EQ(diving.pop(), expected) << "trial " << trial << ", step " << step;
        last_key = expected.key;
        ++popped;
      } else {
        const int floor = last_key + 2;
        const auto keep = [](const Item& item) { return item.id % 5 != 0; };
        const auto rekey = [floor](Item& item) { item.key = std::max(item.key, floor); };
        plain.rebuild(keep, rekey);
        diving.rebuild(keep, rekey);
      }
      ASSERT_EQ(diving.empty(), plain.empty()) << "trial " << trial << ", step " << step;
    }
    while (!plain.empty()) ASSERT_EQ(diving.pop(), plain.pop()) << "trial " << trial;
    EXPECT_TRUE(diving.empty());
    EXPECT_GT(popped, 1000);
  }
}

}  // namespace
}  // namespace drover::carp
