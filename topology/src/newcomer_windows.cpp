// TimelineSet::NewcomerWindows: an entity's agents and newcomer windows in one block.

#include <algorithm>
#include <new>

#include "drover/topology/timeline.hpp"

namespace drover::topology {

namespace {

using NewcomerWindows = TimelineSet::NewcomerWindows;
using AgentBits = TimelineSet::AgentBits;

constexpr std::align_val_t kBlockAlignment{64};

std::size_t block_bytes(std::size_t capacity) {
  return sizeof(AgentBits) + capacity * sizeof(Interval);
}

/// A block for `capacity` windows with no agents, the windows' storage uninitialised.
AgentBits* new_block(std::size_t capacity) {
  void* memory = ::operator new(block_bytes(capacity), kBlockAlignment);
  return new (memory) AgentBits{};
}

}  // namespace

// Two windows fit on the agents' cache line; each block after that takes whole lines.
static_assert(sizeof(AgentBits) + 2 * sizeof(Interval) == 64);

alignas(NewcomerWindows::kLine) const AgentBits NewcomerWindows::kNoAgents{};
const NewcomerWindows TimelineSet::kNoNewcomerWindows{};

NewcomerWindows::NewcomerWindows(const NewcomerWindows& other) {
  if (other.capacity_ == 0) return;  // the shared empty block
  reserve(other.size_);
  *block_ = *other.block_;
  std::copy_n(other.first(), other.size_, first());
  size_ = other.size_;
}

NewcomerWindows::~NewcomerWindows() {
  if (capacity_ > 0) ::operator delete(block_, kBlockAlignment);
}

void NewcomerWindows::clear() noexcept {
  size_ = 0;
  if (capacity_ > 0) *block_ = AgentBits{};
}

void NewcomerWindows::add_agent(AgentBits::Key key) {
  if (capacity_ == 0) reserve(0);
  block_->add(key);
}

void NewcomerWindows::assign(std::span<const Interval> windows) {
  // No windows need no block of their own (an entity not owned keeps the shared one).
  if (!windows.empty()) reserve(windows.size());
  std::copy(windows.begin(), windows.end(), first());
  size_ = static_cast<std::uint32_t>(windows.size());
}

void NewcomerWindows::replace(std::size_t from, std::size_t to, std::span<const Interval> pieces) {
  const std::size_t size = size_ - (to - from) + pieces.size();
  reserve(size);
  Interval* const windows = first();
  // The windows after the replaced ones move to their place behind the pieces.
  const std::size_t behind = from + pieces.size();
  if (behind > to) {
    std::copy_backward(windows + to, windows + size_, windows + size);
  } else if (behind < to) {
    std::copy(windows + to, windows + size_, windows + behind);
  }
  std::copy(pieces.begin(), pieces.end(), windows + from);
  size_ = static_cast<std::uint32_t>(size);
}

void NewcomerWindows::reserve(std::size_t capacity) {
  if (capacity_ > 0 && capacity <= capacity_) return;
  // 2, 6, 14, 30, ... windows: blocks of 1, 2, 4, 8, ... cache lines.
  std::size_t grown = 2;
  while (grown < capacity) grown = 2 * grown + 2;
  AgentBits* const block = new_block(grown);
  *block = *block_;
  std::copy_n(first(), size_, reinterpret_cast<Interval*>(block + 1));
  if (capacity_ > 0) ::operator delete(block_, kBlockAlignment);
  block_ = block;
  capacity_ = static_cast<std::uint32_t>(grown);
}

}  // namespace drover::topology
