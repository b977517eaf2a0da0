#pragma once
// The CARP search: A* over (stop layer, vertex, free window) states, ordered by the earliest
// time the vehicle can leave the vertex plus the exact reservation-free time still to go, or
// by the arrival floor (the earliest the vehicle can drive into the last stop and hold it)
// if that is later (both are lower bounds of the arrival).
//
// A state (k, v, w) means: heading for stop k, the vehicle is on vertex v inside its free
// window w, entered at `entry` and able to leave from `ready` on (entry, or entry + the
// dwell just after a stop). Driving arc a = (v, u) means: enter a's edge at y inside one of
// its free windows e, with y >= ready and y + clearance <= end of w (the vehicle spans both
// for the clearance time); leave it at z >= y + travel inside a free window w' of u, with
// z + clearance <= end of e (waiting on the edge is allowed). The earliest y and z dominate
// later ones, because the vehicle may wait inside e and w'. An arc has a single source
// vertex, so edges need no states of their own. Memory is reused between searches: stamps
// instead of clears, one array for all states (each written once reached); windows are read
// in place where the timelines keep them (a newcomer's view), or kept in blocks that never
// move.

#include <algorithm>
#include <cstdint>
#include <limits>
#include <span>
#include <string_view>
#include <vector>

#include "drover/carp/planner.hpp"
#include "drover/carp/route.hpp"
#include "heuristic.hpp"
#include "min_heap.hpp"

namespace drover::carp {

/// A stop as the search sees it, with its heuristic.
struct Leg {
  topology::EntityIndex stop = topology::kNoEntity;
  DurationNs dwell = 0;        ///< for the last leg: the hold, or kForever for open-ended
  HeuristicTable* table = nullptr;
  DurationNs tail = 0;         ///< fixed time from this stop's arrival to the last arrival
};

struct SearchInput {
  const RoutingGraph* graph = nullptr;
  const Traversal* traversal = nullptr;
  const topology::TimelineSet* timelines = nullptr;
  std::string_view agent;
  topology::EntityIndex start = topology::kNoEntity;
  TimeNs start_time = 0;
  std::span<const Leg> legs;
  TimeNs deadline = 0;         ///< states that could only leave later are dropped
  bool count_locks = true;
  // The planner's options (the defaults taken from there, so that they cannot drift apart).
  std::size_t quick_proof_after = PlannerOptions{}.quick_proof_after;
  std::size_t quick_proof_budget = PlannerOptions{}.quick_proof_budget;
  std::size_t floor_proof_after = PlannerOptions{}.floor_proof_after;
  std::size_t floor_proof_budget = PlannerOptions{}.floor_proof_budget;
  std::size_t shut_in_after = PlannerOptions{}.shut_in_after;
  std::size_t shut_in_region = PlannerOptions{}.shut_in_region;
  std::size_t shut_in_budget = PlannerOptions{}.shut_in_budget;
};

struct SearchOutcome {
  bool found = false;
  bool start_free = false;     ///< the start vertex was free at the start time
  /// A state was dropped for passing the deadline, or the arrival floor passed it.
  bool horizon_cut = false;
};

class WindowSearch {
 public:
  SearchOutcome run(const SearchInput& input);
  /// The route found by the last run(). \pre it found one
  Route route(const SearchInput& input) const;
  /// What the last run() did.
  PlanStats stats() const {
    return PlanStats{arrival_floor_, floor_proofs_, floor_raises_, proof_routes_, expanded_,
                     shut_in_proofs_, shut_in_refusals_};
  }

