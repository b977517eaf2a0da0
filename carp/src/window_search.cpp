#include "window_search.hpp"

#include <algorithm>

namespace drover::carp {

using topology::EntityIndex;
using topology::Interval;

void WindowSearch::begin(const SearchInput& input) {
  if (++generation_ == 0) {  // wrapped: every stamp could look current
    std::fill(entity_stamp_.begin(), entity_stamp_.end(), 0);
    std::fill(block_stamp_.begin(), block_stamp_.end(), 0);
    generation_ = 1;
  }
  const RoutingGraph& graph = *input.graph;
  const std::size_t entities = graph.topology().entity_count();
  if (entity_stamp_.size() != entities) {
    entity_stamp_.assign(entities, 0);
    entity_first_.assign(entities, 0);
    entity_count_.assign(entities, 0);
  }
  const std::size_t blocks = input.legs.size() * (graph.vertex_count() + graph.arc_count());
  if (block_stamp_.size() < blocks) {
    block_stamp_.resize(blocks, 0);
    block_first_.resize(blocks, 0);
  }
  windows_.clear();
  states_.clear();
  open_.clear();
  sequence_ = 0;
  goal_state_ = kNone;
}

std::uint32_t WindowSearch::windows_of(const SearchInput& input, EntityIndex entity,
                                       std::uint32_t& count) {
  if (entity_stamp_[entity] != generation_) {
    entity_stamp_[entity] = generation_;
    entity_first_[entity] = static_cast<std::uint32_t>(windows_.size());
    input.timelines->append_free_windows(entity, input.agent, input.start_time, kForever,
                                         windows_, input.count_locks);
    entity_count_[entity] = static_cast<std::uint32_t>(windows_.size()) - entity_first_[entity];
  }
  count = entity_count_[entity];
  return entity_first_[entity];
}

std::uint32_t WindowSearch::states_of(const SearchInput& input, std::uint32_t layer,
                                      std::uint32_t node) {
  const RoutingGraph& graph = *input.graph;
  const std::size_t vertices = graph.vertex_count();
  const std::size_t key = layer * (vertices + graph.arc_count()) + node;
  if (block_stamp_[key] != generation_) {
    block_stamp_[key] = generation_;
    const EntityIndex entity = node < vertices ? node : graph.arc(node - vertices).edge;
    std::uint32_t count = 0;
    const std::uint32_t first_window = windows_of(input, entity, count);
    block_first_[key] = static_cast<std::uint32_t>(states_.size());
    for (std::uint32_t i = 0; i < count; ++i) {
      states_.push_back(State{0, kForever, kNone, node, first_window + i,
                              static_cast<std::uint16_t>(layer), false});
    }
  }
  return block_first_[key];
}

DurationNs WindowSearch::estimate(const SearchInput& input, std::uint32_t layer,
                                  EntityIndex vertex) {
  const Leg& leg = input.legs[layer];
  const DurationNs to_stop = leg.table->distance(*input.graph, *input.traversal, vertex);
  return to_stop == kUnreachable ? kUnreachable : to_stop + leg.tail;
}

void WindowSearch::improve(std::uint32_t state, TimeNs entry, TimeNs ready,
                           std::uint32_t parent, DurationNs estimate) {
  State& s = states_[state];
  if (s.closed || ready >= s.ready) return;
  s.entry = entry;
  s.ready = ready;
  s.parent = parent;
  open_.push(OpenEntry{ready + estimate, ready, sequence_++, state, kNone});
}

void WindowSearch::enter(const SearchInput& input, std::uint32_t from, std::uint32_t node,
                         EntityIndex entity, DurationNs clearance, DurationNs travel,
                         DurationNs estimate, SearchOutcome& outcome) {
  const State current = states_[from];
  // The vehicle must be gone from its window, tail included, before it ends.
  const TimeNs latest = windows_[current.window].end - clearance;
  if (current.ready > latest) return;
  std::uint32_t count = 0;
  const std::uint32_t first = windows_of(input, entity, count);
  const auto begin = windows_.begin() + first;
  const auto usable = std::partition_point(
      begin, begin + count, [&](const Interval& w) { return w.end <= current.ready; });
  std::uint32_t block = kNone;
  for (auto it = usable; it != begin + count && it->start <= latest; ++it) {
    const TimeNs enter_at = std::max(current.ready, it->start);
    const TimeNs ready = enter_at + travel;
    // On an arc the vehicle must also be able to leave before the window ends.
    if (travel > 0 && ready + clearance > it->end) continue;
    if (ready > input.deadline) {
      outcome.horizon_cut = true;
      break;  // later windows are later still
    }
    if (block == kNone) block = states_of(input, current.layer, node);
    improve(block + static_cast<std::uint32_t>(it - begin), enter_at, ready, from, estimate);
  }
}

bool WindowSearch::completes(const SearchInput& input, const State& state) const {
  const DurationNs hold = input.legs.back().dwell;
  const TimeNs end = windows_[state.window].end;
  return hold == kForever ? end == kForever : state.ready + hold <= end;
}

SearchOutcome WindowSearch::run(const SearchInput& input) {
  begin(input);
  SearchOutcome outcome;
  const RoutingGraph& graph = *input.graph;
  const Traversal& traversal = *input.traversal;
  const auto vertices = static_cast<std::uint32_t>(graph.vertex_count());

  std::uint32_t count = 0;
  const std::uint32_t first = windows_of(input, input.start, count);
  if (count == 0 || windows_[first].start != input.start_time) return outcome;
  outcome.start_free = true;
  const DurationNs start_estimate = estimate(input, 0, input.start);
  if (start_estimate == kUnreachable) return outcome;
  improve(states_of(input, 0, input.start), input.start_time, input.start_time, kNone,
          start_estimate);

  while (!open_.empty()) {
    const OpenEntry top = open_.pop();
    if (top.arc != kNone) {  // a deferred move onto an arc: now look at its windows
      const ArcIndex a = top.arc;
      enter(input, top.state, vertices + a, graph.arc(a).edge, traversal.clearance(a),
            traversal.travel(a), top.f - top.ready, outcome);
      continue;
    }
    State& popped = states_[top.state];
    if (popped.closed || top.ready != popped.ready) continue;  // stale entry
    popped.closed = true;
    const State current = popped;  // states_ may grow below

    if (current.node >= vertices) {  // on an arc: next is its destination vertex
      const ArcIndex a = current.node - vertices;
      const EntityIndex to = graph.arc(a).to;
      enter(input, top.state, to, to, traversal.clearance(a), 0,
            estimate(input, current.layer, to), outcome);
      continue;
    }
    if (current.node == input.legs[current.layer].stop &&
        current.layer + 1u == input.legs.size() && completes(input, current)) {
      goal_state_ = top.state;
      outcome.found = true;
      return outcome;
    }
    expand_vertex(input, top.state, current, outcome);
  }
  return outcome;
}

void WindowSearch::expand_vertex(const SearchInput& input, std::uint32_t index,
                                 const State& current, SearchOutcome& outcome) {
  const RoutingGraph& graph = *input.graph;
  const Traversal& traversal = *input.traversal;
  const EntityIndex vertex = current.node;
  const Leg& leg = input.legs[current.layer];
  if (vertex == leg.stop && current.layer + 1u < input.legs.size()) {
    // Make the stop: stay for the dwell, then head for the next one from here.
    const TimeNs ready = current.ready + leg.dwell;
    const DurationNs next_estimate = estimate(input, current.layer + 1u, vertex);
    if (ready > input.deadline) {
      outcome.horizon_cut = true;
    } else if (ready < windows_[current.window].end && next_estimate != kUnreachable) {
      const std::uint32_t block = states_of(input, current.layer + 1u, vertex);
      improve(block + (current.window - entity_first_[vertex]), current.entry, ready, index,
              next_estimate);
    }
  }
  // Moves onto the arcs are deferred: keyed by the earliest arrival they could give.
  for (ArcIndex a = graph.arcs_begin(vertex); a != graph.arcs_end(vertex); ++a) {
    if (!traversal.usable_arc(a)) continue;
    if (current.ready + traversal.clearance(a) > windows_[current.window].end) continue;
    const DurationNs arc_estimate = estimate(input, current.layer, graph.arc(a).to);
    if (arc_estimate == kUnreachable) continue;
    const TimeNs earliest = current.ready + traversal.travel(a);
    if (earliest > input.deadline) {
      outcome.horizon_cut = true;
      continue;
    }
    open_.push(OpenEntry{earliest + arc_estimate, earliest, sequence_++, index, a});
  }
}

Route WindowSearch::route(const SearchInput& input) const {
  const RoutingGraph& graph = *input.graph;
  const Traversal& traversal = *input.traversal;
  const auto vertices = static_cast<std::uint32_t>(graph.vertex_count());
  std::vector<std::uint32_t> chain;
  for (std::uint32_t s = goal_state_; s != kNone; s = states_[s].parent) chain.push_back(s);
  std::reverse(chain.begin(), chain.end());

  Route route;
  for (std::size_t i = 0; i < chain.size(); ++i) {
    const State& state = states_[chain[i]];
    if (i > 0) {
      const State& previous = states_[chain[i - 1]];
      if (previous.node == state.node) {  // a stop was made here; the step goes on
        route.stop_steps.push_back(route.steps.size() - 1);
        route.stop_arrivals.push_back(previous.ready);
        continue;
      }
      const ArcIndex arc = (previous.node >= vertices ? previous.node : state.node) - vertices;
      route.steps.back().window.end = state.entry + traversal.clearance(arc);
    }
    EntityIndex entity = state.node;
    if (state.node >= vertices) {
      const Arc& arc = graph.arc(state.node - vertices);
      entity = arc.edge;
      route.distance += arc.length;
    }
    route.steps.push_back(topology::RouteStep{entity, Interval{state.entry, 0}});
  }
  const State& goal = states_[goal_state_];
  const DurationNs hold = input.legs.back().dwell;
  route.steps.back().window.end = hold == kForever ? kForever : goal.ready + hold;
  route.stop_steps.push_back(route.steps.size() - 1);
  route.stop_arrivals.push_back(goal.ready);
  route.arrival = goal.ready;
  route.travel_time = goal.ready - input.start_time;
  return route;
}

}  // namespace drover::carp
