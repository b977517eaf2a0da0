#pragma once
// Reservation timelines: per entity, who may be there when (reservations, with shadows on
// the conflict set), when nobody may (locks), who is there now (allocation) and who waits.
//
// TimelineSet keeps the invariants of shared/DESIGN.md after every operation:
//  I1 exclusive   reservations of different agents whose origins conflict (are equal or
//                 in each other's conflict set) never overlap; as reserving e writes
//                 shadow reservations on every f in C(e), each timeline is enough to check
//                 this: on timeline x a real reservation conflicts with every other one,
//                 two shadows only if their origins conflict (shadows of two entities
//                 that do not conflict may overlap). At most one agent holds an
//                 allocation among e and C(e).
//  I2 order       an agent is granted e only when no other agent's reservation (real or
//                 shadow) on e precedes its own; waiting agents learn their queue position.
//  I3 delay keeps order   a delay shifts the agent's remaining reservations and, where
//                 they run into later conflicting reservations of others, those too,
//                 transitively; the order of conflicting reservations on every timeline is
//                 unchanged; every agent moved is reported.
//  I4 locks       a lock blocks new reservations on its entity (and, through shadows and
//                 free-window queries, on its conflict set) during its interval; owners of
//                 reservations it hits are reported; allocations are never revoked by it.
//  atomic         an operation that returns an error has changed nothing.
//
// No DDS here: a topology agent wraps one TimelineSet (the entities it owns) and the
// routing agent keeps a replica for planning.

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "drover/common/clock.hpp"
#include "drover/common/result.hpp"
#include "drover/topology/model.hpp"

namespace drover::topology {

using AgentId = std::string;
/// Identifies a route of one agent; (agent, route) is unique.
using RouteId = std::uint64_t;
using LockId = std::uint64_t;
/// Identifies a prepared (held, not yet committed) reservation set.
using PrepareId = std::uint64_t;

/// Half-open time interval [start, end); end may be kForever. Valid when start < end.
struct Interval {
  TimeNs start = 0;
  TimeNs end = 0;

  bool valid() const noexcept { return start < end; }
  bool overlaps(const Interval& other) const noexcept {
    return start < other.end && other.start < end;
  }
  bool contains(TimeNs t) const noexcept { return start <= t && t < end; }
  friend bool operator==(const Interval&, const Interval&) = default;
};

/// A step of a route: the agent may occupy `entity` during `window`.
struct RouteStep {
  EntityIndex entity = kNoEntity;
  Interval window;
  friend bool operator==(const RouteStep&, const RouteStep&) = default;
};

/// One entry of an entity's timeline. A real reservation has origin == entity; a shadow
/// reservation sits on a member of the origin's conflict set, with the origin's window.
struct Reservation {
  AgentId agent;
  RouteId route = 0;
  std::uint32_t step = 0;      ///< index of the route step it belongs to
  EntityIndex entity = kNoEntity;  ///< the timeline it is on
  EntityIndex origin = kNoEntity;  ///< the entity the route step reserved
  Interval window;
  bool prepared = false;       ///< held by an uncommitted prepare (blocks others all the same)

  bool shadow() const noexcept { return origin != entity; }
  friend bool operator==(const Reservation&, const Reservation&) = default;
};

struct Lock {
  LockId id = 0;
  EntityIndex entity = kNoEntity;
  Interval window;
  std::string operator_id;
  std::string reason;
  friend bool operator==(const Lock&, const Lock&) = default;
};

/// Everything about one entity, as published to observers.
struct Timeline {
  std::uint64_t version = 0;            ///< incremented by every change of this timeline
  /// sorted by window.start; ties (only an agent's own items) by end, agent, route,
  /// step, origin
  std::vector<Reservation> reservations;
  std::vector<Lock> locks;              ///< sorted by window.start, then id
  std::optional<AgentId> holder;        ///< the agent allocated this entity, if any
  std::vector<AgentId> waiting;         ///< agents whose allocation requests wait, in order

