#pragma once
// Allocations granted to this agent that it did not claim through an allocate reply.

#include <chrono>
#include <functional>
#include <map>
#include <optional>
#include <utility>
#include <vector>

#include "agents/logical_agent/src/footprint_monitor.hpp"
#include "drover/topology/timeline.hpp"

namespace drover::logical_agent {

/// A queued allocation request may be granted after the agent stopped waiting for its
/// reply (NOTICE_ALLOCATION_GRANTED tells it). If the agent asks again, the reply claims
/// it; if it has moved on (a re-plan, a withdrawn order), nobody would: a route's cancel
/// keeps what is allocated, so the entity would stay held for ever and every vehicle due
/// there after it would wait. LateGrants remembers such grants and says when to give them
/// back. Not thread-safe (the executor's).
class LateGrants {
 public:
  using Clock = std::chrono::steady_clock;

  /// \param claim_within  how long a grant of the current route may wait for its claim.
  explicit LateGrants(Clock::duration claim_within) : claim_within_(claim_within) {}

  /// A grant of `entity` as `step` was notified at `now` (a later notice replaces it).
  void granted(topology::EntityIndex entity, HeldStep step, Clock::time_point now);

  /// The grants to give back now, which are forgotten: those of another route than
  /// `current` (or of any route when there is none), and those of `current` not claimed
  /// within claim_within. Grants `claimed` says the agent holds are forgotten, not returned.
  std::vector<std::pair<topology::EntityIndex, HeldStep>> to_release(
      const std::function<bool(topology::EntityIndex)>& claimed, std::optional<topology::RouteId> current,
      Clock::time_point now);

  bool empty() const noexcept { return grants_.empty(); }

 private:
  struct Grant {
    HeldStep step;
    Clock::time_point at;
  };
  Clock::duration claim_within_;
  std::map<topology::EntityIndex, Grant> grants_;
};

}  // namespace drover::logical_agent
