// `droverctl order send VEHICLE LOCATION:OPERATION [LOCATION:OPERATION ...] [--name NAME]
// [--wait S]`: sends a transport order to one vehicle's logical agent
// (drover/logical/order, docs/logical-agent.md). Prints the order name and its place in the
// vehicle's queue; with --wait, also waits for the order to finish or fail. Exit 0: queued
// (with --wait: finished); 1: refused, failed, or not done within --wait; 2: bad usage (a
// destination without ':'); 3: no logical agent of that vehicle answered.

#include <chrono>
#include <condition_variable>
#include <iostream>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "agents/cli/command.hpp"
#include "agents/cli/dds_tool_options.hpp"
#include "agents/cli/droverctl_commands.hpp"
#include "drover/common/clock.hpp"
#include "drover/dds/reader.hpp"
#include "drover/dds/service_client.hpp"
#include "drover/dds/wire_error.hpp"
#include "drover/logical_agent/messages.hpp"
#include "drover/logical_agent/names.hpp"

namespace drover::cli {
namespace {

struct OrderArguments {
  DdsToolOptions dds;
  std::string vehicle;
  std::vector<std::string> destinations;
  std::string name;
  double wait_seconds = 0;
};

/// Waits for the terminal progress of one order.
class ProgressWatch {
 public:
  void on_progress(const msg::OrderProgress& progress) {
    std::lock_guard lock(mutex_);
    if (progress.order() != order_) return;
    if (progress.state() == msg::ORDER_FINISHED || progress.state() == msg::ORDER_FAILED) {
      final_ = progress;
      ended_.notify_all();
    }
  }
  void watch(std::string order) {
    std::lock_guard lock(mutex_);
    order_ = std::move(order);
  }
  std::optional<msg::OrderProgress> wait(std::chrono::milliseconds timeout) {
    std::unique_lock lock(mutex_);
    ended_.wait_for(lock, timeout, [&] { return final_.has_value(); });
    return final_;
  }

 private:
  std::mutex mutex_;
  std::condition_variable ended_;
  std::string order_;
  std::optional<msg::OrderProgress> final_;
};

int send(const OrderArguments& arguments) {
  msg::OrderRequest request;
  request.order(arguments.name.empty()
                    ? arguments.vehicle + "-" + std::to_string(SharedClock::unix_now())
                    : arguments.name);
  for (const auto& text : arguments.destinations) {
    const auto colon = text.rfind(':');
    if (colon == std::string::npos || colon == 0) {
      std::cerr << "error: destination '" << text << "': expected LOCATION:OPERATION (e.g. station-1:load)\n";
      return kExitBadInput;
    }
    msg::OrderDestination destination;
    destination.location(text.substr(0, colon));
    destination.operation(text.substr(colon + 1));
    request.destinations().push_back(destination);
  }
  auto participant = open_tool_participant(arguments.dds);
  if (!participant) {
    std::cerr << "error: " << participant.error().message << "\n";
    return participant.error().code == ErrorCode::invalid_argument ? kExitBadInput : kExitFailure;
  }
  int code = kExitOk;
  {
    ProgressWatch watch;
    watch.watch(request.order());
    std::unique_ptr<dds::Reader<msg::OrderProgress>> progress;
    if (arguments.wait_seconds > 0) {
      auto reader = dds::Reader<msg::OrderProgress>::create(
          **participant, logical_agent::kOrderProgressTopic,
          [&watch](const msg::OrderProgress& sample) { watch.on_progress(sample); });
      if (!reader) {
        std::cerr << "error: " << reader.error().message << "\n";
        return kExitFailure;
      }
      progress = std::move(*reader);
    }
    auto client = dds::ServiceClient<msg::OrderRequest, msg::OrderReply>::create(
        **participant, logical_agent::kServiceArea, logical_agent::kOrderService);
    if (!client) {
      std::cerr << "error: " << client.error().message << "\n";
      return kExitFailure;
    }
    auto reply = (*client)->call(request, arguments.dds.timeout(), arguments.vehicle);
    if (!reply) {
      std::cerr << "error: vehicle '" << arguments.vehicle << "': " << reply.error().message << "\n";
      return reply.error().code == ErrorCode::timeout ? kExitNoAnswer : kExitFailure;
    }
    if (auto status = dds::from_wire(reply->error()); !status) {
      std::cerr << "error: vehicle '" << arguments.vehicle << "' refused order '" << request.order()
                << "': " << status.error().message << "\n";
      return kExitFailure;
    }
    std::cout << "order '" << request.order() << "' queued on '" << arguments.vehicle << "' at position "
              << reply->queue_position() << "\n";
    if (progress) {
      const auto wait = std::chrono::milliseconds(static_cast<std::int64_t>(arguments.wait_seconds * 1000));
      const auto final_state = watch.wait(wait);
      if (!final_state) {
        std::cerr << "error: order '" << request.order() << "' not done within " << arguments.wait_seconds << " s\n";
        code = kExitFailure;
      } else if (final_state->state() == msg::ORDER_FAILED) {
        std::cerr << "error: order '" << request.order() << "' failed: " << final_state->failure() << "\n";
        code = kExitFailure;
      } else {
        std::cout << "order '" << request.order() << "' finished\n";
      }
    }
  }
  return code;
}

}  // namespace

void add_order_command(CLI::App& app, CommandContext& context) {
  auto arguments = std::make_shared<OrderArguments>();
  auto* order = app.add_subcommand("order", "Transport orders of the logical agents");
  order->require_subcommand(1);
  auto* send_command = order->add_subcommand("send", "Send an order to one vehicle's logical agent");
  send_command->add_option("vehicle", arguments->vehicle, "The vehicle id")->required();
  send_command->add_option("destinations", arguments->destinations,
                           "LOCATION:OPERATION, in execution order (operation NOP, load, unload, charge, "
                           "park or a custom action)")
      ->required();
  send_command->add_option("--name", arguments->name, "The order's unique name (default: <vehicle>-<time>)");
  send_command->add_option("--wait", arguments->wait_seconds,
                           "Also wait up to S seconds for the order to finish (exit 1 if it fails)")
      ->transform(cli::non_negative());
  add_dds_tool_options(*send_command, arguments->dds, 5.0);
  send_command->callback([arguments, &context] { context.exit_code = send(*arguments); });
}

}  // namespace drover::cli