  friend bool operator==(const Timeline&, const Timeline&) = default;
};

/// Which reservation an allocation holds: the holder's real reservation of this route step
/// on the entity (its first committed one there when it was granted) and the step's shadows
/// on the conflict set. Nobody may be placed before them; release removes them.
struct AllocatedStep {
  RouteId route = 0;
  std::uint32_t step = 0;
  friend bool operator==(const AllocatedStep&, const AllocatedStep&) = default;
};

/// What one agent has in a set (TimelineSet::holdings_of).
struct AgentHoldings {
  std::vector<std::pair<EntityIndex, AllocatedStep>> held;  ///< owned entities it holds, ascending
  std::vector<RouteId> routes;                               ///< routes it has items of, ascending
  friend bool operator==(const AgentHoldings&, const AgentHoldings&) = default;
};

/// Outcome of an allocation request.
struct Allocation {
  bool granted = false;
  /// 0 when granted; otherwise the number of other agents' reservations on the entity
  /// that come before the requester's (its place in the queue, 1-based).
  std::size_t queue_position = 0;
};

/// An allocation that became possible because of a release or cancel: the topology agent
/// answers the waiting request with it.
struct Grant {
  AgentId agent;
  EntityIndex entity = kNoEntity;
  friend bool operator==(const Grant&, const Grant&) = default;
};

/// An agent whose reservations a delay moved.
struct Shift {
  AgentId agent;
  RouteId route = 0;
  std::uint32_t from_step = 0;  ///< first step whose window moved
  DurationNs by = 0;            ///< how far it moved
  friend bool operator==(const Shift&, const Shift&) = default;
};

struct DelayReport {
  /// The delayed route first, then every route pushed by it, by (agent, route). A pushed
  /// route waits longer at its step from_step and arrives later from there on; `by` is how
  /// far its last step moved (its largest shift).
  std::vector<Shift> shifts;
  /// Reservations that moved and now overlap a lock on their timeline (their owners must
  /// re-plan), with their new windows, by entity then in timeline order.
  std::vector<Reservation> hit_locks;
};

struct LockReport {
  LockId id = 0;
  std::vector<Reservation> hit;  ///< reservations (real or shadow) the lock overlaps, in timeline order
};

/// An entity version a plan was made against; prepare fails with `conflict` if it moved.
struct ExpectedVersion {
  EntityIndex entity = kNoEntity;
  std::uint64_t version = 0;
};

/// The allocation an entity's holder holds, as a snapshot records it.
struct Holding {
  AgentId agent;
  AllocatedStep step;
  friend bool operator==(const Holding&, const Holding&) = default;
};

/// What of one entity survives a restart of its topology agent: the committed
/// reservations (real and shadow), the locks and the allocation. Prepared holds and waiting
/// allocation requests are left out: a restart aborts them (presumed abort; their
/// requesters time out and ask again).
struct EntitySnapshot {
  EntityIndex entity = kNoEntity;
  /// The timeline's version; one more than the live one when the snapshot left out
  /// prepared holds or waiting requests (dropping them is a change of the timeline).
  std::uint64_t version = 0;
  std::vector<Reservation> reservations;  ///< committed only, in timeline order
  std::vector<Lock> locks;                ///< in timeline order
  std::optional<Holding> holding;         ///< the holder and the step it holds
  friend bool operator==(const EntitySnapshot&, const EntitySnapshot&) = default;
};

/// The committed state of some owned entities of a TimelineSet plus its id counters: what
/// a topology agent journals after each operation and restores from on restart.
struct TimelineSnapshot {
  std::vector<EntitySnapshot> entities;  ///< ascending by entity
  LockId next_lock_id = 1;               ///< the id the next lock gets
  PrepareId next_prepare_id = 1;         ///< the id the next prepare gets (never reused)
  friend bool operator==(const TimelineSnapshot&, const TimelineSnapshot&) = default;
};

/// The timelines of a set of entities (all of a topology, or one partition's).
class TimelineSet {
  struct Impl;  // the helpers shared by the timeline sources (src/timeline_impl.hpp)

