// Randomised guarantees of the CARP planner (fixed seeds): on small random graphs with random
// reservations of other agents and random locks, every route is valid and collision-free
// (route_checks.hpp), is accepted by TimelineSet::reserve, and arrives exactly when a
// brute-force time-expanded search says the earliest arrival is. All lengths, speeds and
// times are whole seconds, so the brute force on a one-second grid is exact.

#include <algorithm>
#include <random>

#include <gtest/gtest.h>

#include "drover/carp/planner.hpp"
#include "grid_builder.hpp"
#include "route_checks.hpp"

namespace drover::carp::test {
namespace {

using topology::EntityIndex;
using topology::Topology;

constexpr int kNever = std::numeric_limits<int>::max();
constexpr int kGrid = 200;  // brute-force time grid: [0, kGrid) seconds

/// A reservation of another agent, or a lock, in whole seconds (end kNever: open-ended).
struct Blocker {
  EntityIndex entity;
  int start;
  int end;
};

/// When a reservation or a lock on `x` keeps another agent off `e`: when x is e or in C(e).
/// For reservations this is DESIGN's I1 (reservations of different agents on entities whose
/// footprints overlap never overlap in time); a shadow stands for its real reservation, so
/// two entities that both conflict with a third but not with each other may be used at the
/// same time. A lock makes its entity unavailable to every footprint overlapping it.
bool blocks(const Topology& t, EntityIndex x, EntityIndex e) {
  const auto c = t.conflicts(e);
  return x == e || std::find(c.begin(), c.end(), x) != c.end();
}

/// Earliest arrival by exhaustive search over (stop layer, node, entry second), where a
/// node is a vertex or an edge driven in one direction. Independent of the planner: built
/// from the Topology and the blockers only.
class BruteForce {
 public:
  BruteForce(const Topology& t, const std::vector<Blocker>& blockers, const PlanRequest& request)
      : t_(t), request_(request) {
    const std::size_t entities = t.entity_count();
    blocked_prefix_.assign(entities, std::vector<int>(kGrid + 1, 0));
    forever_from_.assign(entities, kNever);
    for (EntityIndex e = 0; e < entities; ++e) {
      std::vector<int> slot(kGrid, 0);
      for (const Blocker& b : blockers) {
        if (!blocks(t, b.entity, e)) continue;
        for (int s = b.start; s < std::min(b.end, kGrid); ++s) slot[s] = 1;
        if (b.end == kNever) forever_from_[e] = std::min(forever_from_[e], b.start);
      }
      for (int s = 0; s < kGrid; ++s) blocked_prefix_[e][s + 1] = blocked_prefix_[e][s] + slot[s];
    }
    for (EntityIndex v = 0; v < t.vertex_count(); ++v) {
      for (const topology::Move& m : t.moves_from(v)) {
        if (restriction_violation(t.edge(m.edge).restrictions, request.vehicle) ||
            restriction_violation(t.vertex(m.to).restrictions, request.vehicle)) {
          continue;
        }
        const double speed = edge_speed(t, m.edge, request.vehicle);
        arcs_.push_back(ArcInfo{v, m.to, m.edge,
                                static_cast<int>(std::lround(t.edge(m.edge).length / speed)),
                                static_cast<int>(std::lround(request.vehicle.length / speed))});
      }
    }
  }

