#pragma once
// A binary min-heap over a reused vector: clear() keeps the capacity, so a search that
// reuses one allocates nothing once it has grown. T needs `bool operator>(const T&)`.

#include <algorithm>
#include <functional>
#include <vector>

namespace drover::carp {

template <class T>
class MinHeap {
 public:
  bool empty() const noexcept { return items_.empty(); }
  std::size_t size() const noexcept { return items_.size(); }
  void clear() noexcept { items_.clear(); }

  void push(const T& item) {
    items_.push_back(item);
    std::push_heap(items_.begin(), items_.end(), std::greater<T>{});
  }
  /// \pre !empty()
  T pop() {
    std::pop_heap(items_.begin(), items_.end(), std::greater<T>{});
    T top = items_.back();
    items_.pop_back();
    return top;
  }

  /// Re-keys every item with `rekey(T&)` and restores the heap order; `keep(const T&)`
  /// drops the items it rejects first.
  template <class Keep, class Rekey>
  void rebuild(Keep keep, Rekey rekey) {
    std::erase_if(items_, [&keep](const T& item) { return !keep(item); });
    for (T& item : items_) rekey(item);
    std::make_heap(items_.begin(), items_.end(), std::greater<T>{});
  }

 private:
  std::vector<T> items_;
};

}  // namespace drover::carp