 public:
  /// \param conflict_sets  C(e) for every entity index (Topology::conflict_sets()); must be
  ///                       symmetric. Out-of-range indices and e itself are ignored.
  /// \param owned          which entities this set manages; empty means all, entities past
  ///                       its end are not owned. Operations on an entity not owned fail
  ///                       with not_found; shadows on entities not owned are their owner's.
  explicit TimelineSet(std::vector<std::vector<EntityIndex>> conflict_sets,
                       std::vector<bool> owned = {});

  /// Equal when every timeline, prepared set, lock and id counter is (a rejected operation
  /// leaves the set equal to a copy taken before it).
  friend bool operator==(const TimelineSet&, const TimelineSet&) = default;

  std::size_t entity_count() const noexcept;
  bool owns(EntityIndex entity) const noexcept;
  /// Whether the set owns every entity (a replica of the whole topology, as a planner
  /// needs). Constant time.
  bool owns_all() const noexcept { return owns_all_; }
  /// How many locks the set holds, over all its timelines (all owned: lock, restore and
  /// replace_timeline take locks on owned entities only). Constant time.
  std::size_t lock_count() const noexcept;
  /// \pre owns(entity)
  const Timeline& timeline(EntityIndex entity) const;
  /// The entity's version (0 for an entity out of range).
  std::uint64_t version(EntityIndex entity) const;

  /// The reservations (real and shadow) a route writes: one real per step, plus a shadow
  /// on every f in C(step.entity). Pure; used by routing agents to split a route by owner.
  std::vector<Reservation> expand(const AgentId& agent, RouteId route,
                                  const std::vector<RouteStep>& steps) const;

  /// Windows within [from, until) in which `agent` could occupy `entity`: free of other
  /// agents' reservations on its timeline, of everything up to the end of such a
  /// reservation that is allocated (nobody may come before a holder), and of locks on the
  /// entity and on the owned members of C(entity). Sorted, disjoint, maximal. The agent's
  /// own reservations never block it. A step whose window lies in one of these windows is
  /// accepted by prepare (versions aside), as far as the owned entities go, provided every
  /// route on the timelines was written as expand() splits it (so a reservation on a
  /// member of C(entity) whose origin conflicts with `entity` has its twin, real or
  /// shadow, on the entity's own timeline). Empty for an entity not owned.
  std::vector<Interval> free_windows(EntityIndex entity, const AgentId& agent, TimeNs from,
                                     TimeNs until) const;

  /// The windows free_windows(entity, agent, from, until) returns, appended to `out`
  /// instead of returned, so a planner reusing `out` allocates nothing once it is large
  /// enough. With count_locks false, locks are ignored (a planner asks whether a route
  /// would exist without them, to explain a failure). Nothing is appended for an entity
  /// not owned. Implemented in timeline_query.cpp.
  void append_free_windows(EntityIndex entity, std::string_view agent, TimeNs from,
                           TimeNs until, std::vector<Interval>& out,
                           bool count_locks = true) const;
  /// The windows of an agent with no reservation on an entity (every reservation there
  /// blocks) from the beginning of time: append_free_windows(entity, agent, from, kForever,
  /// out) appends those that end after `from`, the first starting at `from` at the
  /// earliest. They are an agent's windows unless the entity is among its
  /// reserved_entities.
  ///
  /// Laid out for a planner, which reads them for every entity it touches, mostly missing
  /// the cache: the windows of an entity fill a block aligned to a cache line, four to a
  /// line (bench plan, random-32-32-20: half the entities have at most three windows).
  /// Only a pointer and the count live in the set's array, which stays in cache. Changed
  /// by the set only.
  class NewcomerWindows {
   public:
    NewcomerWindows() noexcept = default;
    NewcomerWindows(const NewcomerWindows& other);
    NewcomerWindows(NewcomerWindows&& other) noexcept { swap(other); }
    NewcomerWindows& operator=(NewcomerWindows other) noexcept {
      swap(other);
      return *this;
    }
    ~NewcomerWindows();

