// `droverctl timeline ENTITY [--json]`: the entity's timeline as its topology agent last
// published it: version, reservations (real and shadow), locks, allocation holder and queue.

#include <condition_variable>
#include <iostream>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "agents/cli/json_line.hpp"
#include "agents/cli/dds_tool_options.hpp"
#include "agents/cli/droverctl_commands.hpp"
#include "agents/cli/topology_tool.hpp"
#include "agents/topology_agent/topology_agent.hpp"
#include "drover/dds/reader.hpp"

namespace drover::cli {
namespace {

struct TimelineArguments {
  DdsToolOptions dds;
  std::string entity;
  bool json = false;
};

std::string end_text(TimeNs end) { return end == kForever ? std::string("forever") : std::to_string(end); }

void print_json(const msg::TimelineState& state) {
  nlohmann::json reservations = nlohmann::json::array();
  for (const auto& item : state.reservations()) {
    reservations.push_back({{"agent", item.agent()},
                            {"route", item.route()},
                            {"step", item.step()},
                            {"origin", item.origin()},
                            {"shadow", item.origin() != item.entity()},
                            {"start_ns", item.window().start()},
                            {"end_ns", item.window().end()},
                            {"prepared", item.prepared()}});
  }
  nlohmann::json locks = nlohmann::json::array();
  for (const auto& lock : state.locks()) {
    locks.push_back({{"id", lock.id()},
                     {"start_ns", lock.window().start()},
                     {"end_ns", lock.window().end()},
                     {"operator", lock.operator_id()},
                     {"reason", lock.reason()}});
  }
  nlohmann::json out{{"entity", state.entity()},
                     {"version", state.version()},
                     {"holder", state.holder().empty() ? nlohmann::json(nullptr) : nlohmann::json(state.holder())},
                     {"waiting", state.waiting()},
                     {"reservations", reservations},
                     {"locks", locks}};
  std::cout << json_line(out) << "\n";
}

void print_table(const msg::TimelineState& state) {
  std::cout << "entity " << state.entity() << "  version " << state.version() << "  holder "
            << (state.holder().empty() ? "-" : state.holder()) << "  waiting";
  if (state.waiting().empty()) std::cout << " -";
  for (const auto& agent : state.waiting()) std::cout << " " << agent;
  std::cout << "\n\nRESERVATIONS\n";
  if (state.reservations().empty()) std::cout << "  (none)\n";
  for (const auto& item : state.reservations()) {
    std::cout << "  " << item.agent() << "  route " << item.route() << "  step " << item.step() << "  ["
              << item.window().start() << ", " << end_text(item.window().end()) << ")"
              << (item.origin() != item.entity() ? "  shadow of " + item.origin() : "")
              << (item.prepared() ? "  prepared" : "") << "\n";
  }
  std::cout << "\nLOCKS\n";
  if (state.locks().empty()) std::cout << "  (none)\n";
  for (const auto& lock : state.locks()) {
    std::cout << "  " << lock.id() << "  [" << lock.window().start() << ", " << end_text(lock.window().end())
              << ")  by " << lock.operator_id() << ": " << lock.reason() << "\n";
  }
}

int run_timeline(const TimelineArguments& arguments) {
  auto participant = open_tool_participant(arguments.dds);
  if (!participant) {
    std::cerr << "error: " << participant.error().message << "\n";
    return participant.error().code == ErrorCode::invalid_argument ? kExitBadInput : kExitFailure;
  }
  std::mutex mutex;
  std::condition_variable arrived;
  std::optional<msg::TimelineState> state;
  auto reader = dds::Reader<msg::TimelineState>::create(
      **participant, topology_agent::kTimelineTopic, [&](const msg::TimelineState& sample) {
        if (sample.entity() != arguments.entity) return;
        std::lock_guard lock(mutex);
        state = sample;
        arrived.notify_all();
      });
  if (!reader) {
    std::cerr << "error: " << reader.error().message << "\n";
    return kExitFailure;
  }
  // The owner tells whether the entity exists; its timeline then comes (transient local).
  // One --timeout bounds both waits.
  const auto deadline = std::chrono::steady_clock::now() + arguments.dds.timeout();
  auto owner = find_owner(**participant, arguments.entity, arguments.dds.timeout());
  if (!owner) {
    std::cerr << "error: " << owner.error().message << " on domain " << arguments.dds.domain_id << " within "
              << arguments.dds.timeout_seconds << " s\n";
    return exit_code_of(owner.error());
  }
  std::optional<msg::TimelineState> shown;
  {
    std::unique_lock lock(mutex);
    arrived.wait_until(lock, deadline, [&] { return state.has_value(); });
    shown = state;
  }
  (*reader).reset();
  if (!shown) {
    std::cerr << "error: topology agent '" << owner->id << "' published no timeline of '" << arguments.entity
              << "' within " << arguments.dds.timeout_seconds << " s\n";
    return kExitNoAnswer;
  }
  if (arguments.json) {
    print_json(*shown);
  } else {
    print_table(*shown);
  }
  return kExitOk;
}

}  // namespace

void add_timeline_command(CLI::App& app, CommandContext& context) {
  auto arguments = std::make_shared<TimelineArguments>();
  auto* command = app.add_subcommand(
      "timeline", "Show an entity's timeline: reservations, locks, allocation holder and queue");
  command->add_option("ENTITY", arguments->entity, "Entity id (vertex or edge)")->required()->check(cli::identifier());
  command->add_flag("--json", arguments->json, "Print one JSON object instead of a table");
  add_dds_tool_options(*command, arguments->dds, 5.0);
  command->callback([arguments, &context] { context.exit_code = run_timeline(*arguments); });
}

}  // namespace drover::cli
