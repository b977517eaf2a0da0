// `droverctl route FROM TO [--agent ID] [--test] [--vehicle PROFILE.json] [--start-time T]
// [--dwell S] [--for AGENT] [--domain N] [--timeout S]`: asks a routing agent for a route
// and prints it as JSON (docs/droverctl.md). Exit 0 with a route; 1 when planning or
// reserving failed (the reason is printed); 2 for bad usage or input (a bad vehicle file,
// an unknown vertex); 3 when no routing agent answered.

#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include <unistd.h>

#include <nlohmann/json.hpp>

#include "agents/cli/json_line.hpp"
#include "agents/cli/command.hpp"
#include "agents/cli/dds_tool_options.hpp"
#include "agents/cli/droverctl_commands.hpp"
#include "agents/routing_agent/route_wire.hpp"
#include "drover/carp/vehicle.hpp"
#include "drover/carp/vehicle_profile_json.hpp"
#include "drover/dds/service_client.hpp"
#include "drover/dds/wire_error.hpp"
#include "routing.h"

namespace drover::cli {
namespace {

struct RouteArguments {
  DdsToolOptions dds;
  std::string from;
  std::string to;
  std::string routing_agent;
  bool test = false;
  std::string vehicle_file;
  std::optional<TimeNs> start_time;
  std::optional<double> dwell_seconds;
  std::string owner;
};

nlohmann::json time_json(TimeNs t) { return t == kForever ? nlohmann::json(nullptr) : nlohmann::json(t); }

nlohmann::json route_json(const msg::RouteReply& reply, const std::string& agent, bool real) {
  nlohmann::json steps = nlohmann::json::array();
  for (const auto& step : reply.steps()) {
    steps.push_back({{"entity", step.entity()},
                     {"start_ns", step.window().start()},
                     {"end_ns", time_json(step.window().end())}});
  }
  nlohmann::json stops = nlohmann::json::array();
  for (std::size_t i = 0; i < reply.stop_steps().size(); ++i) {
    stops.push_back({{"step", reply.stop_steps()[i]},
                     {"arrival_ns", i < reply.stop_arrivals().size() ? reply.stop_arrivals()[i] : 0}});
  }
  return {{"routing_agent", reply.header().responder()},
          {"agent", agent},
          {"real", real},
          {"route", reply.route()},
          {"attempts", reply.attempts()},
          {"distance_m", reply.distance()},
          {"arrival_ns", reply.arrival()},
          {"travel_time_ns", reply.travel_time()},
          {"stops", stops},
          {"steps", steps}};
}

int run_route(const RouteArguments& arguments) {
  carp::VehicleProfile vehicle;
  if (!arguments.vehicle_file.empty()) {
    auto read = carp::read_vehicle_profile(arguments.vehicle_file);
    if (!read) {
      std::cerr << "error: --vehicle " << read.error().message << "\n";
      return kExitBadInput;
    }
    vehicle = std::move(*read);
  }
  auto participant = open_tool_participant(arguments.dds);
  if (!participant) {
    std::cerr << "error: " << participant.error().message << "\n";
    return participant.error().code == ErrorCode::invalid_argument ? kExitBadInput : kExitFailure;
  }
  int exit_code = kExitOk;
  {
    auto client = dds::ServiceClient<msg::RouteRequest, msg::RouteReply>::create(**participant, "routing", "route");
    if (!client) {
      std::cerr << "error: " << client.error().message << "\n";
      return kExitFailure;
    }
    msg::RouteRequest request;
    request.agent(arguments.owner.empty() ? (*participant)->agent_id() : arguments.owner);
    request.real(!arguments.test);
    request.vehicle(routing_agent::to_wire(vehicle));
    request.start(arguments.from);
    request.start_time(arguments.start_time.value_or(0));
    msg::RouteStop stop;
    stop.vertex(arguments.to);
    stop.has_dwell(arguments.dwell_seconds.has_value());
    stop.dwell(seconds_to_ns(arguments.dwell_seconds.value_or(0.0)));
    request.stops().push_back(stop);
    auto reply = (*client)->call(request, arguments.dds.timeout(), arguments.routing_agent);
    if (!reply) {
      std::cerr << "error: no routing agent answered: " << reply.error().message << "\n";
      exit_code = kExitNoAnswer;
    } else if (auto status = dds::from_wire(reply->error()); !status) {
      std::cerr << "error: " << to_string(status.error().code) << ": " << status.error().message << "\n";
      if (!reply->failure().empty()) std::cerr << "failure: " << reply->failure() << "\n";
      const auto code = status.error().code;
      exit_code = code == ErrorCode::invalid_argument || code == ErrorCode::not_found ? kExitBadInput : kExitFailure;
    } else {
      std::cout << json_line(route_json(*reply, request.agent(), request.real())) << "\n";
    }
  }
  return exit_code;
}

}  // namespace

void add_route_command(CLI::App& app, CommandContext& context) {
  auto arguments = std::make_shared<RouteArguments>();
  auto* command = app.add_subcommand("route", "Ask a routing agent for a route (real unless --test), print it as JSON");
  command->add_option("FROM", arguments->from, "Start vertex id")->required()->check(cli::identifier());
  command->add_option("TO", arguments->to, "Destination vertex id")->required()->check(cli::identifier());
  command->add_option("--agent", arguments->routing_agent, "Routing agent to ask (default: any)")
      ->check(cli::identifier());
  command->add_flag("--test", arguments->test, "Test route: planned, nothing reserved");
  command->add_option("--vehicle", arguments->vehicle_file, "Vehicle profile JSON file (default: carp defaults)")
      ->check(cli::non_empty());
  command->add_option("--start-time", arguments->start_time,
                      "Shared-clock start time, ns (default: now on the routing agent's clock)")
      ->transform(cli::exact_whole_in(1, kLatestTime));
  command->add_option("--dwell", arguments->dwell_seconds,
                      "Hold the destination this many seconds (default: open-ended, until the next route)")
      ->transform(cli::positive());
  command->add_option("--for", arguments->owner, "Agent the route is for (default: droverctl-<pid>)")
      ->check(cli::identifier());
  add_dds_tool_options(*command, arguments->dds, 5.0);
  command->callback([arguments, &context] { context.exit_code = run_route(*arguments); });
}

}  // namespace drover::cli
