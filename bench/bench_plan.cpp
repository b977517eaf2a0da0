#include "bench/bench_plan.hpp"

#include <algorithm>
#include <chrono>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <optional>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "bench/output_file.hpp"
#include "bench/scenario.hpp"
#include "drover/carp/free_path.hpp"
#include "drover/carp/planner.hpp"
#include "drover/common/logging.hpp"
#include "drover/common/text_file.hpp"
#include "drover/topology/movingai.hpp"

namespace drover::bench {

namespace {

using carp::PlanError;
using carp::Route;
using topology::EntityIndex;

struct PlanBenchArguments {
  std::string map;
  std::string scenario;
  std::size_t agents = 0;
  std::string paths;
  int repeat = 1;
};

/// One agent of the benchmark: a scenario task on the imported map.
struct Agent {
  std::string id;
  EntityIndex start = topology::kNoEntity;
  EntityIndex goal = topology::kNoEntity;
};

/// What became of one agent's route.
struct Outcome {
  std::optional<Route> route;
  std::optional<PlanError> error;
};

struct CarpRun {
  std::vector<Outcome> outcomes;
  std::vector<double> agent_plan_seconds;  ///< per agent, the time of its plan
  double plan_seconds = 0;     ///< time in the planner (search and route)
  double reserve_seconds = 0;  ///< time in TimelineSet::reserve (writing the routes)
};

/// The baseline's run: per agent, the time of its search and the reservation-free travel
/// time it found, if it found a path.
struct AstarRun {
  std::vector<double> agent_seconds;
  std::vector<std::optional<DurationNs>> travel_times;
  double seconds = 0;
  std::size_t found = 0;
};

constexpr topology::RouteId kRoute = 1;
// More agents than any MovingAI scenario holds (at most a few thousand tasks).
constexpr long long kMaxAgents = 1'000'000;

/// A monotonic clock, in seconds. Read around every plan, so it must cost next to nothing
/// and leave the caches alone: the thread's CPU clock (CLOCK_THREAD_CPUTIME_ID) is a system
/// call on virtualised hosts (1.4 us on the development machine, with the TLB flushed on the
/// way in and out), which every plan paid and the A* run, timed once, did not. This one is
/// read in user space (vDSO, 27 ns there). Wall time counts what other processes take from
/// the thread: with --repeat, the medians leave such runs out.
double now_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

carp::VehicleProfile bench_vehicle(double cell_size) {
  carp::VehicleProfile vehicle;
  vehicle.id = "bench";
  vehicle.type = "agv";
  vehicle.max_speed = 1.0;      // unit speed: a cell per second
  vehicle.length = cell_size;   // one cell in size
  vehicle.width = cell_size;
  return vehicle;
}

/// Plain reservation-free A* for every agent.
AstarRun run_astar(const std::shared_ptr<const carp::RoutingGraph>& graph,
                   const std::vector<Agent>& agents, const carp::VehicleProfile& vehicle) {
  carp::FreePathSearch search(graph);
  AstarRun run;
  for (const Agent& agent : agents) {
    // Timed one by one, as the plans are, so that both pay the same for the clock.
    const double start = now_seconds();
    const auto path = search.find(vehicle, agent.start, agent.goal);
    const double seconds = now_seconds() - start;
    run.agent_seconds.push_back(seconds);
    run.seconds += seconds;
    run.travel_times.push_back(path ? std::optional(path->travel_time) : std::nullopt);
    if (path) ++run.found;
  }
  return run;
}

/// Prioritized planning with CARP, in scenario order: each agent gets a real route from
/// time 0 (its start held from 0 until it leaves) to its goal, held open-ended, around the
/// routes of the agents before it. The timelines only gain reservations, so an agent that
/// fails would fail again later: there is no retry (see docs/benchmarks.md).
CarpRun run_carp(const std::shared_ptr<const carp::RoutingGraph>& graph,
                 const std::vector<Agent>& agents, const carp::VehicleProfile& vehicle) {
  topology::TimelineSet timelines(graph->topology().conflict_sets());
  carp::Planner planner(graph);
  CarpRun run;
  run.outcomes.resize(agents.size());
  for (std::size_t i = 0; i < agents.size(); ++i) {
    carp::PlanRequest request;
    request.agent = agents[i].id;
    request.vehicle = vehicle;
    request.start = agents[i].start;
    request.start_time = 0;
    request.stops = {carp::Stop{agents[i].goal, std::nullopt}};
    double start = now_seconds();
    auto planned = planner.plan(timelines, request);
    run.agent_plan_seconds.push_back(now_seconds() - start);
    run.plan_seconds += run.agent_plan_seconds.back();
    if (!planned) {
      run.outcomes[i].error = std::move(planned).error();
      continue;
    }
    start = now_seconds();
    auto reserved = timelines.reserve(request.agent, kRoute, planned->steps);
    run.reserve_seconds += now_seconds() - start;
    if (!reserved) {
      throw std::runtime_error("the timelines refused the planned route of " + request.agent +
                               ": " + reserved.error().message);
    }
    run.outcomes[i].route = std::move(planned).value();
  }
  return run;
}

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 == 1 ? values[n / 2] : (values[n / 2 - 1] + values[n / 2]) / 2;
}

nlohmann::json steps_json(const topology::Topology& topology, const Route& route) {
  nlohmann::json steps = nlohmann::json::array();
  for (const auto& step : route.steps) {
    steps.push_back({{"entity", topology.id(step.entity)},
                     {"enter", ns_to_seconds(step.window.start)},
                     {"leave", step.window.end == kForever ? nlohmann::json(nullptr)
                                                           : nlohmann::json(ns_to_seconds(step.window.end))}});
  }
  return steps;
}

int run_plan_bench(const PlanBenchArguments& arguments) {
  const auto logger = make_agent_logger("bench-plan");
  topology::MovingAiOptions map_options;  // 1 m cells, 1 m/s edges
  const auto loaded = topology::load_movingai_grid(arguments.map, map_options);
  if (!loaded) {
    return cli::report_bad_file(arguments.map, loaded.error());
  }
  const auto tasks = load_scenario(arguments.scenario);
  if (!tasks) {
    std::cerr << "error: " << tasks.error().message << "\n";
    return cli::kExitBadInput;
  }
  if (arguments.agents > tasks->size()) {
    std::cerr << "error: " << arguments.scenario << ": --agents " << arguments.agents
              << " but the scenario has only " << tasks->size() << " tasks\n";
    return cli::kExitBadInput;
  }
  const topology::Topology& map = loaded->topology;
  const std::string map_name = std::filesystem::path(arguments.map).filename().string();

  std::vector<Agent> agents;
  std::size_t other_map_tasks = 0;
  for (std::size_t i = 0; i < arguments.agents; ++i) {
    const ScenarioTask& task = (*tasks)[i];
    // Cells are named by their coordinates: on a map of another size they name other cells.
    if (task.map_width != loaded->width || task.map_height != loaded->height) {
      std::cerr << "error: " << arguments.scenario << ":line " << task.line << ": the task is for a "
                << task.map_width << "x" << task.map_height << " map, but " << arguments.map
                << " is " << loaded->width << "x" << loaded->height << " (width x height)\n";
      return cli::kExitBadInput;
    }
    // Said once, for the first such task: a renamed copy of the map would repeat it N times.
    if (task.map != map_name && other_map_tasks++ == 0) {
      logger->warn("{}:line {}: the task is for map {}, running it on {}", arguments.scenario,
                   task.line, printable_excerpt(task.map), map_name);
    }
    const auto start = map.find(fmt::format("{},{}", task.start_x, task.start_y));
    const auto goal = map.find(fmt::format("{},{}", task.goal_x, task.goal_y));
    if (!start || !goal) {
      std::cerr << "error: " << arguments.scenario << ":line " << task.line << ": "
                << (!start ? "start" : "goal") << " cell is not a passable cell of "
                << arguments.map << "\n";
      return cli::kExitBadInput;
    }
    agents.push_back(Agent{fmt::format("agent-{}", i), *start, *goal});
  }
  if (other_map_tasks > 1) {
    logger->warn("{}: {} of the {} tasks run are for another map than {}", arguments.scenario,
                 other_map_tasks, agents.size(), map_name);
  }

  // Opened once the input is checked, before any work: a paths file that cannot be
  // written is bad input, refused before the run rather than after minutes of it.
  std::optional<OutputFile> paths_out;
  if (!arguments.paths.empty()) {
    auto opened = OutputFile::open(arguments.paths, {arguments.map, arguments.scenario});
    if (!opened) {
      std::cerr << "error: " << opened.error().message << "\n";
      return cli::kExitBadInput;
    }
    paths_out.emplace(std::move(opened).value());
  }

  const auto graph = std::make_shared<const carp::RoutingGraph>(map);
  const carp::VehicleProfile vehicle = bench_vehicle(map_options.cell_size);

  std::vector<double> astar_times, plan_times, reserve_times;
  // The same sums over the planned agents only: every repeat plans the same agents.
  std::vector<double> planned_astar_times, planned_plan_times;
  AstarRun astar;
  CarpRun run;
  for (int r = 0; r < arguments.repeat; ++r) {
    astar = run_astar(graph, agents, vehicle);
    run = run_carp(graph, agents, vehicle);
    astar_times.push_back(astar.seconds);
    plan_times.push_back(run.plan_seconds);
    reserve_times.push_back(run.reserve_seconds);
    double planned_astar = 0, planned_plan = 0;
    for (std::size_t i = 0; i < agents.size(); ++i) {
      if (!run.outcomes[i].route) continue;
      planned_astar += astar.agent_seconds[i];
      planned_plan += run.agent_plan_seconds[i];
    }
    planned_astar_times.push_back(planned_astar);
    planned_plan_times.push_back(planned_plan);
  }

  std::size_t planned = 0;
  double sum_of_costs = 0, makespan = 0, free_sum_of_costs = 0;
  std::map<std::string, std::size_t> failures;
  for (std::size_t i = 0; i < agents.size(); ++i) {
    const Outcome& outcome = run.outcomes[i];
    if (outcome.route) {
      ++planned;
      const double arrival = ns_to_seconds(outcome.route->arrival);
      sum_of_costs += arrival;
      makespan = std::max(makespan, arrival);
      // A planned agent's goal is reachable, so the baseline found a path.
      free_sum_of_costs += ns_to_seconds(astar.travel_times[i].value_or(0));
    } else {
      ++failures[carp::to_string(outcome.error->reason)];
      logger->info("{} ({} -> {}) not planned: {}: {}", agents[i].id, map.id(agents[i].start),
                   map.id(agents[i].goal), carp::to_string(outcome.error->reason),
                   outcome.error->message);
    }
  }
  const double plan_seconds = median(plan_times);
  const double astar_seconds = median(astar_times);
  const double planned_plan_seconds = median(planned_plan_times);
  const double planned_astar_seconds = median(planned_astar_times);
  nlohmann::json line = {
      {"map", map_name},
      {"agents", agents.size()},
      {"planned", planned},
      {"failed", agents.size() - planned},
      {"sum_of_costs", sum_of_costs},
      {"makespan", makespan},
      {"plan_seconds", plan_seconds},
      {"astar_seconds", astar_seconds},
      {"ratio_to_astar", astar_seconds > 0 ? plan_seconds / astar_seconds : 0.0},
      {"reserve_seconds", median(reserve_times)},
      {"failures", failures},
      {"astar_found", astar.found},
      {"free_sum_of_costs", free_sum_of_costs},
      {"planned_plan_seconds", planned_plan_seconds},
      {"planned_astar_seconds", planned_astar_seconds},
      {"planned_ratio_to_astar",
       planned_astar_seconds > 0 ? planned_plan_seconds / planned_astar_seconds : 0.0},
  };
  // The paths first: the result line is printed only for a run whose output is complete.
  if (paths_out) {
    for (std::size_t i = 0; i < agents.size() && paths_out->stream(); ++i) {
      nlohmann::json path = {{"agent", i}};
      const Outcome& outcome = run.outcomes[i];
      if (outcome.route) {
        path["steps"] = steps_json(map, *outcome.route);
      } else {
        path["steps"] = nlohmann::json::array();
        path["error"] = fmt::format("{}: {}", carp::to_string(outcome.error->reason),
                                    outcome.error->message);
      }
      paths_out->stream() << path.dump() << "\n";
    }
    if (auto written = paths_out->commit(); !written) {
      std::cerr << "error: " << written.error().message << "\n";
      return cli::kExitFailure;
    }
  }
  std::cout << line.dump() << "\n";
  return cli::kExitOk;
}

}  // namespace

