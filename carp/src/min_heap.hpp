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
  /// The least item. \pre !empty()
  const T& top() const { return items_.front(); }

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

/// A MinHeap that keeps one item aside, the least pushed since the last pop that took it:
/// a search that pops the best of the successors it has just pushed (diving along equally
/// good paths, as A* does on grids) then passes that one by the heap both ways. Items come
/// out in the same order as from a MinHeap (the least first; with a strict order, the same
/// sequence).
template <class T>
class DivingMinHeap {
 public:
  bool empty() const noexcept { return !held_ && heap_.empty(); }
  void clear() noexcept {
    held_ = false;
    heap_.clear();
  }

  void push(const T& item) {
    if (!held_) {
      aside_ = item;
      held_ = true;
    } else if (aside_ > item) {
      heap_.push(aside_);
      aside_ = item;
    } else {
      heap_.push(item);
    }
  }
  /// \pre !empty()
  T pop() {
    if (held_ && (heap_.empty() || !(aside_ > heap_.top()))) {
      held_ = false;
      return aside_;
    }
    return heap_.pop();
  }

  /// As MinHeap::rebuild.
  template <class Keep, class Rekey>
  void rebuild(Keep keep, Rekey rekey) {
    if (held_ && !keep(aside_)) held_ = false;
    if (held_) rekey(aside_);
    heap_.rebuild(keep, rekey);
  }

 private:
  MinHeap<T> heap_;
  T aside_{};
  bool held_ = false;
};

}  // namespace drover::carp