    /// The windows, sorted and disjoint, the first starting before any time asked for.
    std::span<const Interval> windows() const noexcept { return {windows_, size_}; }

   private:
    friend struct TimelineSet::Impl;
    void swap(NewcomerWindows& other) noexcept {
      std::swap(windows_, other.windows_);
      std::swap(size_, other.size_);
      std::swap(capacity_, other.capacity_);
    }
    void clear() noexcept { size_ = 0; }
    void assign(std::span<const Interval> windows);
    /// Replaces windows [first, last) by `pieces`.
    void replace(std::size_t first, std::size_t last, std::span<const Interval> pieces);
    /// Makes room for `capacity` windows, keeping the windows.
    void reserve(std::size_t capacity);

    // capacity_ windows, in whole cache lines (none while capacity_ is 0).
    Interval* windows_ = nullptr;
    std::uint32_t size_ = 0;
    std::uint32_t capacity_ = 0;
  };
  /// \return those of `entity`, kept by the set (recomputed whenever the entity's windows
  ///         revision moves): valid until the set changes. Empty for an entity not owned.
  ///         Inline: a planner asks for every entity it reads.
  const NewcomerWindows& newcomer_windows(EntityIndex entity) const noexcept {
    return entity < newcomers_.of.size() ? newcomers_.of[entity] : kNoNewcomerWindows;
  }
  /// The entities on whose timelines `agent` has a reservation (real or shadow, prepared
  /// or committed), sorted: where its free windows may differ from newcomer_windows.
  /// Exact, kept with the newcomer windows, so that a planner can tell the entities whose
  /// views it may read once per search instead of once per read. Valid until the set
  /// changes; empty for an agent with none.
  std::span<const EntityIndex> reserved_entities(std::string_view agent) const noexcept;
  /// Changes, to a value never returned before in this process for any set, whenever the
  /// free windows of `entity` may change (its timeline, a lock on its conflict set, an
  /// allocation of a reservation's origin). Equal revisions of an entity, on this set or
  /// on a copy of it, mean equal free windows: a planner may keep windows between plans.
  std::uint64_t windows_revision(EntityIndex entity) const noexcept;
  /// Holds `items` (from expand) for one route, all or nothing: fails with conflict if any
  /// overlaps a lock or another agent's reservation whose origin conflicts with the
  /// item's (I1), or if an expected version moved;
  /// invalid_argument for an empty set, a bad window or mixed agents/routes; not_found for
  /// an entity not owned. Held items block others until commit, abort or expiry.
  /// Also conflict: an item that would come before another agent's allocated reservation
  /// with a conflicting origin on its timeline (a holder is never overtaken), or a step of the route that already
  /// has reservations here. invalid_argument too: an empty agent id, a shadow that is not
  /// on a member of its origin's conflict set, items of one step with different origins
  /// or windows, the same item twice. Checks run in that order of codes: every
  /// invalid_argument first, then not_found, then invalid_argument for a step without all
  /// the items expand() writes on owned entities (the real item where its entity is owned,
  /// a shadow on every owned member of its conflict set), then conflict.
  Result<PrepareId> prepare(const std::vector<Reservation>& items,
                            const std::vector<ExpectedVersion>& expected, TimeNs expires_at);
  /// Makes a prepared set permanent. not_found if it was aborted or expired. Waiting
  /// requests this makes grantable are granted (see take_grants).
  Status commit(PrepareId id);
  /// Drops a prepared set. not_found if unknown. Waiting requests this makes grantable are
  /// granted (see take_grants).
  Status abort(PrepareId id);
  /// Drops every prepared set whose expiry is <= now (presumed abort); returns their ids,
  /// ascending. Waiting requests this makes grantable are granted (see take_grants).
  std::vector<PrepareId> expire(TimeNs now);