void add_bench_plan_command(CLI::App& bench, cli::CommandContext& context) {
  auto arguments = std::make_shared<PlanBenchArguments>();
  auto* plan = bench.add_subcommand(
      "plan",
      "Plan the first N tasks of a MovingAI scenario one after another as real CARP routes "
      "from time 0 (goals held open-ended) and time it against a reservation-free A* on the "
      "same start/goal pairs; prints one JSON line");
  plan->add_option("--map", arguments->map, "MovingAI .map file")->required()->check(cli::non_empty());
  plan->add_option("--scen", arguments->scenario, "MovingAI .scen file")
      ->required()
      ->check(cli::non_empty());
  plan->add_option("--agents", arguments->agents, "How many scenario tasks to plan (N >= 1)")
      ->required()
      ->transform(cli::whole_in(1, kMaxAgents));
  plan->add_option("--paths", arguments->paths,
                   "Also write one JSON line per agent with its steps to this file (written "
                   "as FILE.partial, renamed when complete)")
      ->check(cli::non_empty());
  plan->add_option("--repeat", arguments->repeat,
                   "Run the whole measurement this many times and report median times")
      ->transform(cli::whole_in(1, 100));
  plan->callback([arguments, &context] {
    try {
      context.exit_code = run_plan_bench(*arguments);
    } catch (const std::exception& e) {
      std::cerr << "error: bench plan: " << e.what() << "\n";
      context.exit_code = cli::kExitFailure;
    }
  });
}

}  // namespace drover::bench
