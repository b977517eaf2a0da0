#pragma once
// Helpers shared by the TimelineSet sources (timeline*.cpp). Private to the library.

#include <functional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include <boost/container/flat_set.hpp>

#include "drover/topology/timeline.hpp"

namespace drover::topology {

/// The entities an operation changed; each gets its version incremented once at the end.
/// A sorted vector: a route touches hundreds of entities, and a tree node each (allocated,
/// then freed) cost reserve a tenth of its time and scattered the heap the planner reads.
using TouchedSet = boost::container::flat_set<EntityIndex>;

struct TimelineSet::Impl {
  /// Timeline order (see Timeline::reservations).
  static bool timeline_order(const Reservation& a, const Reservation& b);
  static void sort_reservations(Timeline& timeline);
  /// Whether a change of timelines changed what their free windows read, and whether the
  /// change kept them up to date itself (`updated`: only their revision must move).
  enum class Windows { changed, updated, unchanged };
  /// Increments the version of every touched entity and, unless `windows` is unchanged,
  /// moves its windows revision, revising its free windows when they `changed` (a change of
  /// reservations changes only the windows of the timelines it touches).
  static void bump_versions(TimelineSet& set, const TouchedSet& touched,
                            Windows windows = Windows::changed);
  /// A revision number never used before in this process.
  static std::uint64_t next_revision();
  /// Revises the free windows of `entity` and of the members of its conflict set, for a
  /// change of its locks or of who holds it: their free windows read the entity's locks,
  /// and whether the reservations standing for it (real and shadows) are held.
  static void revise_around(TimelineSet& set, EntityIndex entity);
  /// Gives `entity` windows revision `revision` and recomputes what derives from its
  /// timeline (a newcomer's windows). Every change of what free windows read goes through
  /// here, after the change.
  static void revise(TimelineSet& set, EntityIndex entity, std::uint64_t revision);
  /// Revises every entity, with one fresh revision (a set made or restored).
  static void revise_all(TimelineSet& set);
  /// Removes `cut` from the windows out[base..] (sorted, disjoint), splitting one if needed.
  static void cut_window(std::vector<Interval>& out, std::size_t base, Interval cut);
  /// The same on a newcomer's windows.
  static void cut_window(NewcomerWindows& windows, Interval cut);
  /// Whether admit would accept `item` on its timeline without reading the reservations:
  /// its agent has none there (`agent_entities`: its reserved_entities) and its window lies
  /// within one of the newcomer's windows, which every reservation, holder and lock there
  /// (and the locks on the conflict set) keep clear. False says nothing.
  static bool clear_for_newcomer(const TimelineSet& set, const Reservation& item,
                                 std::span<const EntityIndex> agent_entities);
  // Who has a reservation where (reserved_entities.cpp).
  /// The number of `agent` in the index, given one if it has none yet.
  static std::uint32_t agent_number(TimelineSet& set, std::string_view agent);
  /// Records that agent number `agent` has reservations on `entities` (sorted in place).
  static void add_reservers(TimelineSet& set, std::uint32_t agent,
                            std::vector<EntityIndex>& entities);
  /// Records that `agents` (numbers, sorted in place) are those with a reservation on
  /// `entity`.
  static void set_reservers(TimelineSet& set, EntityIndex entity,
                            std::vector<std::uint32_t>& agents);
  /// Whether `entity` is among `agent_entities` (an agent's reserved_entities).
  static bool has_reservation(std::span<const EntityIndex> agent_entities, EntityIndex entity);
  /// The free-window sweep of append_free_windows; `skip(r)` leaves out reservation r.
  template <class Skip>
  static void sweep(const TimelineSet& set, EntityIndex entity, TimeNs from, TimeNs until,
                    std::vector<Interval>& out, bool count_locks, Skip skip);

  static bool in_conflict_set(const TimelineSet& set, EntityIndex origin, EntityIndex entity);
  /// True when reservations standing for origins a and b may not overlap in time if they
  /// belong to different agents (I1): a == b or a in C(b). Two reservations on one
  /// timeline x conflict exactly when their origins do: a real one (origin x) conflicts
  /// with everything on x; two shadows on x conflict only if their origins do.
  static bool origins_conflict(const TimelineSet& set, EntityIndex a, EntityIndex b);

  /// True when `r` belongs to an allocation: r's origin is owned and held by r's agent at
  /// r's route step (so r is the held real reservation or one of its shadows).
  static bool is_held(const TimelineSet& set, const Reservation& r);

  /// Removes the reservations `doomed` selects from every owned timeline; records where.
  static void remove_reservations(TimelineSet& set,
                                  const std::function<bool(const Reservation&)>& doomed,
                                  TouchedSet& touched);

  /// Every check of prepare (see its contract), for `op` ("prepare" or "reserve").
  static Status admit(const TimelineSet& set, const std::vector<Reservation>& items,
                      const std::vector<ExpectedVersion>& expected, const std::string& op);
  /// Adds admitted items to their timelines, prepared or committed; records where, and
  /// keeps their free windows up to date (bump_versions with Windows::updated after it).
  static void insert(TimelineSet& set, const std::vector<Reservation>& items, bool prepared,
                     TouchedSet& touched);

  /// Removes a prepared set and its items and grants what that made grantable (kept for
  /// take_grants). Records what changed in `touched`. \pre the set exists.
  static void drop_prepared(TimelineSet& set, PrepareId id, TouchedSet& touched);
  /// Keeps grants made by operations that do not report them, for take_grants.
  static void keep_grants(TimelineSet& set, const std::vector<Grant>& grants);

  /// The agent's first committed real reservation on the timeline, or nullptr.
  static const Reservation* first_committed_real(const Timeline& timeline,
                                                 const AgentId& agent);
  /// How many reservations of other agents start before `start` on the timeline.
  static std::size_t others_before(const Timeline& timeline, const AgentId& agent,
                                   TimeNs start);

  /// On each of `entities`: drops waiting requests whose agent has no committed real
  /// reservation left there, then grants the waiting request that has become grantable,
  /// if any (at most one can be). Records what changed in `touched`.
  /// \return the grants, by entity.
  static std::vector<Grant> grant_waiting(TimelineSet& set, const TouchedSet& entities,
                                          TouchedSet& touched);
};

}  // namespace drover::topology