  /// Rules of the set's owner beyond reservation order (no clock here: locks in force now,
  /// say): a waiting request is granted only where `may_grant(agent, entity)` is true; one
  /// refused stays queued (the agent asks again). Empty: every grantable request is granted.
  using GrantFilter = std::function<bool(const AgentId& agent, EntityIndex entity)>;
  void set_grant_filter(GrantFilter may_grant) { grant_filter_.may_grant = std::move(may_grant); }

  /// The grants that commit, abort and expire made since the last call, in the order they
  /// were made. (Aborting or expiring frees held items a waiting request may queue behind;
  /// committing may put a waiting agent's new reservation before everyone else's. These
  /// operations report no grants themselves.)
  std::vector<Grant> take_grants();

  /// prepare + commit in one step, of the items expand() writes on owned entities. Every
  /// step's entity must be owned (not_found); invalid_argument for no steps, an empty agent
  /// id or a bad window. Grants as commit does (see take_grants).
  Status reserve(const AgentId& agent, RouteId route, const std::vector<RouteStep>& steps);

  /// Asks for the allocation of `entity`, where the agent must hold a committed real
  /// reservation. Granted when no other agent's reservation on the entity precedes the
  /// agent's first one; otherwise queued (answered later through a Grant).
  /// Asking again while queued or holding is harmless and reports the current state.
  /// not_found if the entity is not owned or the agent has no committed real reservation
  /// on it; invalid_argument for an empty agent id.
  Result<Allocation> allocate(const AgentId& agent, EntityIndex entity);

  /// The route step the holder of `entity` holds; nullopt when nobody holds it (or the
  /// entity is not owned). Timeline::holder names the agent.
  std::optional<AllocatedStep> allocated_step(EntityIndex entity) const;

  /// What `agent` has here: the owned entities it holds with the step each allocation
  /// holds, and every route it has reservations of on owned entities (real or shadow,
  /// committed or prepared). Empty for an agent without any.
  AgentHoldings holdings_of(const AgentId& agent) const;

  /// Gives up the allocation of `entity`: removes the agent's allocated reservation there
  /// and its shadows. not_permitted if the agent does not hold it.
  /// \return the waiting requests that this made grantable (now granted), by entity.
  Result<std::vector<Grant>> release(const AgentId& agent, EntityIndex entity);

  /// For a partition that does not own `origin`: after its owner released the agent's
  /// allocation of (route, step) there, removes that step's shadows from the owned
  /// members of C(origin). Removing nothing is no error (a repeated request).
  /// \return the waiting requests that this made grantable (now granted); not_permitted
  ///         when `origin` is owned here (use release).
  Result<std::vector<Grant>> release_shadows(const AgentId& agent, RouteId route, std::uint32_t step,
                                             EntityIndex origin);

  /// Removes every reservation of (agent, route) that is not allocated, with shadows, also
  /// held (prepared) ones, whose prepared sets are dropped; withdraws the agent's waiting
  /// requests where no committed reservation of it is left. `held_steps`: steps of the
  /// route the agent holds in another partition (its vehicle stands there); their shadows
  /// here stay until release_shadows, so that a conflicting entity across the border stays
  /// guarded. not_found if the route has nothing here.
  /// \return the waiting requests this made grantable (now granted), by entity.
  Result<std::vector<Grant>> cancel_route(const AgentId& agent, RouteId route,
                                          const std::vector<std::uint32_t>& held_steps = {});

