#pragma once
// A deterministic stream of random TimelineSet operations, for tests that need sets in
// realistic, busy states (persistence and restore): routes planned into free windows,
// prepares left open, committed, aborted or expired, allocations queued and granted,
// releases, cancels, delays, locks and unlocks; on a partition also the shadows that
// neighbours' routes write on it. The same seed applied to equal sets gives equal
// operations, so a test can replay a stream (a copy of the workload continues it).

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "drover/topology/timeline.hpp"

namespace drover::topology::test {

/// Random symmetric conflict sets (sorted) over `count` entities.
std::vector<std::vector<EntityIndex>> random_conflicts(std::uint64_t seed, std::size_t count,
                                                       double density);

class TimelineWorkload {
 public:
  /// \param conflicts, owned  those of the sets it will be applied to
  /// \param queue  whether allocation requests may queue; without, an agent asks only when
  ///               it would be granted, so no request ever waits
  TimelineWorkload(std::uint64_t seed, std::vector<std::vector<EntityIndex>> conflicts,
                   std::vector<bool> owned = {}, bool queue = true);

  /// Applies one operation to `set` and takes the grants it made (so none stay pending).
  /// \return what it did, for failure messages.
  std::string apply(TimelineSet& set);

 private:
  TimeNs uniform(TimeNs low, TimeNs high) {
    return std::uniform_int_distribution<TimeNs>(low, high)(rng_);
  }
  bool chance(double p) { return std::bernoulli_distribution(p)(rng_); }
  EntityIndex owned_entity();
  EntityIndex any_entity();
  /// Some reservation on an owned timeline, or nullptr when there is none.
  const Reservation* some_reservation(const TimelineSet& set);
  std::vector<RouteStep> plan(const TimelineSet& set, const AgentId& agent, bool owned_only);

  std::string reserve(TimelineSet& set);
  std::string prepare(TimelineSet& set, bool neighbour);
  std::string finish_prepare(TimelineSet& set);
  std::string allocate(TimelineSet& set);
  std::string release(TimelineSet& set);
  std::string cancel(TimelineSet& set);
  std::string delay(TimelineSet& set);
  std::string lock(TimelineSet& set);
  std::string unlock(TimelineSet& set);

  std::mt19937_64 rng_;
  std::vector<std::vector<EntityIndex>> conflicts_;
  std::vector<EntityIndex> owned_;  // the owned entities
  bool queue_ = true;
  std::vector<AgentId> agents_{"amy", "bob", "cat"};
  RouteId next_route_ = 1;
  std::vector<PrepareId> open_prepares_;
  std::vector<LockId> locks_;
};

}  // namespace drover::topology::test