  /// The earliest arrival in seconds, or nullopt when none exists on the grid.
  std::optional<int> earliest_arrival() {
    const std::size_t layers = request_.stops.size();
    const std::size_t vertices = t_.vertex_count();
    const std::size_t nodes = vertices + arcs_.size();
    best_.assign(layers * nodes * kGrid, kNever);
    const auto at = [&](std::size_t k, std::size_t n, int x) -> int& {
      return best_[(k * nodes + n) * kGrid + x];
    };
    if (restriction_violation(t_.vertex(request_.start).restrictions, request_.vehicle)) {
      return std::nullopt;
    }
    const int start_time = static_cast<int>(request_.start_time / kNsPerSecond);
    at(0, request_.start, start_time) = start_time;
    std::optional<int> arrival;
    for (int x = 0; x < kGrid; ++x) {
      for (std::size_t k = 0; k < layers; ++k) {
        const Stop& stop = request_.stops[k];
        const int dwell = static_cast<int>(stop.dwell.value_or(0) / kNsPerSecond);
        for (std::size_t n = 0; n < nodes; ++n) {
          const int ready = at(k, n, x);
          if (ready == kNever) continue;
          if (n < vertices) {
            const auto v = static_cast<EntityIndex>(n);
            if (v == stop.vertex &&
                !restriction_violation(t_.vertex(v).restrictions, request_.vehicle)) {
              if (k + 1 == layers) {
                const bool held = stop.dwell ? free(v, x, ready + dwell) : free(v, x, kNever);
                if (held && (!arrival || ready < *arrival)) arrival = ready;
              } else if (ready + dwell < kGrid) {
                int& next = at(k + 1, n, x);
                next = std::min(next, ready + dwell);
              }
            }
            for (std::size_t a = 0; a < arcs_.size(); ++a) {
              if (arcs_[a].from != v) continue;
              for (int y = ready; y < kGrid && free(v, x, y + arcs_[a].clearance); ++y) {
                int& next = at(k, vertices + a, y);
                next = std::min(next, y + arcs_[a].travel);
              }
            }
          } else {
            const ArcInfo& arc = arcs_[n - vertices];
            for (int y = ready; y < kGrid && free(arc.edge, x, y + arc.clearance); ++y) {
              int& next = at(k, arc.to, y);
              next = std::min(next, y);
            }
          }
        }
      }
    }
    return arrival;
  }

 private:
  struct ArcInfo {
    EntityIndex from, to, edge;
    int travel, clearance;
  };
  /// True when e is free for the whole of [from, until) (until kNever: for good).
  bool free(EntityIndex e, int from, int until) const {
    if (until == kNever && forever_from_[e] != kNever) return false;
    const int end = std::min(until, kGrid);
    return from >= end || blocked_prefix_[e][end] == blocked_prefix_[e][from];
  }