 private:
  struct State {
    TimeNs entry;            // when the vehicle starts entering the vertex
    TimeNs ready;            // also in reached_, where the search compares arrivals
    TimeNs edge_entry;       // when it entered the edge it came by
    std::uint32_t parent;
    std::uint32_t arc;       // the arc it came by; kNone at the start or after a stop
    std::uint32_t vertex;
    std::uint32_t window;    // which window of its vertex (see windows_of)
    std::uint16_t layer;     // which leg (stop) it heads for: kMaxStops fit
    bool closed;
  };
  static_assert(kMaxStops - 1 <= std::numeric_limits<decltype(State::layer)>::max());
  /// An open state, keyed by a lower bound of the arrival through it.
  struct OpenEntry {
    TimeNs f;                // max(ready + h, arrival_floor_)
    DurationNs h;            // the heuristic: reservation-free time still to go
    TimeNs ready;            // the state's ready when pushed (a later push supersedes it)
    std::uint32_t sequence;  // push order
    std::uint32_t state;
    /// Ties go to the entry closer to the goal (smaller h: without the floor, the later
    /// state): on grids many paths are equally fast, and going deep along one spares
    /// exploring all of them. Then to the earlier `ready`: the floor gives many states of a
    /// delayed agent the same key and h, and taking the newest among them reached states
    /// late first and expanded them again with each earlier `ready` found later (up to five
    /// times per state on average for the worst agents). Then to the newest.
    /// Compared as two 128-bit keys, (f, h) and (ready, newest first), which GCC turns into
    /// two comparisons without the branches of four (times are never negative). Both are
    /// made up front and combined with | and &, not by an early return, which leaves GCC
    /// fewer branches to mispredict where which of two entries is less is a coin toss
    /// (in-process A/B over 30 repeats, two runs: ratio to A* -1 % at random N = 200, -1.5
    /// to -3 % at N = 400, 0 to -1 % at warehouse N = 400).
    bool operator>(const OpenEntry& o) const {
      __extension__ typedef unsigned __int128 Key;
      const auto key = [](TimeNs high, std::uint64_t low) {
        return Key{static_cast<std::uint64_t>(high)} << 64 | low;
      };
      const Key first = key(f, static_cast<std::uint64_t>(h));
      const Key other_first = key(o.f, static_cast<std::uint64_t>(o.h));
      const bool second_greater =
          key(ready, ~std::uint64_t{sequence}) > key(o.ready, ~std::uint64_t{o.sequence});
      return (first > other_first) | ((first == other_first) & second_greater);
    }
  };
  static constexpr std::uint32_t kNone = 0xffffffffu;

