#pragma once
// A brute-force model of TimelineSet for the tests, written separately from the library:
// one flat list of every reservation, every rule checked by scanning it. Plus checkers of
// the invariants I1-I4 over snapshots of timelines, each returning the violations found.

#include <cstdint>
#include <map>
#include <ostream>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "drover/common/result.hpp"
#include "drover/topology/timeline.hpp"

namespace drover::topology {
// GoogleTest printers, so that failures show readable values.
void PrintTo(const Interval& w, std::ostream* out);
void PrintTo(const Reservation& r, std::ostream* out);
void PrintTo(const Shift& s, std::ostream* out);
void PrintTo(const Grant& g, std::ostream* out);
void PrintTo(const Timeline& t, std::ostream* out);
}  // namespace drover::topology

namespace drover::topology::reference {

/// The reservation an allocation holds (a real reservation of this route step).
struct HeldStep {
  AgentId agent;
  RouteId route = 0;
  std::uint32_t step = 0;
  friend bool operator==(const HeldStep&, const HeldStep&) = default;
};

/// Timelines as observed, plus which reservation each holder holds.
struct Snapshot {
  std::vector<std::vector<EntityIndex>> conflicts;
  std::vector<Timeline> timelines;
  std::map<EntityIndex, HeldStep> held;
};

/// Identifies a reservation across operations (windows change, keys do not).
using ReservationKey = std::tuple<EntityIndex, AgentId, RouteId, std::uint32_t, EntityIndex>;
ReservationKey key_of(const Reservation& r);

/// The model. Owns every entity; conflict sets as given (symmetric, sorted).
class ReferenceTimelines {
 public:
  explicit ReferenceTimelines(std::vector<std::vector<EntityIndex>> conflicts);

  Timeline timeline(EntityIndex entity) const;
  Snapshot snapshot() const;
  std::vector<Interval> free_windows(EntityIndex entity, const AgentId& agent, TimeNs from,
                                     TimeNs until) const;

  Result<PrepareId> prepare(const std::vector<Reservation>& items,
                            const std::vector<ExpectedVersion>& expected, TimeNs expires_at);
  Status commit(PrepareId id);
  Status abort(PrepareId id);
  std::vector<PrepareId> expire(TimeNs now);
  std::vector<Grant> take_grants();
  Status reserve(const AgentId& agent, RouteId route, const std::vector<RouteStep>& steps);
  Result<Allocation> allocate(const AgentId& agent, EntityIndex entity);
  Result<std::vector<Grant>> release(const AgentId& agent, EntityIndex entity);
  Result<std::vector<Grant>> cancel_route(const AgentId& agent, RouteId route);
  Result<DelayReport> delay(const AgentId& agent, RouteId route, EntityIndex entity,
                            DurationNs by);
  Result<LockReport> lock(EntityIndex entity, Interval window, const std::string& operator_id,
                          const std::string& reason);
  Status unlock(LockId id);

  /// Every reservation (the flat list).
  std::vector<Reservation> all() const;

 private:
  struct Item {
    Reservation reservation;
    PrepareId prepare = 0;  // 0 once committed
  };
  struct PreparedSet {
    AgentId agent;
    RouteId route = 0;
    TimeNs expires_at = 0;
  };

  /// Every check of prepare; invalid_argument, then not_found, then conflict.
  Status admit(const std::vector<Reservation>& items,
               const std::vector<ExpectedVersion>& expected) const;
  /// Adds committed reservations and grants what they make grantable (for take_grants).
  void add_committed(const std::vector<Reservation>& items);
  bool held(const Reservation& r) const;
  bool in_conflict_set(EntityIndex origin, EntityIndex entity) const;
  const Reservation* first_committed_real(const AgentId& agent, EntityIndex entity) const;
  std::size_t others_before(const AgentId& agent, EntityIndex entity, TimeNs start) const;
  std::vector<Grant> grant_everywhere();
  void drop_prepared(PrepareId id);
  /// Runs `change`, then increments the version of every timeline whose content changed.
  template <class F>
  auto versioned(F&& change);

  std::vector<std::vector<EntityIndex>> conflicts_;
  std::vector<Item> items_;
  std::vector<Lock> locks_;
  std::map<EntityIndex, HeldStep> holders_;
  std::map<EntityIndex, std::vector<AgentId>> waiting_;
  std::map<PrepareId, PreparedSet> prepared_;
  std::vector<std::uint64_t> versions_;
  std::vector<Grant> pending_grants_;
  PrepareId next_prepare_ = 1;
  LockId next_lock_ = 1;
};

// ---- invariant checkers: each returns one line per violation, empty when all hold ----

/// I1: on each timeline different agents' reservations whose origins conflict (are equal
/// or in each other's conflict set) never overlap; real reservations of different agents on
/// e and on f in C(e) never overlap; every real reservation has its
/// shadow on each member of its conflict set and every shadow its real one.
std::vector<std::string> check_exclusive(const Snapshot& s);

/// Allocations: a holder holds a committed real reservation that no other agent's
/// reservation on the entity precedes (I2); at most one agent holds among e and C(e);
/// no waiting request could be granted; a waiting agent has a committed real reservation
/// there and is not the holder.
std::vector<std::string> check_allocations(const Snapshot& s);

/// I3 for one delay of (agent, route) from `step` by `by`: the order of different agents'
/// reservations with conflicting origins on every timeline is unchanged; the delayed route's step ends `by` later and its later
/// steps moved by exactly `by`, its earlier ones not at all; the report names the delayed
/// route first and then exactly the other routes whose windows moved, with the step from
/// which and how far; hit_locks lists exactly the moved reservations that overlap a lock;
/// nothing but windows changed.
std::vector<std::string> check_delay(const Snapshot& before, const Snapshot& after,
                                     const AgentId& agent, RouteId route, std::uint32_t step,
                                     DurationNs by, const DelayReport& report);

/// I4: every reservation that overlaps a lock is excused: it was there when the lock came
/// (the lock reported it) or a delay moved it there (the delay reported it). `excused`
/// holds (reservation, lock id) pairs.
std::vector<std::string> check_locks(const Snapshot& s,
                                     const std::set<std::pair<ReservationKey, LockId>>& excused);

}  // namespace drover::topology::reference