  const Topology& t_;
  const PlanRequest& request_;
  std::vector<std::vector<int>> blocked_prefix_;
  std::vector<int> forever_from_;
  std::vector<ArcInfo> arcs_;
  std::vector<int> best_;
};

/// A random grid of up to 5 x 5 cells with random lengths, slow edges, one-way edges, a few
/// diagonals (which cross) and a few edges closed to the test vehicle's type.
Topology random_grid(std::mt19937& rng) {
  std::uniform_int_distribution<int> size(2, 5);
  std::uniform_real_distribution<double> coin(0, 1);
  const int width = size(rng), height = size(rng);
  std::vector<std::vector<bool>> present(width, std::vector<bool>(height));
  GridBuilder g;
  for (int x = 0; x < width; ++x) {
    for (int y = 0; y < height; ++y) {
      present[x][y] = coin(rng) < 0.85 || (x == 0 && y == 0) || (x == 1 && y == 0);
      if (present[x][y]) g.cell(x, y);
    }
  }
  const auto maybe_edge = [&](int x1, int y1, int x2, int y2, double probability) {
    if (x2 >= width || y2 >= height || !present[x1][y1] || !present[x2][y2]) return;
    if (coin(rng) >= probability) return;
    EdgeOptions options;
    options.length = std::uniform_int_distribution<int>(1, 3)(rng);
    options.max_speed = coin(rng) < 0.2 ? 0.5 : 1.0;
    if (coin(rng) < 0.1) {
      options.bidirectional = false;
      if (coin(rng) < 0.5) {
        std::swap(x1, x2);
        std::swap(y1, y2);
      }
    }
    if (coin(rng) < 0.04) options.restrictions.forbidden_vehicle_types = {"agv"};
    g.edge(x1, y1, x2, y2, options);
  };
  for (int x = 0; x < width; ++x) {
    for (int y = 0; y < height; ++y) {
      maybe_edge(x, y, x + 1, y, 0.9);
      maybe_edge(x, y, x, y + 1, 0.9);
      maybe_edge(x, y, x + 1, y + 1, 0.1);
    }
  }
  return std::move(g).build();
}

/// Fills the timelines with random reservations of agents b, c, d (and a few of a's own,
/// which must not matter) and random locks; returns what blocks agent a.
/// `parked`: the chance that a reservation of the traffic is open-ended (an agent parked).
std::vector<Blocker> random_traffic(World& w, std::mt19937& rng, double parked = 0.03) {
  std::uniform_real_distribution<double> coin(0, 1);
  std::uniform_int_distribution<EntityIndex> entity(
      0, static_cast<EntityIndex>(w.topology.entity_count() - 1));
  std::uniform_int_distribution<int> start(0, 50), length(1, 8);
  std::vector<Blocker> blockers;
  for (const char* agent : {"b", "c", "d", "a"}) {
    const int attempts = 2;
    for (int i = 0; i < attempts; ++i) {
      const EntityIndex e = entity(rng);
      const int from = start(rng);
      const int until = coin(rng) < parked ? kNever : from + length(rng);
      const topology::Interval window{sec(from), until == kNever ? kForever : sec(until)};
      if (w.timelines.reserve(agent, w.next_route++, {{e, window}}) && agent[0] != 'a') {
        blockers.push_back(Blocker{e, from, until});
      }
    }
  }
  if (coin(rng) < 0.3) {
    const EntityIndex e = entity(rng);
    const int from = start(rng);
    const int until = coin(rng) < 0.1 ? kNever : from + length(rng);
    const topology::Interval window{sec(from), until == kNever ? kForever : sec(until)};
    if (w.timelines.lock(e, window, "operator", "random")) {
      blockers.push_back(Blocker{e, from, until});
    }
  }
  return blockers;
}

/// A random request of agent a; `open_ended_only`: one stop, held open-ended (the only kind
/// whose arrival floor the planner raises by proof).
PlanRequest random_request(const World& w, std::mt19937& rng, bool open_ended_only = false) {
  std::uniform_real_distribution<double> coin(0, 1);
  std::uniform_int_distribution<EntityIndex> vertex(
      0, static_cast<EntityIndex>(w.topology.vertex_count() - 1));
  PlanRequest request;
  request.agent = "a";
  request.vehicle = unit_vehicle();
  request.vehicle.length = coin(rng) < 0.3 ? 2.0 : 1.0;
  request.start = vertex(rng);
  const double draw = coin(rng);
  const int stops = open_ended_only ? 1 : draw < 0.6 ? 1 : draw < 0.9 ? 2 : 3;
  for (int k = 0; k < stops; ++k) {
    Stop stop{vertex(rng), std::nullopt};
    if (k + 1 < stops) {
      stop.dwell = sec(std::uniform_int_distribution<int>(0, 3)(rng));
    } else if (!open_ended_only && coin(rng) < 0.3) {
      stop.dwell = sec(std::uniform_int_distribution<int>(1, 4)(rng));
    }
    request.stops.push_back(stop);
  }
  return request;
}

/// What the backward proofs did over the trials of check_against_brute_force.
struct ProofUse {
  int raised = 0;  ///< trials in which a proof raised the floor
  int routes = 0;  ///< trials whose route a proof found (it reached the start)
  int shut_in = 0;  ///< trials that a shut-in proof ended (no route)
};

/// Plans `trials` random requests on random small grids with random traffic and compares
/// each with the brute force: the arrival, and the arrival floor the search ended with
/// (which must never pass the earliest arrival, whatever the search's luck in finding it).
/// `open_ended_only`: requests with one open-ended stop, and every fourth trial with small
/// proof budgets (1 to 32 states), so that proofs also give up and try again.
/// `use`: what the proofs did, if asked. `parked`: as for random_traffic. `latest_start`:
/// requests start at a random whole second up to it (0: at time 0).
void check_against_brute_force(PlannerOptions options, int trials, bool open_ended_only = false,
                               ProofUse* use = nullptr, double parked = 0.03,
                               int latest_start = 0) {
  const std::size_t budget = options.floor_proof_budget;
  const std::size_t quick_budget = options.quick_proof_budget;
  std::mt19937 rng(20240611);
  int found = 0, refused = 0;
  if (use != nullptr) *use = ProofUse{};
  for (int trial = 0; trial < trials; ++trial) {
    SCOPED_TRACE("trial " + std::to_string(trial));
    const bool small = open_ended_only && trial % 4 == 3;
    options.floor_proof_budget = small ? 1 + trial / 4 % 32 : budget;
    options.quick_proof_budget = small ? 1 + trial / 4 % 32 : quick_budget;
    World w(random_grid(rng), options);
    const std::vector<Blocker> blockers = random_traffic(w, rng, parked);
    PlanRequest request = random_request(w, rng, open_ended_only);
    if (latest_start > 0) {
      request.start_time = sec(std::uniform_int_distribution<int>(0, latest_start)(rng));
    }
    const auto expected = BruteForce(w.topology, blockers, request).earliest_arrival();
    const auto planned = w.planner.plan(w.timelines, request);
    const PlanStats stats = w.planner.last_stats();
    if (use != nullptr) {
      use->raised += stats.floor_raises > 0 ? 1 : 0;
      use->routes += static_cast<int>(stats.proof_routes);
      use->shut_in += static_cast<int>(stats.shut_in_refusals);
    }
    if (expected) {
      // A floor past the earliest arrival is a wrong proof even when the search happens to
      // pop the earliest completed state first anyway.
      ASSERT_LE(stats.arrival_floor, sec(*expected))
          << "the search's floor passed the earliest arrival after " << stats.floor_raises
          << " raises";
    }
    ASSERT_EQ(planned.has_value(), expected.has_value())
        << (planned ? "planned, the brute force found nothing"
                    : "refused (" + planned.error().message + "), the brute force arrives at " +
                          std::to_string(*expected) + " s");
    if (!planned) {
      ++refused;
      continue;
    }
    ++found;
    EXPECT_EQ(planned->arrival, sec(*expected));
    ASSERT_TRUE(check_route(w.topology, w.timelines, request, *planned));
    topology::TimelineSet copy = w.timelines;
    const auto reserved = copy.reserve(request.agent, 1, planned->steps);
    EXPECT_TRUE(reserved.has_value()) << reserved.error().message;
  }
  // Both outcomes must be well represented for the test to mean something.
  EXPECT_GT(found, trials * 3 / 8);
  EXPECT_GT(refused, trials / 20);
}

/// A full floor proof after each expansion keyed by the floor, with a budget no small grid
/// exhausts; no quick proofs.
PlannerOptions full_proofs_at_every_floor() {
  return PlannerOptions{.horizon = sec(1000),
                        .quick_proof_after = 0,
                        .floor_proof_after = 1,
                        .floor_proof_budget = 1 << 20};
}

/// A quick floor proof after each expansion keyed by the floor, with a budget no small grid
/// exhausts; no full proofs.
PlannerOptions quick_proofs_at_every_floor() {
  return PlannerOptions{.horizon = sec(1000),
                        .quick_proof_after = 1,
                        .quick_proof_budget = 1 << 20,
                        .floor_proof_after = std::size_t{1} << 40};
}

/// The shut-in check after the first expansion, in a region of any size, and its proof
/// with a budget no small grid exhausts.
PlannerOptions shut_in_proofs_at_once() {
  return PlannerOptions{.horizon = sec(1000),
                        .shut_in_after = 1,
                        .shut_in_region = 1 << 20,
                        .shut_in_budget = 1 << 20};
}

TEST(PlannerRandom, RoutesAreValidCollisionFreeAndArriveAtTheEarliestPossibleTime) {
  check_against_brute_force(PlannerOptions{.horizon = sec(1000)}, 400);
}

// Starting later, the windows that ended before the start time are still in the timelines'
// views the planner reads in place, and the start's window need not be the first.
TEST(PlannerRandom, RoutesFromALaterStartTimeArriveAtTheEarliestPossibleTime) {
  check_against_brute_force(PlannerOptions{.horizon = sec(1000)}, 400, false, nullptr, 0.03, 30);
}

// The small grids seldom make a search expand hundreds of states keyed by the arrival floor,
// so here every search tries to prove its floor too early after one, with a budget no
// small grid exhausts (a budget of one state, as when it was tied to the trigger, let few
// proofs finish: a wrong proof went unnoticed), on requests with one open-ended stop (the
// only ones proved).
// After each raise the next proof comes one floor-keyed expansion later, so the floor is
// pushed up to where no proof holds: right below the earliest arrival, where a proof that
// claims too much shows. Checked: the final floor and the arrival against the brute force.
// A proof at a floor the route meets reaches the start instead, and the route is the one
// its labels lead to: those are checked like the search's own.
TEST(PlannerRandom, RaisingTheArrivalFloorByProofsKeepsTheEarliestArrival) {
  ProofUse use;
  check_against_brute_force(full_proofs_at_every_floor(), 1200, true, &use);
  // The proofs must have been put to work, both ways.
  EXPECT_GT(use.raised, 150) << use.raised;
  EXPECT_GT(use.routes, 300) << use.routes;
}

// The same from later start times: the backward searches must stop at the start's window.
TEST(PlannerRandom, RaisingTheArrivalFloorFromALaterStartTimeKeepsTheEarliestArrival) {
  ProofUse use;
  check_against_brute_force(full_proofs_at_every_floor(), 600, true, &use, 0.03, 30);
  EXPECT_GT(use.raised, 50) << use.raised;
  EXPECT_GT(use.routes, 100) << use.routes;
}

// The same for quick proofs alone (how early a route reaches a vertex bounded by the
// heuristic's triangle inequality, not by the forward table): one after every floor-keyed
// expansion, as each raise starts the count again.
TEST(PlannerRandom, RaisingTheArrivalFloorByQuickProofsKeepsTheEarliestArrival) {
  ProofUse use;
  check_against_brute_force(quick_proofs_at_every_floor(), 1200, true, &use);
  EXPECT_GT(use.raised, 150) << use.raised;
  EXPECT_GT(use.routes, 300) << use.routes;
}

// And from later start times.
TEST(PlannerRandom, RaisingTheArrivalFloorByQuickProofsFromALaterStartTimeKeepsTheEarliestArrival) {
  ProofUse use;
  check_against_brute_force(quick_proofs_at_every_floor(), 600, true, &use, 0.03, 30);
  EXPECT_GT(use.raised, 50) << use.raised;
  EXPECT_GT(use.routes, 100) << use.routes;
}

// Shut-in proofs end a search with no route: here every search for one open-ended stop
// checks after its first state whether the stop is shut in (in a region of any size), and
// tries the proof with a budget no small grid exhausts, among agents parked for good half of
// the time. A wrong proof would refuse a request the brute force routes.
TEST(PlannerRandom, ShutInProofsRefuseOnlyRequestsWithoutARoute) {
  ProofUse use;
  check_against_brute_force(shut_in_proofs_at_once(), 1200, true, &use, 0.5);
  EXPECT_GT(use.shut_in, 40) << use.shut_in;
}

// And from later start times.
TEST(PlannerRandom, ShutInProofsFromALaterStartTimeRefuseOnlyRequestsWithoutARoute) {
  ProofUse use;
  check_against_brute_force(shut_in_proofs_at_once(), 600, true, &use, 0.5, 30);
  EXPECT_GT(use.shut_in, 20) << use.shut_in;
}

TEST(PlannerRandom, AgentsPlannedOneAfterAnotherNeverCollide) {
  std::mt19937 rng(77);
  for (int trial = 0; trial < 30; ++trial) {
    SCOPED_TRACE("trial " + std::to_string(trial));
    World w(random_grid(rng));
    std::vector<std::pair<PlanRequest, Route>> routes;
    for (int agent = 0; agent < 6; ++agent) {
      PlanRequest request = random_request(w, rng);
      request.agent = "agent" + std::to_string(agent);
      request.start_time = sec(std::uniform_int_distribution<int>(0, 10)(rng));
      auto planned = w.planner.plan_and_reserve(w.timelines, request, 1);
      if (planned) routes.emplace_back(request, *planned);
    }
    // Checked at the end, against everything reserved after each route too.
    for (const auto& [request, route] : routes) {
      ASSERT_TRUE(check_route(w.topology, w.timelines, request, route)) << request.agent;
    }
  }
}

/// Plans `request` with the kept planner and with a fresh one: the windows the kept one
/// keeps between plans must never differ from what the timelines say now.
void expect_like_a_fresh_planner(World& w, const topology::TimelineSet& timelines,
                                 const PlanRequest& request) {
  const auto kept = w.planner.plan(timelines, request);
  const auto fresh = Planner(w.graph).plan(timelines, request);
  ASSERT_EQ(kept.has_value(), fresh.has_value());
  if (kept) {
    EXPECT_EQ(kept->steps, fresh->steps);
  } else {
    EXPECT_EQ(kept.error().reason, fresh.error().reason);
  }
}

TEST(PlannerRandom, APlannerKeptAcrossChangesOfTheTimelinesAnswersLikeAFreshOne) {
  std::mt19937 rng(4242);
  std::uniform_real_distribution<double> coin(0, 1);
  for (int trial = 0; trial < 60; ++trial) {
    SCOPED_TRACE("trial " + std::to_string(trial));
    World w(random_grid(rng));
    random_traffic(w, rng);
    std::uniform_int_distribution<EntityIndex> entity(
        0, static_cast<EntityIndex>(w.topology.entity_count() - 1));
    std::vector<topology::LockId> locks;
    for (int change = 0; change < 12; ++change) {
      PlanRequest request = random_request(w, rng);
      request.start_time = sec(std::uniform_int_distribution<int>(0, 20)(rng));
      expect_like_a_fresh_planner(w, w.timelines, request);
      // A copy that moves on alone must not be mistaken for the original, nor the reverse.
      topology::TimelineSet copy = w.timelines;
      const EntityIndex e = entity(rng);
      const int from = std::uniform_int_distribution<int>(0, 40)(rng);
      (void)copy.reserve("c", w.next_route++, {{e, {sec(from), sec(from + 3)}}});
      expect_like_a_fresh_planner(w, copy, request);
      expect_like_a_fresh_planner(w, w.timelines, request);
      // Then the timelines change: another route (or one of the agent's own), a lock, an
      // unlock, an allocation.
      const double draw = coin(rng);
      if (draw < 0.4) {
        PlanRequest other = random_request(w, rng);
        other.agent = coin(rng) < 0.2 ? "a" : "agent" + std::to_string(change);
        (void)w.planner.plan_and_reserve(w.timelines, other, w.next_route++);
      } else if (draw < 0.6) {
        if (auto lock = w.timelines.lock(e, {sec(from), sec(from + 5)}, "op", "test")) {
          locks.push_back(lock->id);
        }
      } else if (draw < 0.75 && !locks.empty()) {
        ASSERT_TRUE(w.timelines.unlock(locks.back()));
        locks.pop_back();
      } else {
        for (const auto& r : w.timelines.timeline(e).reservations) {
          if (!r.shadow()) {
            (void)w.timelines.allocate(r.agent, e);
            break;
          }
        }
      }
    }
  }
}

}  // namespace
}  // namespace drover::carp::test