  void begin(const SearchInput& input);
  /// A lower bound of the arrival: the earliest the last stop can be entered and held (in
  /// a free window long enough for the hold, or open-ended), looking one step back: unless
  /// the last leg starts on the stop, the vehicle drives in along an arc whose edge must be
  /// free from `travel` before to `clearance` after (such edges often stay blocked a little
  /// longer than the stop, by the same passing vehicle). kForever if the stop can never be
  /// entered and held: then no route arrives.
  TimeNs arrival_floor(const SearchInput& input);
  /// The earliest time >= `at` from which the last stop can be held, kForever if none.
  TimeNs held_after(const SearchInput& input, TimeNs at);
  /// The earliest time >= `at` from which `window` (of the last stop) can hold the
  /// vehicle, kForever if it cannot.
  static TimeNs held_from(const SearchInput& input, topology::Interval window, TimeNs at);
  /// The earliest arrival at the last stop along `arc` that its edge's windows allow, if
  /// before `bound`; kForever otherwise.
  TimeNs arrival_over(const SearchInput& input, ArcIndex arc, TimeNs bound);
  /// The two kinds of floor proof: quick ones bound how early a route can be at a vertex
  /// by the heuristic alone and visit few states; full ones use the exact forward table.
  enum class ProofKind { quick, full };
  /// What raise_arrival_floor found.
  enum class FloorProof {
    go_on,        ///< the floor rose, or stayed: the search goes on
    no_route,     ///< no route ever arrives (a certificate of failure)
    route_found,  ///< a route arrives at the floor, the earliest possible: it is in path_
    past_deadline,  ///< the floor passed the deadline: no route arrives in time
  };
  /// Whether prove_late applies: one stop, held open-ended (the proofs search back from its
  /// open-ended window).
  static bool backward_proofs_apply(const SearchInput& input) {
    return input.legs.size() == 1 && input.legs.back().dwell == kForever;
  }
  /// Raises arrival_floor_ while prove_late proves that no route arrives by it, and re-keys
  /// the open list. Only for one open-ended stop. Called once a search has expanded many
  /// states keyed by the floor: all that could arrive by the floor share it as key, and with
  /// a floor below the arrival every one of them must be expanded. A proof that reaches the
  /// start instead shows a route arriving by the floor, which no route beats: its labels
  /// lead to it (follow_labels), and the search is over.
  FloorProof raise_arrival_floor(const SearchInput& input, ProofKind kind);
  /// What a backward search from the last stop found about arrivals by a deadline.
  struct LateProof {
    bool proven = false;     ///< no route arrives by the deadline
    DurationNs margin = 0;   ///< if proven: nor by deadline + margin - 1 ns; kForever: never
    bool reached_start = false;  ///< a route arrives by the deadline (follow_labels finds it)
  };
  /// A backward search over (vertex, free window) states from the open-ended window of the
  /// last stop, labelled with the latest time the vehicle may be ready there and still arrive
  /// by `deadline`; states the vehicle cannot reach in time (travel_from_start) are
  /// dropped. If it ends without reaching the start state, no route arrives by
  /// the deadline. Each check it failed compares a time that grows at most as fast as the
  /// deadline with a fixed one; the smallest gap is a margin by which the deadline can grow
  /// with every check still failing, so with no route arriving. Gives up (not proven) after
  /// `budget` states. `kind` chooses the bound of travel_from_start.
  LateProof prove_late(const SearchInput& input, ProofKind kind, TimeNs deadline,
                       std::size_t budget);
  /// After prove_late reached the start: the route its labels lead to, from the start state
  /// ready at the start time, into path_: the earliest at every state among the moves that
  /// reach a state within its label (the latest the vehicle may be ready there and still
  /// arrive by the deadline, so such moves lead to the last stop), found in Dijkstra's order
  /// of ready times. Visits each labelled state at most once; never revisits one on the route.
  /// \return true (false only if the labels were unsound: then path_ is unchanged).
  bool follow_labels(const SearchInput& input);
  /// True when the last stop is shut in: the vertices from which it can be reached over
  /// arcs whose edge and source vertex some time become free for good (their last window is
  /// open-ended) are at most input.shut_in_region, the start not among them. Every route
  /// then enters that region over an entity that is blocked for good from some time on.
  /// Cheap (a bounded breadth-first search), so that the proof it calls for is tried only
  /// where it may succeed.
  bool last_stop_shut_in(const SearchInput& input);
  /// Tries to prove that no route arrives within the horizon (prove_late with the
  /// search's deadline). \return true when proven: the search can end without a route.
  bool prove_no_route(const SearchInput& input, SearchOutcome& outcome);
  /// A lower bound of the reservation-free travel time from the start to `vertex`,
  /// kUnreachable if no route passes there: the earliest a route can be there after the
  /// start time. In a full proof the exact time, from a table set up by the first call of
  /// each search (only searches that try a full proof pay for it, about one heuristic
  /// search); in a quick proof the heuristic's triangle inequality, h(start) - h(vertex)
  /// (a route through a vertex that cannot reach the last stop does not exist either).
  DurationNs travel_from_start(const SearchInput& input, ProofKind kind,
                               topology::EntityIndex vertex) {
    if (kind == ProofKind::quick) {
      const Leg& last = input.legs.back();
      const DurationNs to_stop = last.table->distance(*input.graph, *input.traversal, vertex);
      if (to_stop == kUnreachable) return kUnreachable;
      const DurationNs from_start =
          last.table->distance(*input.graph, *input.traversal, input.start);
      return std::max<DurationNs>(0, from_start - to_stop);
    }
    if (from_start_generation_ != generation_) {
      from_start_.reset(*input.graph, input.start);
      from_start_generation_ = generation_;
    }
    return from_start_.distance(*input.graph, *input.traversal, vertex);
  }
  /// The open-list entry of a state that can leave at `ready`, `estimate` to go.
  OpenEntry open_entry(TimeNs ready, DurationNs estimate, std::uint32_t state);
  /// The free windows of `entity`, sorted: `count` of them from the pointer returned, which
  /// stays valid during the search. Served in place from the timelines' newcomer view when
  /// every reservation there blocks the agent (where it has none: most entities, told by a
  /// bit of own_entities_): then they begin with those that ended by the start time, and
  /// the first after it may start before it (the search never gets there before it, and
  /// every reader takes a window start as "free from", so that start only weakens bounds).
  /// Otherwise from an exact query, from the start time on.
  /// Inline: no record of the search's own stands between it and the timelines (bench plan,
  /// in-process A/B over 30 repeats, two runs: ratio to A* -1 to -3 % at random N = 200, -3
  /// to -4 % at N = 400, -2 % at warehouse N = 400, against a stamped record per entity read
  /// first).
  const topology::Interval* windows_of(const SearchInput& input, topology::EntityIndex entity,
                                       std::uint32_t& count) {
    if (input.count_locks && !own_entity(entity)) [[likely]] {
      const std::span<const topology::Interval> windows =
          input.timelines->newcomer_windows(entity).windows();
      count = static_cast<std::uint32_t>(windows.size());
      return windows.data();
    }
    if (queried_[entity].stamp != generation_) query_windows(input, entity);
    const QueriedWindows& queried = queried_[entity];
    count = queried.count;
    return queried.windows;
  }
  /// The index of the first of the `count` windows at `first` (sorted, disjoint, so their
  /// ends increase) that ends after `t`; `count` if none does.
  static std::uint32_t ending_after(const topology::Interval* first, std::uint32_t count,
                                    TimeNs t) {
    // A binary search whose halving is a conditional move: its steps depend on the count
    // alone, so that only the loop's end can be mispredicted, where a scan (or a branching
    // binary search) mispredicts where the answer lies, a coin toss per call. In-process
    // A/B over 30 repeats, two runs, against a scan up to 8 windows and std::partition_point
    // beyond: ratio to A* -6 to -7 % at random N = 200, -4 to -7 % at N = 400, +-1 % at
    // warehouse N = 400, though it runs 4 % more planner instructions.
    if (count == 0) return 0;
    const topology::Interval* base = first;
    while (count > 1) {
      const std::uint32_t half = count / 2;
      base = base[half].end <= t ? base + half : base;
      count -= half;
    }
    return static_cast<std::uint32_t>(base - first) + (base->end <= t ? 1 : 0);
  }
  /// Queries the free windows of `entity` for the search's agent from the start time on
  /// (locks counted or not, as the input says), keeps them in own_windows_ and records
  /// where in queried_.
  void query_windows(const SearchInput& input, topology::EntityIndex entity);
  /// Window `window` of `vertex`.
  const topology::Interval& window_of(const SearchInput& input, topology::EntityIndex vertex,
                                     std::uint32_t window) {
    std::uint32_t count = 0;
    return windows_of(input, vertex, count)[window];
  }
  /// The number of window `window` of `entity` among the windows of the entities this
  /// search numbered so far (prove_late labels them by it); numbers an entity's windows
  /// the first time it is asked about it.
  std::uint32_t window_id(const SearchInput& input, topology::EntityIndex entity,
                          std::uint32_t window) {
    WindowIds& ids = window_ids_of_[entity];
    if (ids.stamp != generation_) {
      std::uint32_t count = 0;
      windows_of(input, entity, count);
      ids = WindowIds{window_ids_, generation_};
      window_ids_ += count;
    }
    return ids.first + window;
  }
  /// Storage for the windows a search reads by exact query (where its own agent has
  /// reservations, or locks are ignored): blocks that never move, so that the search may
  /// hold pointers into them while it reads more. Reused between searches.
  class WindowStore {
   public:
    void clear() noexcept { block_ = 0, used_ = 0; }
    /// Copies `windows` in and returns where they now lie.
    const topology::Interval* store(const std::vector<topology::Interval>& windows);

