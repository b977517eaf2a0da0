// TimelineSet::NewcomerWindows: an entity's newcomer windows in blocks of whole cache lines.

#include <algorithm>
#include <new>

#include "drover/topology/timeline.hpp"

namespace drover::topology {

namespace {

using NewcomerWindows = TimelineSet::NewcomerWindows;

constexpr std::size_t kLine = 64;
constexpr std::align_val_t kBlockAlignment{kLine};
static_assert(kLine % sizeof(Interval) == 0);

}  // namespace

const NewcomerWindows TimelineSet::kNoNewcomerWindows{};

NewcomerWindows::NewcomerWindows(const NewcomerWindows& other) { assign(other.windows()); }

NewcomerWindows::~NewcomerWindows() {
  if (capacity_ > 0) ::operator delete(windows_, kBlockAlignment);
}

void NewcomerWindows::assign(std::span<const Interval> windows) {
  // No windows need no block (an entity not owned has none).
  if (!windows.empty()) reserve(windows.size());
  std::copy(windows.begin(), windows.end(), windows_);
  size_ = static_cast<std::uint32_t>(windows.size());
}

void NewcomerWindows::replace(std::size_t from, std::size_t to, std::span<const Interval> pieces) {
  const std::size_t size = size_ - (to - from) + pieces.size();
  reserve(size);
  // The windows after the replaced ones move to their place behind the pieces.
  const std::size_t behind = from + pieces.size();
  if (behind > to) {
    std::copy_backward(windows_ + to, windows_ + size_, windows_ + size);
  } else if (behind < to) {
    std::copy(windows_ + to, windows_ + size_, windows_ + behind);
  }
  std::copy(pieces.begin(), pieces.end(), windows_ + from);
  size_ = static_cast<std::uint32_t>(size);
}

void NewcomerWindows::reserve(std::size_t capacity) {
  if (capacity <= capacity_) return;
  // 4, 8, 16, ... windows: blocks of 1, 2, 4, ... cache lines.
  std::size_t grown = kLine / sizeof(Interval);
  while (grown < capacity) grown *= 2;
  auto* const windows =
      static_cast<Interval*>(::operator new(grown * sizeof(Interval), kBlockAlignment));
  std::copy_n(windows_, size_, windows);
  if (capacity_ > 0) ::operator delete(windows_, kBlockAlignment);
  windows_ = windows;
  capacity_ = static_cast<std::uint32_t>(grown);
}

}  // namespace drover::topology
