#include "window_search.hpp"

#include <algorithm>
#include <cassert>

namespace drover::carp {

using topology::EntityIndex;
using topology::Interval;

namespace {

/// How many times a search raises the arrival floor in a row (each by one proof). Once a
/// search has expanded input.quick_proof_after states keyed by the floor, it tries a quick
/// proof that the floor is too early (prove_late with input.quick_proof_budget backward
/// states and no forward table), once per floor. After input.floor_proof_after, it tries a
/// full proof with a budget of input.floor_proof_budget; if that fails, it tries again at
/// four times as many with four times the budget, so the proofs cost at most about half the
/// expansions. A floor one step below the arrival can cost tens of thousands of expansions
/// (warehouse N = 400: 12 000 for an agent that needs 60 with the exact floor), while most
/// searches expand only a few hundred states and never try a full proof.
constexpr int kLateProofRounds = 8;

}  // namespace

void WindowSearch::begin(const SearchInput& input) {
  if (++generation_ == 0) {  // wrapped: every stamp could look current
    for (QueriedWindows& q : queried_) q.stamp = 0;
    for (WindowIds& ids : window_ids_of_) ids.stamp = 0;
    std::fill(block_stamp_.begin(), block_stamp_.end(), 0);
    std::fill(region_stamp_.begin(), region_stamp_.end(), 0);
    from_start_generation_ = 0;
    generation_ = 1;
  }
  const RoutingGraph& graph = *input.graph;
  const std::size_t entities = graph.topology().entity_count();
  if (queried_.size() != entities) {
    queried_.assign(entities, QueriedWindows{});
    window_ids_of_.assign(entities, WindowIds{});
  }
  mark_own_entities(input);
  const std::size_t blocks = input.legs.size() * graph.vertex_count();
  if (block_stamp_.size() < blocks) {
    block_stamp_.resize(blocks, 0);
    block_first_.resize(blocks, 0);
  }
  own_windows_.clear();
  window_ids_ = 0;
  slots_ = 0;
  open_.clear();
  sequence_ = 0;
  arrival_floor_ = 0;
  floor_pops_ = 0;
  next_proof_at_ = input.floor_proof_after;
  proof_budget_ = input.floor_proof_budget;
  floor_proofs_ = 0;
  floor_raises_ = 0;
  proof_routes_ = 0;
  expanded_ = 0;
  shut_in_proofs_ = 0;
  shut_in_refusals_ = 0;
  path_.clear();
}

void WindowSearch::mark_own_entities(const SearchInput& input) {
  // Cleared whole: a bit per entity, a few hundred words on the largest benchmark map.
  const std::size_t entities = input.graph->topology().entity_count();
  own_entities_.assign((entities + 63) / 64, 0);
  for (const EntityIndex entity : input.timelines->reserved_entities(input.agent)) {
    if (entity >= entities) break;  // sorted: none of the graph's from here on
    own_entities_[entity >> 6] |= std::uint64_t{1} << (entity & 63);
  }
}

void WindowSearch::query_windows(const SearchInput& input, EntityIndex entity) {
  scratch_.clear();
  input.timelines->append_free_windows(entity, input.agent, input.start_time, kForever, scratch_,
                                       input.count_locks);
  queried_[entity] = QueriedWindows{own_windows_.store(scratch_),
                                    static_cast<std::uint32_t>(scratch_.size()), generation_};
}

const Interval* WindowSearch::WindowStore::store(const std::vector<Interval>& windows) {
  if (windows.empty()) return nullptr;
  if (block_ < blocks_.size() && used_ + windows.size() > blocks_[block_].size()) {
    ++block_;  // full: on to the next block
    used_ = 0;
  }
  if (block_ < blocks_.size() && windows.size() > blocks_[block_].size()) {
    blocks_[block_].resize(windows.size());  // an unused block, too small: nothing points in
  }
  if (block_ == blocks_.size()) {
    blocks_.emplace_back(std::max<std::size_t>(4096, windows.size()));
  }
  Interval* at = blocks_[block_].data() + used_;
  std::copy(windows.begin(), windows.end(), at);
  used_ += windows.size();
  return at;
}

void WindowSearch::add_states(const SearchInput& input, std::size_t key, EntityIndex vertex) {
  block_stamp_[key] = generation_;
  std::uint32_t count = 0;
  const Interval* first = windows_of(input, vertex, count);
  // Windows that ended by the start time are never reached (every arrival is later): no
  // states for them. The block's index still counts them (unsigned arithmetic wraps back),
  // so that block + window stays the state of that window.
  const std::uint32_t ended = ending_after(first, count, input.start_time);
  block_first_[key] = slots_ - ended;
  const std::uint32_t end = slots_ + (count - ended);
  if (end > reached_.size()) {
    // The states themselves are written when first reached (improve): most never are.
    reached_.resize(std::max<std::size_t>(end, 2 * reached_.size()));
    states_.resize(reached_.size());
  }
  std::fill(reached_.begin() + slots_, reached_.begin() + end, kForever);
  slots_ = end;
}

// Inlined, as improve below, into drive's callback (once per state improved): -2 % planner
// instructions at random N = 200 for the two.
[[gnu::always_inline]] inline DurationNs WindowSearch::estimate(const SearchInput& input,
                                                                std::uint32_t layer,
                                                                EntityIndex vertex) {
  const Leg& leg = input.legs[layer];
  const DurationNs to_stop = leg.table->distance(*input.graph, *input.traversal, vertex);
  return to_stop == kUnreachable ? kUnreachable : to_stop + leg.tail;
}

TimeNs WindowSearch::held_from(const SearchInput& input, Interval window, TimeNs at) {
  const DurationNs hold = input.legs.back().dwell;
  at = std::max(at, window.start);
  // at + hold <= window.end, without the sum: `at` may be a window start near kForever.
  const bool holds = hold == kForever ? window.end == kForever
                                      : at <= window.end && hold <= window.end - at;
  return holds ? at : kForever;
}

TimeNs WindowSearch::arrival_floor(const SearchInput& input) {
  const Leg& last = input.legs.back();
  const EntityIndex previous =
      input.legs.size() > 1 ? input.legs[input.legs.size() - 2].stop : input.start;
  TimeNs floor = kForever;
  if (previous == last.stop) {  // the last leg may start on the stop: no arc needed
    floor = held_after(input, input.start_time);
  } else {
    for (const ArcIndex a : input.graph->arcs_into(last.stop)) {
      if (input.traversal->usable_arc(a)) floor = std::min(floor, arrival_over(input, a, floor));
    }
  }
  return floor;
}

TimeNs WindowSearch::held_after(const SearchInput& input, TimeNs at) {
  std::uint32_t count = 0;
  const Interval* first = windows_of(input, input.legs.back().stop, count);
  for (std::uint32_t g = ending_after(first, count, at); g < count; ++g) {
    if (const TimeNs t = held_from(input, first[g], at); t != kForever) return t;
  }
  return kForever;
}

TimeNs WindowSearch::arrival_over(const SearchInput& input, ArcIndex arc, TimeNs bound) {
  // Inside a free window e of the arc's edge, the vehicle arrives at z >= e.start + travel
  // and its tail leaves the edge by z + clearance <= e.end.
  const DurationNs travel = input.traversal->travel(arc);
  const DurationNs clearance = input.traversal->clearance(arc);
  std::uint32_t count = 0;
  const Interval* first = windows_of(input, input.graph->arc(arc).edge, count);
  for (std::uint32_t e = ending_after(first, count, input.start_time); e < count; ++e) {
    const Interval edge = first[e];
    const TimeNs onto_edge = std::max(edge.start, input.start_time);
    // Compared without sums: a window may start near kForever (bound - travel and
    // edge.end - clearance cannot overflow: both times are >= 0, the durations bounded).
    if (onto_edge >= bound - travel) break;
    const TimeNs z = held_after(input, onto_edge + travel);
    if (z != kForever && z <= edge.end - clearance) return z;
  }
  return kForever;
}

WindowSearch::FloorProof WindowSearch::raise_arrival_floor(const SearchInput& input,
                                                           ProofKind kind) {
  if (!backward_proofs_apply(input)) return FloorProof::go_on;
  const TimeNs floor = arrival_floor_;
  const std::size_t budget = kind == ProofKind::quick ? input.quick_proof_budget : proof_budget_;
  for (int round = 0; round < kLateProofRounds; ++round) {
    const LateProof proof = prove_late(input, kind, arrival_floor_, budget);
    ++floor_proofs_;
    if (proof.reached_start && arrival_floor_ <= input.deadline) {
      // A route arrives by the floor, and none earlier: the earliest arrival.
      if (!follow_labels(input)) return FloorProof::go_on;  // never: the search would find it
      ++proof_routes_;
      return FloorProof::route_found;
    }
    if (!proof.proven) break;
    ++floor_raises_;
    if (proof.margin == kForever) {
      arrival_floor_ = kForever;
      return FloorProof::no_route;
    }
    // The floor stays within the deadline (run() checks the first): past it no route can
    // arrive in time, and the next proof, counting from the floor, could overflow.
    if (proof.margin > input.deadline - arrival_floor_) {
      arrival_floor_ = input.deadline + 1;  // a lower bound still: floor + margin is above
      return FloorProof::past_deadline;
    }
    arrival_floor_ += proof.margin;
  }
  if (arrival_floor_ == floor) {
    if (kind == ProofKind::quick) return FloorProof::go_on;  // tried once per floor
    proof_budget_ *= 4;
    next_proof_at_ *= 4;
    return FloorProof::go_on;
  }
  floor_pops_ = 0;
  next_proof_at_ = input.floor_proof_after;
  // Every open key is at least the new floor; entries of states closed since are dropped.
  open_.rebuild([this](const OpenEntry& e) { return !states_[e.state].closed; },
                [this](OpenEntry& e) { e.f = std::max(e.ready + e.h, arrival_floor_); });
  return FloorProof::go_on;
}

// Why a proof is sound (reviewed 2026-11-25). Take any route of the forward model (drive)
// arriving by deadline + d, 0 <= d < margin: states s_0 (the start state) ... s_n (the
// stop's open-ended window), ready at r_i. Backwards from s_n, every s_i is reached with a
// final label (latest, cap) such that latest >= r_i - d and cap >= r_i:
// - s_n: latest = deadline >= r_n - d, cap = kForever.
// - Step from s_(i+1) over arc a, edge window e, window W of s_i, onto the edge at y: the
//   route has max(r_i, e.start) <= y <= min(r_(i+1), e.end - clearance) - travel,
//   y <= W.end - clearance, r_i >= W.start and r_i >= start_time + a lower bound of the
//   reservation-free travel time from the start to its vertex (travel_from_start, finite:
//   the route got there, and goes on to the last stop). So the checks that do not depend
//   on the deadline (`continue` without fails_by) pass; the label side of the others is
//   >= y - d (latest) and >= y (cap): the edge check's top.latest - travel, and
//   latest_onto_edge, are >= y - d; the window and travel-time checks' label >= r_i - d.
//   Had one failed, it would have recorded a gap <= d < margin (its cap reaches the fixed
//   time, so it counts). The breaks skip only windows that start later (larger gaps). So
//   s_i is reached with latest >= min(y - d, W.end - clearance) >= r_i - d and cap >= r_i.
//   Labels keep the max of `latest` and of `cap` separately (an over-approximation), and a
//   label that grows is expanded again, so the checks are made with the final label too.
// - At the route's last visit to the start window (it could as well have waited there from
//   the start time), the start check either returned "not proven" or recorded
//   start_time - latest <= d. Contradiction: no route arrives by deadline + d.
// (Before the search: no arrival precedes the open-ended window's start, hence that margin.)
// The horizon and the heuristic's unreachable vertices are not checked (a relaxation: a
// proof only gets rarer); usable_vertex(from) holds for every vertex a route leaves (an arc
// needs a usable destination, check_usable the start). Every gap is > 0, so the floor
// rises strictly. It stays a lower bound of every arrival, so the keys
// max(ready + h, floor) stay admissible, improve() reopens closed states, and the first
// completed state popped is the earliest arrival. planner_random_test checks the final
// floor itself against the brute force.
WindowSearch::LateProof WindowSearch::prove_late(const SearchInput& input, ProofKind kind,
                                                 TimeNs deadline, std::size_t budget) {
  const Traversal::Adjacency& adjacency = input.traversal->adjacency(*input.graph);
  if (++late_generation_ == 0) {  // wrapped: every stamp could look current
    std::fill(late_stamp_.begin(), late_stamp_.end(), 0);
    std::fill(walk_stamp_.begin(), walk_stamp_.end(), 0);  // follow_labels stamps with it too
    late_generation_ = 1;
  }
  late_open_.clear();
  DurationNs margin = kForever;
  // A check failed because `latest` is earlier than the fixed time `needed`. With a later
  // deadline, `latest` grows at most as much, and never beyond `cap` (its value for a
  // deadline that never comes).
  const auto fails_by = [&margin](TimeNs needed, TimeNs latest, TimeNs cap) {
    if (cap >= needed) margin = std::min(margin, needed - latest);
  };
  // A state is expanded again when only its cap grew: its successors' caps may grow too.
  // `from_start`: travel_from_start of the vertex.
  const auto reach = [this, kind, &input](EntityIndex vertex, std::uint32_t window,
                                          DurationNs from_start, TimeNs latest, TimeNs cap) {
    const std::uint32_t id = window_id(input, vertex, window);
    if (late_stamp_.size() < window_ids_) {
      late_stamp_.resize(window_ids_, 0);
      late_labels_.resize(window_ids_);
    }
    LateLabel& label = late_labels_[id];
    if (late_stamp_[id] == late_generation_) {
      if (latest <= label.latest && cap <= label.cap) return;
      label = LateLabel{std::max(latest, label.latest), std::max(cap, label.cap)};
    } else {
      late_stamp_[id] = late_generation_;
      label = LateLabel{latest, cap};
    }
    const TimeNs rank = kind == ProofKind::full ? label.latest - from_start : label.latest;
    late_open_.push(LateEntry{rank, label.latest, label.cap, window, id, vertex});
  };
  // Window starts before the start time read as the start time, as when the windows were
  // read from it (the proof's margins compare with them).
  const auto clipped = [&input](Interval w) {
    w.start = std::max(w.start, input.start_time);
    return w;
  };

  std::uint32_t goal_count = 0;
  const Interval* goal_windows = windows_of(input, input.legs.back().stop, goal_count);
  if (goal_count == 0 || goal_windows[goal_count - 1].end != kForever) {
    return LateProof{true, kForever};  // never held open-ended
  }
  const Interval held = clipped(goal_windows[goal_count - 1]);
  if (held.start > deadline) return LateProof{true, held.start - deadline};
  const EntityIndex stop = input.legs.back().stop;
  reach(stop, goal_count - 1, travel_from_start(input, kind, stop), deadline, kForever);

  std::size_t visited = 0;
  while (!late_open_.empty()) {
    const LateEntry top = late_open_.pop();
    const LateLabel& label = late_labels_[top.id];
    if (label.latest != top.latest || label.cap != top.cap) continue;  // superseded
    if (++visited > budget) return LateProof{};
    if (top.vertex == input.start && top.window == start_window_) {
      // The search's first state: ready at the start time, and never reached again.
      if (top.latest >= input.start_time) return LateProof{false, 0, true};
      fails_by(input.start_time, top.latest, top.cap);
      continue;
    }
    const Interval into = clipped(window_of(input, top.vertex, top.window));
    for (const Traversal::Hop& hop : adjacency.into_of(top.vertex)) {
      const EntityIndex from = hop.from;
      const DurationNs travel = adjacency.timing(hop).travel;
      const DurationNs clearance = adjacency.timing(hop).clearance;
      const DurationNs from_start = travel_from_start(input, kind, from);
      if (from_start == kUnreachable) continue;  // no route passes there, whatever the deadline
      const TimeNs earliest = input.start_time + from_start;
      std::uint32_t edge_count = 0;
      const Interval* edge_first = windows_of(input, hop.edge, edge_count);
      // Windows ending before into.start + clearance fail the first check below: skipped.
      for (std::uint32_t i = ending_after(edge_first, edge_count, into.start + clearance - 1);
           i < edge_count; ++i) {
        // As in drive: onto the edge at y >= edge.start, arriving at z >= y + travel and
        // z >= into.start, with z + clearance <= edge.end and z <= top.latest.
        const Interval edge = clipped(edge_first[i]);
        const TimeNs latest_arrival = edge.end - clearance;
        if (latest_arrival < into.start || latest_arrival - travel < edge.start) continue;
        const TimeNs latest_onto_edge = std::min(top.latest, latest_arrival) - travel;
        const TimeNs cap_onto_edge = std::min(top.cap, latest_arrival) - travel;
        if (latest_onto_edge < edge.start) {  // later windows start later still
          fails_by(edge.start, top.latest - travel, top.cap - travel);
          break;
        }
        std::uint32_t from_count = 0;
        const Interval* from_first = windows_of(input, from, from_count);
        // Windows ending before edge.start + clearance fail the first check below: skipped.
        for (std::uint32_t j = ending_after(from_first, from_count, edge.start + clearance - 1);
             j < from_count; ++j) {
          // Ready at r >= window.start, onto the edge at max(r, edge.start), off the vertex
          // (tail included) before the window ends.
          const Interval window = clipped(from_first[j]);
          if (window.end - clearance < std::max(window.start, edge.start)) continue;
          if (latest_onto_edge < window.start) {  // later windows start later still
            fails_by(window.start, latest_onto_edge, cap_onto_edge);
            break;
          }
          const TimeNs latest = std::min(latest_onto_edge, window.end - clearance);
          const TimeNs cap = std::min(cap_onto_edge, window.end - clearance);
          if (latest < earliest) {
            fails_by(earliest, latest, cap);
            continue;
          }
          reach(from, j, from_start, latest, cap);
        }
      }
    }
  }
  return LateProof{true, margin};
}

bool WindowSearch::last_stop_shut_in(const SearchInput& input) {
  if (!backward_proofs_apply(input)) return false;
  const RoutingGraph& graph = *input.graph;
  const Traversal::Adjacency& adjacency = input.traversal->adjacency(graph);
  const auto free_for_good = [&](EntityIndex entity) {
    std::uint32_t count = 0;
    const Interval* first = windows_of(input, entity, count);
    return count > 0 && first[count - 1].end == kForever;
  };
  if (region_stamp_.size() != graph.vertex_count()) region_stamp_.assign(graph.vertex_count(), 0);
  const EntityIndex stop = input.legs.back().stop;
  region_queue_.assign(1, stop);
  region_stamp_[stop] = generation_;
  for (std::size_t head = 0; head < region_queue_.size(); ++head) {
    for (const Traversal::Hop& hop : adjacency.into_of(region_queue_[head])) {
      const EntityIndex from = hop.from;
      if (region_stamp_[from] == generation_ || !free_for_good(hop.edge) ||
          !free_for_good(from)) {
        continue;
      }
      if (from == input.start || region_queue_.size() >= input.shut_in_region) return false;
      region_stamp_[from] = generation_;
      region_queue_.push_back(from);
    }
  }
  return true;
}

bool WindowSearch::prove_no_route(const SearchInput& input, SearchOutcome& outcome) {
  ++shut_in_proofs_;
  // A full proof: with the search's deadline, labels are late and only the exact earliest
  // times from the start drop the states no route reaches in time (with the heuristic's
  // bound instead, bench plan on random-32-32-20, N = 400, ran 1.5 % more planner
  // instructions). The forward table it sets up costs about one heuristic search.
  const LateProof proof =
      prove_late(input, ProofKind::full, input.deadline, input.shut_in_budget);
  if (!proof.proven) return false;
  ++shut_in_refusals_;
  // No route arrives by the deadline; when one might arrive later (the margin is finite),
  // the horizon is what cut it, as an exhaustive search would report.
  outcome.horizon_cut = outcome.horizon_cut || proof.margin != kForever;
  return true;
}

WindowSearch::OpenEntry WindowSearch::open_entry(TimeNs ready, DurationNs estimate,
                                                 std::uint32_t state) {
  return OpenEntry{std::max(ready + estimate, arrival_floor_), estimate, ready, sequence_++,
                   state};
}

[[gnu::always_inline]] inline void WindowSearch::improve(std::uint32_t state,
                                                        const State& reached,
                                                        DurationNs estimate) {
  if (reached.ready >= reached_[state]) return;
  reached_[state] = reached.ready;
  // Keys clipped by the arrival floor are not consistent: a state may be closed before its
  // best `ready` is known. It is then opened again (rare; the result stays exact).
  states_[state] = reached;
  open_.push(open_entry(reached.ready, estimate, state));
}

// Inlined into drive, the search's innermost loop: called there, it cost the planner 2 %
// more instructions (bench plan, random N = 200).
template <class Arrive, class PastDeadline>
[[gnu::always_inline]] inline void WindowSearch::arrivals(const SearchInput& input,
                                                          const State& current,
                                                          TimeNs window_end,
                                                          const Traversal::Move& move,
                                                          Arrive&& arrive,
                                                          PastDeadline&& past_deadline) {
  const Traversal::Timing& timing = input.traversal->adjacency(*input.graph).timing(move);
  const DurationNs travel = timing.travel;
  const DurationNs clearance = timing.clearance;
  // The vehicle must be off the vertex, tail included, before its window ends.
  const TimeNs latest_onto_edge = window_end - clearance;
  if (current.ready > latest_onto_edge) return;

  std::uint32_t edge_count = 0, vertex_count = 0;
  const Interval* edge_first = windows_of(input, move.edge, edge_count);
  // The destination's windows are read only once the edge is known to lead somewhere:
  // reading a timeline is the dearest part of a move.
  const Interval* vertex_first = nullptr;
  for (std::uint32_t i = ending_after(edge_first, edge_count, current.ready); i < edge_count; ++i) {
    const Interval edge = edge_first[i];
    if (edge.start > latest_onto_edge) break;
    const TimeNs onto_edge = std::max(current.ready, edge.start);
    // A window may start so near kForever that the arrival is past every time: it and the
    // later ones only lead past the deadline. (A test of the overflow flag: the cheapest
    // guard in this loop, one instruction.)
    TimeNs earliest_arrival = 0;
    if (__builtin_add_overflow(onto_edge, travel, &earliest_arrival)) [[unlikely]] {
      past_deadline();
      break;
    }
    const TimeNs latest_arrival = edge.end - clearance;  // the tail must leave the edge too
    if (earliest_arrival > latest_arrival) continue;
    if (vertex_first == nullptr) vertex_first = windows_of(input, move.to, vertex_count);
    for (std::uint32_t j = ending_after(vertex_first, vertex_count, earliest_arrival);
         j < vertex_count; ++j) {
      const Interval window = vertex_first[j];
      if (window.start > latest_arrival) break;
      if (!arrive(j, onto_edge, std::max(earliest_arrival, window.start))) break;
    }
  }
}

void WindowSearch::drive(const SearchInput& input, std::uint32_t from, const State& current,
                         TimeNs window_end, const Traversal::Move& move,
                         SearchOutcome& outcome) {
  std::uint32_t block = kNone;
  DurationNs to_go = -1;  // the heuristic of move.to, looked up only if a state improves
  // Forced inline (GCC left it a call once improve was inlined into it): -1 % planner
  // instructions at random N = 200.
  const auto arrive = [&](std::uint32_t j, TimeNs onto_edge,
                          TimeNs arrival) __attribute__((always_inline)) {
    if (arrival > input.deadline) {
      outcome.horizon_cut = true;
      return false;  // later windows are later still
    }
    if (block == kNone) block = states_of(input, current.layer, move.to);
    if (arrival >= reached_[block + j]) return true;
    if (to_go < 0) to_go = estimate(input, current.layer, move.to);
    if (to_go == kUnreachable) return false;  // nor any other window of move.to
    improve(block + j,
            State{arrival, arrival, onto_edge, from, move.arc, move.to, j, current.layer, false},
            to_go);
    // The state may be expanded soon (often next: the search dives), and the moves of its
    // vertex are a cache miss more often than not after a reserve: fetched meanwhile.
    __builtin_prefetch(input.traversal->adjacency(*input.graph).out_of(move.to).data());
    return true;
  };
  arrivals(input, current, window_end, move, arrive, [&] { outcome.horizon_cut = true; });
}

// Why a successor always exists (the converse of prove_late's soundness): a state's label
// L was set from a successor s' (label L' then, never less since) over an arc, edge window e
// and window W, as min(min(L', e.end - clearance) - travel, W.end - clearance), after
// checking e.start <= that and W.end - clearance >= e.start. Ready at r <= L, the vehicle
// enters e at y = max(r, e.start) <= min(L', e.end - clearance) - travel, with
// y + clearance <= W.end, and arrives in s' at max(y + travel, start of s') <=
// min(L', e.end - clearance) (a label is never below its window's start): within L'. So
// from the start state, states within their labels lead on to the last stop's open-ended
// window (the only completing state with a label). Among the routes through them the walk
// takes the earliest at every state, by Dijkstra's order over ready times: each state is
// settled once, so the route never comes back to a state. (A greedy walk, leaving each state
// as early as it could, drove back and forth between two vertices where it had to wait,
// once per travel time: 1 800 003 steps for a wait of 18 s on a 10 µm edge.) A later ready
// never reaches a state earlier (a vehicle may wait), so the earliest ready suffices.
bool WindowSearch::follow_labels(const SearchInput& input) {
  const Leg& last = input.legs.back();
  const Traversal::Adjacency& adjacency = input.traversal->adjacency(*input.graph);
  walk_states_.clear();
  walk_open_.clear();
  if (walk_best_.size() < late_stamp_.size()) {
    walk_best_.resize(late_stamp_.size());
    walk_stamp_.resize(late_stamp_.size(), 0);
  }
  // late_generation_ is this proof's: it stamps the states the walk reached too.
  const auto reach = [&](const State& state, std::uint32_t id) {
    if (walk_stamp_[id] == late_generation_ && walk_states_[walk_best_[id]].ready <= state.ready) {
      return;
    }
    walk_stamp_[id] = late_generation_;
    walk_best_[id] = static_cast<std::uint32_t>(walk_states_.size());
    walk_states_.push_back(state);
    walk_open_.push(WalkEntry{state.ready, walk_best_[id]});
  };
  reach(State{input.start_time, input.start_time, 0, kNone, kNone, input.start, start_window_, 0,
              false},
        window_id(input, input.start, start_window_));
  while (!walk_open_.empty()) {
    const std::uint32_t index = walk_open_.pop().state;
    const State at = walk_states_[index];
    if (walk_best_[window_id(input, at.vertex, at.window)] != index) continue;  // reached earlier
    if (at.vertex == last.stop && completes(input, at)) {
      path_.clear();
      for (std::uint32_t s = index; s != kNone; s = walk_states_[s].parent) {
        path_.push_back(walk_states_[s]);
      }
      std::reverse(path_.begin(), path_.end());
      return true;
    }
    const TimeNs window_end = window_of(input, at.vertex, at.window).end;
    for (const Traversal::Move& move : adjacency.out_of(at.vertex)) {
      arrivals(input, at, window_end, move, [&](std::uint32_t j, TimeNs onto_edge, TimeNs arrival) {
        const std::uint32_t id = window_id(input, move.to, j);
        if (id < late_stamp_.size() && late_stamp_[id] == late_generation_ &&
            arrival <= late_labels_[id].latest) {
          reach(State{arrival, arrival, onto_edge, index, move.arc, move.to, j, 0, false}, id);
        }
        return true;  // a later window may lead on where this one does not
      }, [] {});
    }
  }
  // Never reached: the start state's label leads to the last stop (see above).
  assert(false && "follow_labels: the labels lead nowhere");
  return false;
}

bool WindowSearch::completes(const SearchInput& input, const State& state) {
  const DurationNs hold = input.legs.back().dwell;
  const TimeNs end = window_of(input, state.vertex, state.window).end;
  return hold == kForever ? end == kForever : state.ready + hold <= end;
}

SearchOutcome WindowSearch::run(const SearchInput& input) {
  begin(input);
  SearchOutcome outcome;
  std::uint32_t count = 0;
  const Interval* first = windows_of(input, input.start, count);
  start_window_ = ending_after(first, count, input.start_time);
  if (start_window_ == count || first[start_window_].start > input.start_time) return outcome;
  outcome.start_free = true;
  // Every state's key is at least this: states that could only reach the goal before it
  // is free would otherwise all be expanded first, in order of a bound that cannot be met.
  arrival_floor_ = arrival_floor(input);
  if (arrival_floor_ == kForever) return outcome;  // the stop can never be entered and held
  // No route arrives by the deadline; and the proofs, which count from the floor, could
  // overflow near kForever. (raise_arrival_floor keeps it so.)
  if (arrival_floor_ > input.deadline) {
    outcome.horizon_cut = true;
    return outcome;
  }
  const DurationNs start_estimate = estimate(input, 0, input.start);
  if (start_estimate == kUnreachable) return outcome;
  improve(states_of(input, 0, input.start) + start_window_,
          State{input.start_time, input.start_time, 0, kNone, kNone, input.start, start_window_, 0,
                false},
          start_estimate);

  while (!open_.empty()) {
    const OpenEntry top = open_.pop();
    State& popped = states_[top.state];
    if (popped.closed || top.ready != popped.ready) continue;  // stale entry
    if (top.f == arrival_floor_) {
      ++floor_pops_;
      FloorProof proof = FloorProof::go_on;
      if (floor_pops_ == input.quick_proof_after) {
        proof = raise_arrival_floor(input, ProofKind::quick);
      }
      if (proof == FloorProof::go_on && floor_pops_ == next_proof_at_) {
        proof = raise_arrival_floor(input, ProofKind::full);
      }
      if (proof != FloorProof::go_on) {
        outcome.found = proof == FloorProof::route_found;
        outcome.horizon_cut = proof == FloorProof::past_deadline;
        return outcome;
      }
      if (top.f < arrival_floor_) {  // the key rose: back to the open list
        open_.push(open_entry(top.ready, top.h, top.state));
        continue;
      }
    }
    if (++expanded_ == input.shut_in_after && last_stop_shut_in(input) &&
        prove_no_route(input, outcome)) {
      return outcome;
    }
    popped.closed = true;
    const State current = popped;  // states_ may grow below
    if (current.vertex == input.legs[current.layer].stop &&
        current.layer + 1u == input.legs.size() && completes(input, current)) {
      for (std::uint32_t s = top.state; s != kNone; s = states_[s].parent) {
        path_.push_back(states_[s]);
      }
      std::reverse(path_.begin(), path_.end());
      outcome.found = true;
      return outcome;
    }
    expand(input, top.state, current, outcome);
  }
  return outcome;
}

EntityIndex WindowSearch::came_from_last_window(const SearchInput& input, const State& state) {
  if (state.arc == kNone) return topology::kNoEntity;  // the start, or a stop made in place
  const State& parent = states_[state.parent];
  std::uint32_t count = 0;
  windows_of(input, parent.vertex, count);
  return parent.window + 1 == count ? parent.vertex : topology::kNoEntity;
}

void WindowSearch::prefetch_windows(std::span<const Interval> windows) {
  if (windows.empty()) return;
  __builtin_prefetch(windows.data());
  __builtin_prefetch(&windows.back());
}

void WindowSearch::expand(const SearchInput& input, std::uint32_t index, const State& current,
                          SearchOutcome& outcome) {
  const EntityIndex vertex = current.vertex;
  const TimeNs window_end = window_of(input, current.vertex, current.window).end;
  const Leg& leg = input.legs[current.layer];
  if (vertex == leg.stop && current.layer + 1u < input.legs.size()) {
    // Make the stop: stay for the dwell, then head for the next one from here.
    const TimeNs ready = current.ready + leg.dwell;
    const DurationNs next_estimate = estimate(input, current.layer + 1u, vertex);
    if (ready > input.deadline) {
      outcome.horizon_cut = true;
    } else if (ready < window_end && next_estimate != kUnreachable) {
      const std::uint32_t block = states_of(input, current.layer + 1u, vertex);
      improve(block + current.window,
              State{current.entry, ready, 0, index, kNone, vertex, current.window,
                    static_cast<std::uint16_t>(current.layer + 1u), false},
              next_estimate);
    }
  }
  const auto moves = input.traversal->adjacency(*input.graph).out_of(vertex);
  // Back where the state came from, the vehicle arrives later than the parent state's
  // ready: in the parent's window that improves nothing, the windows before it have ended,
  // and if the parent's window is the vertex's last there is nothing else to reach. The
  // move is then skipped, reads and all (in-process A/B over 30 repeats, six runs: ratio to
  // A* -2.0 % at random N = 200, -2.3 % at N = 400, -0.6 % at warehouse N = 400; same
  // routes). Such a move no longer counts towards horizon_cut either: past the deadline it
  // would only have been dominated, not a state the horizon cut off.
  const EntityIndex back = came_from_last_window(input, current);
  // The windows of the moves' edges and destinations, a cache miss each when the search
  // first reads them (after a reserve, most are): asked for all at once, so that their
  // misses overlap instead of coming one after another in drive (in-process A/B over 30
  // repeats: ratio to A* -3 % at random N = 200, -4 % at N = 400, -10 % at warehouse
  // N = 400). Reading the timelines' per-entity pointer costs no miss: neighbours' entries
  // share lines. Both ends of each entity's windows: ending_after's binary search reads
  // the middle first, often on the line after the first (six in-process A/B runs: ratio to
  // A* -1 to -3 % in each case measured).
  for (const Traversal::Move& move : moves) {
    if (move.to == back) continue;
    prefetch_windows(input.timelines->newcomer_windows(move.edge).windows());
    prefetch_windows(input.timelines->newcomer_windows(move.to).windows());
  }
  for (const Traversal::Move& move : moves) {
    if (move.to == back) continue;
    drive(input, index, current, window_end, move, outcome);
  }
}

Route WindowSearch::route(const SearchInput& input) const {
  const RoutingGraph& graph = *input.graph;
  const Traversal& traversal = *input.traversal;
  Route route;
  route.steps.reserve(2 * path_.size());  // a vertex per state, an edge between two
  for (std::size_t i = 0; i < path_.size(); ++i) {
    const State& state = path_[i];
    if (i > 0) {
      const State& previous = path_[i - 1];
      if (state.arc == kNone) {  // a stop was made at the previous state; the step goes on
        route.stop_steps.push_back(route.steps.size() - 1);
        route.stop_arrivals.push_back(previous.ready);
        continue;
      }
      const Arc& arc = graph.arc(state.arc);
      const DurationNs clearance = traversal.clearance(state.arc);
      route.steps.back().window.end = state.edge_entry + clearance;
      route.steps.push_back(
          topology::RouteStep{arc.edge, Interval{state.edge_entry, state.entry + clearance}});
      route.distance += arc.length;
    }
    route.steps.push_back(topology::RouteStep{state.vertex, Interval{state.entry, 0}});
  }
  const State& goal = path_.back();
  const DurationNs hold = input.legs.back().dwell;
  route.steps.back().window.end = hold == kForever ? kForever : goal.ready + hold;
  route.stop_steps.push_back(route.steps.size() - 1);
  route.stop_arrivals.push_back(goal.ready);
  route.arrival = goal.ready;
  route.travel_time = goal.ready - input.start_time;
  return route;
}

}  // namespace drover::carp
