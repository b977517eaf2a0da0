#pragma once
// The CARP search: A* over (stop layer, node, free window) states, where a node is a vertex
// or an arc (an edge in one direction), ordered by the earliest time the vehicle can leave
// the node's entity plus the exact reservation-free time still to go.
//
// A state (k, n, w) means: heading for stop k, the vehicle is on n's entity inside its free
// window w, entered at `entry` and able to leave from `ready` on (entry, or entry + travel
// time for an arc, or the arrival plus the dwell just after a stop). Leaving at y into the
// next entity's window w' needs y >= ready, y in w', and y + clearance <= end of w (the
// vehicle spans both for the clearance time). The earliest such y dominates every later one,
// because the vehicle may wait inside w'. Memory is reused between searches: stamps instead
// of clears, one arena for all windows and states.

#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

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
};

struct SearchOutcome {
  bool found = false;
  bool start_free = false;     ///< the start vertex was free at the start time
  bool horizon_cut = false;    ///< some state was dropped for passing the deadline
};

class WindowSearch {
 public:
  SearchOutcome run(const SearchInput& input);
  /// The route found by the last run(). \pre it found one
  Route route(const SearchInput& input) const;

 private:
  struct State {
    TimeNs entry;
    TimeNs ready;            // kForever: not reached yet
    std::uint32_t parent;
    std::uint32_t node;      // vertex index, or vertex_count + arc index
    std::uint32_t window;    // index into windows_
    std::uint16_t layer;
    bool closed;
  };
  /// An open state, or (arc != kNone) a deferred move from a closed vertex state onto an
  /// arc, keyed by the earliest the move could get there: the arc's windows are looked up
  /// only if the search ever gets that far, which spares most free-window queries.
  struct OpenEntry {
    TimeNs f;
    TimeNs ready;
    std::uint32_t sequence;  // push order
    std::uint32_t state;
    std::uint32_t arc;
    /// Ties go to the later state, then to the newest entry: on grids many paths are
    /// equally fast, and going deep along one spares exploring all of them.
    bool operator>(const OpenEntry& o) const {
      if (f != o.f) return f > o.f;
      if (ready != o.ready) return ready < o.ready;
      return sequence < o.sequence;
    }
  };
  static constexpr std::uint32_t kNone = 0xffffffffu;

  void begin(const SearchInput& input);
  /// The free windows of `entity` from the start time on: indices [first, first + count).
  std::uint32_t windows_of(const SearchInput& input, topology::EntityIndex entity,
                           std::uint32_t& count);
  /// The index of the state for window 0 of (layer, node); its other windows follow.
  std::uint32_t states_of(const SearchInput& input, std::uint32_t layer, std::uint32_t node);
  /// The heuristic of (layer, vertex), kUnreachable when the goal cannot be reached.
  DurationNs estimate(const SearchInput& input, std::uint32_t layer, topology::EntityIndex vertex);
  /// Moves from state `from` into every fitting window of `node` (entity `entity`).
  void enter(const SearchInput& input, std::uint32_t from, std::uint32_t node,
             topology::EntityIndex entity, DurationNs clearance, DurationNs travel,
             DurationNs estimate, SearchOutcome& outcome);
  void improve(std::uint32_t state, TimeNs entry, TimeNs ready, std::uint32_t parent,
               DurationNs estimate);
  bool completes(const SearchInput& input, const State& state) const;
  void expand_vertex(const SearchInput& input, std::uint32_t index, const State& current,
                     SearchOutcome& outcome);

  std::uint32_t generation_ = 0;
  std::vector<std::uint32_t> entity_stamp_, entity_first_, entity_count_;
  std::vector<std::uint32_t> block_stamp_, block_first_;
  std::vector<topology::Interval> windows_;
  std::vector<State> states_;
  MinHeap<OpenEntry> open_;
  std::uint32_t sequence_ = 0;
  std::uint32_t goal_state_ = kNone;
};

}  // namespace drover::carp