  /// Delay of `by` (> 0) for `agent`'s route from its step on `entity` on: that step's
  /// window ends `by` later and the later steps move by `by`; every later reservation of
  /// another agent they run into moves as far as needed, transitively (I3). Open ends stay
  /// open. Only reservations whose origins conflict push each other (as in I1).
  /// not_found if the agent has no reservation of the route on the entity.
  /// The step is the route's real reservation on `entity`, else its shadow there (the
  /// owner of a neighbour's shadows delays them this way). A pushed route's step that
  /// would start before its blocker ends starts when it ends: the route waits that much
  /// longer at the previous step (its first step moves whole) and moves on from there,
  /// each route by no more than needed. Allocations and waiting requests are unchanged
  /// (the order of conflicting reservations on every timeline is). invalid_argument if a
  /// time would pass kForever.
  Result<DelayReport> delay(const AgentId& agent, RouteId route, EntityIndex entity,
                            DurationNs by);

  /// Locks `entity` during `window`. invalid_argument for a bad window (empty, reversed, or
  /// beyond [0, kLatestTime] but for an end of kForever) or empty operator,
  /// not_found for an entity not owned. Reservations already there stay (see LockReport).
  Result<LockReport> lock(EntityIndex entity, Interval window, std::string operator_id,
                          std::string reason);
  /// Removes a lock. not_found if unknown.
  Status unlock(LockId id);

  // ---- replicas (timeline_replica.cpp) ----

  /// For a replica (a routing agent mirroring the timelines its topology agents publish):
  /// sets the owned entity's timeline to the one its owner published, version included.
  /// The holder, if any, is taken to hold its first committed real reservation there (the
  /// one allocate grants). Nothing else is checked: the owner enforces the invariants and
  /// checks every prepare against the versions the replica had. Held (prepared) items
  /// block others like any reservation but make no prepared set here.
  /// \return not_found for an entity not owned.
  Status replace_timeline(EntityIndex entity, Timeline timeline);

  /// For a replica assembled from several partitions' timelines: sets the window of every
  /// copy of a route step (its real reservation and its shadows, published by different
  /// owners) to the hull of all its copies here, keeping each timeline sorted. The copies
  /// of one step drift apart while a delay travels from one partition to the next; a route
  /// planned in the gap between them would come after the step on one entity and before
  /// it on a conflicting one, and the allocation order (I2) would deadlock both vehicles.
  /// Planned on the hulls, a new route comes before or after each step everywhere alike.
  /// Versions are kept (prepares are checked against the published ones); the windows
  /// revisions of widened entities change.
  void widen_to_step_hulls();

  // ---- persistence (timeline_snapshot.cpp) ----

  /// The committed state of every owned entity that is not empty at version 0 (see
  /// EntitySnapshot), and the id counters. Restoring it rebuilds this set as it would be
  /// after a restart: the same except that nothing is prepared and nobody waits.
  TimelineSnapshot snapshot() const;
  /// The same for `entities` only (those an operation changed, for a journal); entities
  /// not owned are skipped, duplicates taken once.
  TimelineSnapshot snapshot(const std::vector<EntityIndex>& entities) const;

  /// Rebuilds a set from a snapshot of it: the owned entities the snapshot names get its
  /// state, the others are empty at version 0; nothing is prepared, nobody waits.
  /// restore(c, o, set.snapshot()).snapshot() == set.snapshot().
  /// \param conflict_sets, owned  as for the constructor (the same topology and partition
  ///                              the snapshot was taken of)
  /// \return invalid_argument naming the entity and the item when the snapshot is
  ///         inconsistent: an entity out of range, not owned or given twice; a reservation
  ///         that is prepared, has an empty agent or window, sits on another timeline, is a
  ///         shadow of an entity it does not conflict with, repeats its step, or overlaps
  ///         another agent's with a conflicting origin (I1); a real reservation without its shadow on an owned member
  ///         of its conflict set, or a shadow without its real reservation on an owned
  ///         origin (same window); a holder without its committed real reservation, with
  ///         another agent's reservation before it (I2), or next to another agent holding
  ///         a conflicting entity; a lock that is malformed, on another timeline, repeats
  ///         an id or has an id not below next_lock_id; a counter of 0.
  static Result<TimelineSet> restore(std::vector<std::vector<EntityIndex>> conflict_sets,
                                     std::vector<bool> owned, const TimelineSnapshot& snapshot);

