// `droverctl orders [--vehicle V] [--domain N] [--timeout S] [--json]`: the orders the
// logical agents of a domain know (their queues, running orders and the ended orders they
// remember), from the progress they publish (drover/logical/order_progress, kept for late
// joiners). Exit 3 when no logical agent is heard within the timeout.

#include <algorithm>
#include <iostream>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "agents/cli/json_line.hpp"
#include "agents/cli/agent_discovery.hpp"
#include "agents/cli/command.hpp"
#include "agents/cli/dds_tool_options.hpp"
#include "agents/cli/droverctl_commands.hpp"
#include "agents/cli/table.hpp"
#include "drover/dds/reader.hpp"
#include "drover/logical_agent/messages.hpp"
#include "drover/logical_agent/names.hpp"
#include "drover/logical_agent/wire_names.hpp"

namespace drover::cli {
namespace {

struct OrdersArguments {
  DdsToolOptions dds;
  std::string vehicle;
  bool json = false;
};

/// The latest progress of each order (by vehicle and name), as it arrives.
class OrderProgresses {
 public:
  explicit OrderProgresses(std::string vehicle) : vehicle_(std::move(vehicle)) {}
  void on_progress(const msg::OrderProgress& progress) {
    if (!vehicle_.empty() && progress.vehicle() != vehicle_) return;
    std::lock_guard lock(mutex_);
    orders_[{progress.vehicle(), progress.order()}] = progress;
  }
  std::map<std::pair<std::string, std::string>, msg::OrderProgress> orders() const {
    std::lock_guard lock(mutex_);
    return orders_;
  }

 private:
  const std::string vehicle_;
  mutable std::mutex mutex_;
  std::map<std::pair<std::string, std::string>, msg::OrderProgress> orders_;
};

nlohmann::json optional_time(const msg::OptionalTime& time) {
  return time.present() ? nlohmann::json(time.ns()) : nlohmann::json(nullptr);
}

int run_orders(const OrdersArguments& arguments) {
  auto participant = open_tool_participant(arguments.dds);
  if (!participant) {
    std::cerr << "error: " << participant.error().message << "\n";
    return participant.error().code == ErrorCode::invalid_argument ? kExitBadInput : kExitFailure;
  }
  OrderProgresses collected(arguments.vehicle);
  auto reader = dds::Reader<msg::OrderProgress>::create(
      **participant, logical_agent::kOrderProgressTopic,
      [&collected](const msg::OrderProgress& progress) { collected.on_progress(progress); });
  if (!reader) {
    std::cerr << "error: " << reader.error().message << "\n";
    return kExitFailure;
  }
  // How many orders an agent remembers is not announced: the progress kept for late joiners
  // is listened to for the whole timeout.
  const auto agents = discover_live_agents(**participant, arguments.dds.timeout(), [](const auto&) { return false; });
  if (!agents) {
    std::cerr << "error: " << agents.error().message << "\n";
    return kExitFailure;
  }
  const auto orders = collected.orders();
  reader->reset();  // before `collected`, which its callback fills
  const auto vehicles = live_logical_vehicles(*agents);
  const bool logical_heard = arguments.vehicle.empty()
                                 ? !vehicles.empty()
                                 : std::binary_search(vehicles.begin(), vehicles.end(), arguments.vehicle);
  if (!logical_heard && orders.empty()) {
    std::cerr << "error: no logical agent" << (arguments.vehicle.empty() ? "" : " of vehicle '" + arguments.vehicle + "'")
              << " answered on domain " << arguments.dds.domain_id << " within " << arguments.dds.timeout_seconds
              << " s\n";
    return kExitNoAnswer;
  }
  if (arguments.json) {
    nlohmann::json out = nlohmann::json::array();
    for (const auto& [key, progress] : orders) {
      out.push_back({{"vehicle", progress.vehicle()},
                     {"order", progress.order()},
                     {"state", std::string(logical_agent::order_state_name(progress.state()))},
                     {"destination", progress.destination()},
                     {"destination_count", progress.destination_count()},
                     {"created_ns", optional_time(progress.created())},
                     {"started_ns", optional_time(progress.started())},
                     {"finished_ns", optional_time(progress.finished())},
                     {"failure", progress.failure()}});
    }
    std::cout << json_line(out) << "\n";
    return kExitOk;
  }
  std::vector<std::vector<std::string>> rows;
  for (const auto& [key, progress] : orders) {
    rows.push_back({progress.vehicle(), progress.order(), std::string(logical_agent::order_state_name(progress.state())),
                    std::to_string(progress.destination()) + "/" + std::to_string(progress.destination_count()),
                    progress.failure().empty() ? "-" : progress.failure()});
  }
  print_table(std::cout, {"VEHICLE", "ORDER", "STATE", "DESTINATION", "REASON"}, rows);
  return kExitOk;
}

}  // namespace

void add_orders_command(CLI::App& app, CommandContext& context) {
  auto arguments = std::make_shared<OrdersArguments>();
  auto* command = app.add_subcommand(
      "orders", "The orders the logical agents know: queued, running and the ended ones they remember, with progress");
  add_dds_tool_options(*command, arguments->dds, 2.0);
  command->add_option("--vehicle", arguments->vehicle, "Only the orders of this vehicle")->check(cli::identifier());
  command->add_flag("--json", arguments->json, "Print a JSON array instead of a table");
  command->callback([arguments, &context] { context.exit_code = run_orders(*arguments); });
}

}  // namespace drover::cli