   private:
    std::vector<std::vector<topology::Interval>> blocks_;  // each sized once, when made
    std::size_t block_ = 0;  // the block being filled
    std::size_t used_ = 0;   // of it
  };
  /// The index of the state for window 0 of (layer, vertex); its other windows follow (those
  /// that ended by the start time have none: see add_states).
  std::uint32_t states_of(const SearchInput& input, std::uint32_t layer,
                          topology::EntityIndex vertex) {
    const std::size_t key = layer * input.graph->vertex_count() + vertex;
    if (block_stamp_[key] != generation_) add_states(input, key, vertex);
    return block_first_[key];
  }
  /// Numbers the states of (layer, vertex) under `key`, one per window that ends after the
  /// start time, unreached (reached_ kForever). Nothing of the states is written: a state
  /// is written whole when first reached (improve), and most never are (bench plan, random
  /// N = 200: 31 000 of 76 000), which spares writing a 48-byte state for each (cold after
  /// a reserve: half the planner's first-level write misses in callgrind's cache model).
  void add_states(const SearchInput& input, std::size_t key, topology::EntityIndex vertex);
  /// The heuristic of (layer, vertex), kUnreachable when the goal cannot be reached.
  DurationNs estimate(const SearchInput& input, std::uint32_t layer, topology::EntityIndex vertex);
  /// Calls arrive(j, onto_edge, arrival) for every window j of move.to that the vehicle
  /// reaches from `current` (whose window ends at `window_end`) by `move`: entering the edge
  /// at `onto_edge`, arriving at `arrival`, both the earliest possible; in order of the
  /// edge's windows, and for each of the destination's windows in order. When arrive returns
  /// false, the destination's later windows are skipped for that edge window (they are
  /// reached later still). Edge windows where the arrival would pass kForever (they open
  /// that late) are not driven: past_deadline() is called instead, once.
  template <class Arrive, class PastDeadline>
  void arrivals(const SearchInput& input, const State& current, TimeNs window_end,
                const Traversal::Move& move, Arrive&& arrive, PastDeadline&& past_deadline);
  /// Drives `move` from state `from` (`current`, a copy: states_ may grow; its window ends
  /// at `window_end`) into every window of its destination it can reach.
  void drive(const SearchInput& input, std::uint32_t from, const State& current,
             TimeNs window_end, const Traversal::Move& move, SearchOutcome& outcome);
  /// Makes `reached` (closed: false) the state at index `state`, and opens it, if it is
  /// ready earlier than the state found there before (if any).
  void improve(std::uint32_t state, const State& reached, DurationNs estimate);
  bool completes(const SearchInput& input, const State& state);
  /// The vertex `state` was reached from over an arc, if the vehicle left it in that
  /// vertex's last window; kNoEntity otherwise. Driving back there reaches nothing new: the
  /// vehicle would arrive after the parent state's ready, and the vertex has no window
  /// after the parent's (those before it ended earlier still).
  topology::EntityIndex came_from_last_window(const SearchInput& input, const State& state);
  void expand(const SearchInput& input, std::uint32_t index, const State& current,
              SearchOutcome& outcome);
  /// Asks the cache for the first and the last line of `windows`.
  static void prefetch_windows(std::span<const topology::Interval> windows);