 private:
  /// Names one reservation of the set within a prepared set's (agent, route). Prepared
  /// sets remember keys, not copies, because a delay may move held items before commit.
  struct ItemKey {
    EntityIndex entity = kNoEntity;
    std::uint32_t step = 0;
    EntityIndex origin = kNoEntity;
    friend bool operator==(const ItemKey&, const ItemKey&) = default;
  };
  struct PreparedSet {
    AgentId agent;
    RouteId route = 0;
    TimeNs expires_at = 0;
    std::vector<ItemKey> items;
    friend bool operator==(const PreparedSet&, const PreparedSet&) = default;
  };
  std::vector<std::vector<EntityIndex>> conflict_sets_;
  std::vector<bool> owned_;                       // one flag per entity
  bool owns_all_ = true;                          // every flag of owned_ is set
  std::vector<Timeline> timelines_;
  std::vector<std::optional<AllocatedStep>> held_;  // per entity; set iff its holder is
  std::map<PrepareId, PreparedSet> prepared_;
  std::map<LockId, EntityIndex> lock_entities_;   // where each lock lives
  // Locks on all timelines (a replica's too): without any, a free-window query need not
  // look at the conflict set's timelines, the dearest part of it (one cache miss each).
  std::size_t lock_count_ = 0;
  // Per entity, see windows_revision. Not part of the state: equal sets may differ in it.
  struct Revisions {
    std::vector<std::uint64_t> of;
    friend bool operator==(const Revisions&, const Revisions&) { return true; }
  };
  Revisions revisions_;
  // What newcomer_windows gives for an entity out of range: none. Not a local static of
  // it, whose guard every call would test.
  static const NewcomerWindows kNoNewcomerWindows;
  // Per entity, see newcomer_windows: recomputed whenever its windows revision moves
  // (every change of what free windows read moves it), in the pass that moves it. Planners
  // read them for every entity they touch, and sweeping the reservations then was
  // memory-bound (bench plan: a fifth of the planner's time, most of it cache misses on
  // reservations and holders). Empty for entities not owned. Derived: equal sets may
  // differ in it.
  struct Newcomers {
    std::vector<NewcomerWindows> of;
    std::vector<Interval> scratch;  // a sweep's windows, before they are stored
    // Who has a reservation where (see reserved_entities), kept with the windows: agents
    // by number, in the order first seen.
    struct AgentHash {
      using is_transparent = void;
      std::size_t operator()(std::string_view agent) const noexcept {
        return std::hash<std::string_view>{}(agent);
      }
    };
    std::unordered_map<AgentId, std::uint32_t, AgentHash, std::equal_to<>> numbers;
    std::vector<std::vector<std::uint32_t>> agents_of;    // per entity: numbers, sorted
    std::vector<std::vector<EntityIndex>> entities_of;    // per number: entities, sorted
    std::vector<std::uint32_t> scratch_agents;  // a sweep's agents, before they are stored
    friend bool operator==(const Newcomers&, const Newcomers&) { return true; }
  };
  Newcomers newcomers_;
  std::vector<Grant> pending_grants_;             // see take_grants
  /// The owner's rule (set_grant_filter), not the set's state: sets compare equal whatever
  /// their filters.
  struct GrantFilterSlot {
    GrantFilter may_grant;
    friend bool operator==(const GrantFilterSlot&, const GrantFilterSlot&) { return true; }
  };
  GrantFilterSlot grant_filter_;
  LockId next_lock_id_ = 1;
  PrepareId next_prepare_id_ = 1;
};

}  // namespace drover::topology