  std::uint32_t generation_ = 0;
  // Per entity queried by this search (see windows_of), valid where stamped with the
  // search's generation: where its windows are and how many.
  struct QueriedWindows {
    const topology::Interval* windows = nullptr;
    std::uint32_t count = 0;
    std::uint32_t stamp = 0;
  };
  std::vector<QueriedWindows> queried_;
  struct WindowIds {
    std::uint32_t first = 0;  // the id of the entity's window 0
    std::uint32_t stamp = 0;  // the search's generation when assigned
  };
  std::vector<WindowIds> window_ids_of_;
  std::uint32_t window_ids_ = 0;  // windows numbered by this search
  std::vector<std::uint32_t> block_stamp_, block_first_;
  // The windows of exact queries (see windows_of).
  WindowStore own_windows_;
  std::vector<topology::Interval> scratch_;  // an exact query's answer, before it is stored
  /// Whether the search's agent has a reservation on `entity` (see mark_own_entities).
  bool own_entity(topology::EntityIndex entity) const {
    return (own_entities_[entity >> 6] >> (entity & 63) & 1) != 0;
  }
  /// Sets the bits of own_entities_ for the entities where the search's agent has
  /// reservations, and only those: a bit per entity stays in L1, so telling those entities
  /// from the others costs no read of the timelines (docs/carp.md).
  void mark_own_entities(const SearchInput& input);
  std::vector<std::uint64_t> own_entities_;  // a bit per entity
  // Per window of each (layer, vertex) the search touched (see states_of): the earliest
  // `ready` found there, kForever until reached. Dense, so that telling whether an arrival
  // improves a state reads 8 bytes, not a state's line.
  std::vector<TimeNs> reached_;
  std::uint32_t slots_ = 0;  // of reached_ (and states_) used by this search
  // The states, at the same indices: each written whole when reached (improve), left as a
  // former search left it before. Never shrinks.
  std::vector<State> states_;
  DivingMinHeap<OpenEntry> open_;
  /// The label of a state of prove_late's backward search: the latest time the vehicle may
  /// be ready there, and the most that time can become however late the deadline.
  struct LateLabel {
    TimeNs latest = 0;
    TimeNs cap = 0;
  };
  /// An open state of that search: window `window` of `vertex` (its id is `id`), the
  /// highest rank first. In a full proof the rank is the slack: the latest the vehicle may
  /// be ready there, less the earliest it can be there (the forward table's exact time), so
  /// that the search heads for the start like an A* and, when the floor can be met, reaches
  /// it soon, with a route (warehouse N = 200: 7 % fewer planner instructions than latest
  /// first). In a quick proof, whose earliest times are loose, the rank is the latest time
  /// (slack ranks measured no better). Among equal ranks, the state reached earliest first.
  /// Any order gives the same labels when a proof runs to its end (see prove_late).
  struct LateEntry {
    TimeNs rank;
    TimeNs latest;
    TimeNs cap;
    std::uint32_t window;
    std::uint32_t id;
    topology::EntityIndex vertex;
    bool operator>(const LateEntry& o) const {
      return rank != o.rank ? rank < o.rank : latest > o.latest;
    }
  };
  DivingMinHeap<LateEntry> late_open_;
  std::vector<LateLabel> late_labels_;     // per window id, valid where stamped
  std::vector<std::uint32_t> late_stamp_;  // per window id
  std::uint32_t late_generation_ = 0;
  std::uint32_t start_window_ = 0;  // the start state's window of the start vertex
  ReachTable from_start_;                    // see travel_from_start
  std::uint32_t from_start_generation_ = 0;  // generation_ of the search it was set up for
  std::uint32_t sequence_ = 0;
  TimeNs arrival_floor_ = 0;  // no arrival at the last stop can be earlier (see arrival_floor)
  std::size_t floor_pops_ = 0;     // states expanded with the floor as key, since it last rose
  std::size_t next_proof_at_ = 0;  // floor_pops_ at which raise_arrival_floor is tried
  std::size_t proof_budget_ = 0;   // backward states prove_late may visit
  std::size_t floor_proofs_ = 0;   // prove_late calls in this search
  std::size_t floor_raises_ = 0;   // of which proven
  std::size_t proof_routes_ = 0;   // 1 when a proof found the route
  std::size_t expanded_ = 0;       // see PlanStats
  std::size_t shut_in_proofs_ = 0;    // see PlanStats
  std::size_t shut_in_refusals_ = 0;
  // last_stop_shut_in's breadth-first search: vertices stamped with the search's generation
  // once queued, and the queue.
  std::vector<std::uint32_t> region_stamp_;
  std::vector<topology::EntityIndex> region_queue_;
  std::vector<State> path_;  // the route found, from the start state to the goal's
  // follow_labels' search: the states it reached (parent: an index here), the best of them
  // per window id (valid where stamped with the proof's late_generation_), and the open ones
  // by ready time.
  struct WalkEntry {
    TimeNs ready;
    std::uint32_t state;
    bool operator>(const WalkEntry& o) const { return ready > o.ready; }
  };
  std::vector<State> walk_states_;
  std::vector<std::uint32_t> walk_best_;
  std::vector<std::uint32_t> walk_stamp_;
  MinHeap<WalkEntry> walk_open_;
};

}  // namespace drover::carp
