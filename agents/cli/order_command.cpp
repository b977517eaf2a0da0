// `droverctl order send VEHICLE LOCATION:OPERATION [LOCATION:OPERATION ...] [--name NAME]
// [--wait S]`: sends a transport order to one vehicle's logical agent
// (drover/logical/order, docs/logical-agent.md). Prints the order name and its place in the
// vehicle's queue; with --wait, also waits for the order to finish or fail. Exit 0: queued
// (with --wait: finished); 1: refused, failed, or not done within --wait; 2: bad usage (a
// destination without ':'); 3: no logical agent of that vehicle answered.
//
// `droverctl order withdraw VEHICLE ORDER [--reason TEXT] [--wait S]`: withdraws one of the
// vehicle's orders (drover/logical/withdraw). Exit 0: withdrawn, or being withdrawn (with
// --wait: withdrawn within S); 1: refused (no such order, it has ended), or it ended
// otherwise or not within --wait; 3: no logical agent of that vehicle answered.

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
#include "agents/cli/logical_agent_call.hpp"
#include "drover/common/clock.hpp"
#include "drover/common/identifier.hpp"
#include "drover/dds/reader.hpp"
#include "drover/dds/service_client.hpp"
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

struct WithdrawArguments {
  DdsToolOptions dds;
  std::string vehicle;
  std::string order;
  std::string reason;
  double wait_seconds = 0;
};

bool ended(msg::OrderState state) {
  return state == msg::ORDER_FINISHED || state == msg::ORDER_FAILED || state == msg::ORDER_WITHDRAWN;
}

/// How an order ended, for messages: "finished", "failed: why", "withdrawn (reason)".
std::string end_text(const msg::OrderProgress& progress) {
  switch (progress.state()) {
    case msg::ORDER_FINISHED: return "finished";
    case msg::ORDER_FAILED: return "failed: " + progress.failure();
    case msg::ORDER_WITHDRAWN:
      return progress.failure().empty() ? "withdrawn" : "withdrawn (" + progress.failure() + ")";
    default: return "not ended";
  }
}

/// Waits for the terminal progress of one order of one vehicle.
class ProgressWatch {
 public:
  void on_progress(const msg::OrderProgress& progress) {
    std::lock_guard lock(mutex_);
    // Names are unique per vehicle only: another vehicle's order of the same name (ended
    // long ago, kept for late joiners) says nothing of this one.
    if (progress.order() != order_ || progress.vehicle() != vehicle_) return;
    if (ended(progress.state())) {
      final_ = progress;
      ended_.notify_all();
    }
  }
  void watch(std::string vehicle, std::string order) {
    std::lock_guard lock(mutex_);
    vehicle_ = std::move(vehicle);
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
  std::string vehicle_;
  std::string order_;
  std::optional<msg::OrderProgress> final_;
};

/// A tool participant watching one order's progress (when `wait_seconds` > 0) and a client
/// of one of the logical agents' services.
/// Members in the order they are made: destroyed the other way round, the DDS entities go
/// before their participant and the reader before the watch it calls.
template <class Request, class Reply>
class OrderSession {
  std::unique_ptr<dds::Participant> participant_;
  ProgressWatch watch_;
  std::unique_ptr<dds::Reader<msg::OrderProgress>> progress_;
  std::unique_ptr<dds::ServiceClient<Request, Reply>> client_;

  /// \return kExitOk, or the exit code after printing why it could not be opened.
  int open(const DdsToolOptions& options, const char* service, const std::string& vehicle, const std::string& order,
           double wait_seconds) {
    auto opened = open_tool_participant(options);
    if (!opened) {
      std::cerr << "error: " << opened.error().message << "\n";
      return opened.error().code == ErrorCode::invalid_argument ? kExitBadInput : kExitFailure;
    }
    participant_ = std::move(*opened);
    watch_.watch(vehicle, order);
    if (wait_seconds > 0) {
      auto reader = dds::Reader<msg::OrderProgress>::create(
          *participant_, logical_agent::kOrderProgressTopic,
          [this](const msg::OrderProgress& sample) { watch_.on_progress(sample); });
      if (!reader) {
        std::cerr << "error: " << reader.error().message << "\n";
        return kExitFailure;
      }
      progress_ = std::move(*reader);
    }
    auto made = dds::ServiceClient<Request, Reply>::create(*participant_, logical_agent::kServiceArea, service);
    if (!made) {
      std::cerr << "error: " << made.error().message << "\n";
      return kExitFailure;
    }
    client_ = std::move(*made);
    return kExitOk;
  }

 public:
  /// Opens the session, then sends `request` to `vehicle`'s logical agent. \return its reply
  /// when the agent accepted the request; otherwise nullopt, with the reason printed and
  /// `exit_code` set (`refused` says what a refusing agent did not do: "refused order 'x'").
  std::optional<Reply> ask(const DdsToolOptions& options, const char* service, const std::string& vehicle,
                           const Request& request, const std::string& order, double wait_seconds,
                           const std::string& refused, int& exit_code) {
    exit_code = open(options, service, vehicle, order, wait_seconds);
    if (exit_code != kExitOk) return std::nullopt;
    return call_logical_agent(*client_, options, vehicle, request, refused, exit_code);
  }
  /// Waits up to `wait_seconds` for `order` to end in state `expected`. \return kExitOk after
  /// printing "order 'x' <done>", or kExitFailure after printing "... <not_done> within S s"
  /// or how it ended otherwise followed by `otherwise`.
  int await_end(const std::string& order, double wait_seconds, msg::OrderState expected, const char* done,
                const char* not_done, const char* otherwise) {
    const auto final_state = watch_.wait(std::chrono::milliseconds(static_cast<std::int64_t>(wait_seconds * 1000)));
    if (!final_state) {
      std::cerr << "error: order '" << order << "' " << not_done << " within " << wait_seconds << " s\n";
      return kExitFailure;
    }
    if (final_state->state() != expected) {
      std::cerr << "error: order '" << order << "' " << end_text(*final_state) << otherwise << "\n";
      return kExitFailure;
    }
    std::cout << "order '" << order << "' " << done << "\n";
    return kExitOk;
  }
};

int send(const OrderArguments& arguments) {
  msg::OrderRequest request;
  request.order(arguments.name.empty()
                    ? arguments.vehicle + "-" + std::to_string(SharedClock::unix_now())
                    : arguments.name);
  if (auto problem = identifier_problem(request.order()); problem && arguments.name.empty()) {
    // The default name, made from a long vehicle id: the operator never gave it.
    std::cerr << "error: the default order name <vehicle>-<time> " << *problem << "; give one with --name\n";
    return kExitBadInput;
  }
  for (const auto& text : arguments.destinations) {
    const auto colon = text.rfind(':');
    if (colon == std::string::npos || colon == 0 || colon + 1 == text.size()) {
      std::cerr << "error: destination '" << text << "': expected LOCATION:OPERATION (e.g. station-1:load)\n";
      return kExitBadInput;
    }
    msg::OrderDestination destination;
    destination.location(text.substr(0, colon));
    destination.operation(text.substr(colon + 1));
    request.destinations().push_back(destination);
  }
  OrderSession<msg::OrderRequest, msg::OrderReply> session;
  int code = kExitOk;
  const auto reply = session.ask(arguments.dds, logical_agent::kOrderService, arguments.vehicle, request,
                                 request.order(), arguments.wait_seconds,
                                 "refused order '" + request.order() + "'", code);
  if (!reply) return code;
  std::cout << "order '" << request.order() << "' queued on '" << arguments.vehicle << "' at position "
            << reply->queue_position() << "\n";
  if (arguments.wait_seconds <= 0) return kExitOk;
  return session.await_end(request.order(), arguments.wait_seconds, msg::ORDER_FINISHED, "finished", "not done", "");
}

int withdraw(const WithdrawArguments& arguments) {
  msg::OrderWithdrawRequest request;
  request.order(arguments.order);
  request.reason(arguments.reason);
  OrderSession<msg::OrderWithdrawRequest, msg::OrderWithdrawReply> session;
  int code = kExitOk;
  const auto reply = session.ask(arguments.dds, logical_agent::kWithdrawService, arguments.vehicle, request,
                                 arguments.order, arguments.wait_seconds,
                                 "did not withdraw order '" + arguments.order + "'", code);
  if (!reply) return code;
  if (reply->state() == msg::ORDER_WITHDRAWN) {
    std::cout << "order '" << arguments.order << "' withdrawn\n";
    return kExitOk;
  }
  std::cout << "order '" << arguments.order << "' being withdrawn: vehicle '" << arguments.vehicle
            << "' stops at the next vertex it can\n";
  if (arguments.wait_seconds <= 0) return kExitOk;
  return session.await_end(arguments.order, arguments.wait_seconds, msg::ORDER_WITHDRAWN, "withdrawn",
                           "not withdrawn", " before it could be withdrawn");
}

}  // namespace

void add_order_command(CLI::App& app, CommandContext& context) {
  auto arguments = std::make_shared<OrderArguments>();
  auto* order = app.add_subcommand("order", "Transport orders of the logical agents");
  order->require_subcommand(1);
  auto* send_command = order->add_subcommand("send", "Send an order to one vehicle's logical agent");
  send_command->add_option("vehicle", arguments->vehicle, "The vehicle id")->required()->check(cli::identifier());
  send_command->add_option("destinations", arguments->destinations,
                           "LOCATION:OPERATION, in execution order (operation NOP, load, unload, charge, "
                           "park or a custom action)")
      ->required();
  send_command->add_option("--name", arguments->name, "The order's unique name (default: <vehicle>-<time>)")
      ->check(cli::identifier());
  send_command->add_option("--wait", arguments->wait_seconds,
                           "Also wait up to S seconds for the order to finish (exit 1 if it fails)")
      ->transform(cli::non_negative());
  add_dds_tool_options(*send_command, arguments->dds, 5.0);
  send_command->callback([arguments, &context] { context.exit_code = send(*arguments); });

  auto withdrawal = std::make_shared<WithdrawArguments>();
  auto* withdraw_command = order->add_subcommand(
      "withdraw", "Withdraw an order: a queued one at once, a running one once the vehicle stands on a vertex");
  withdraw_command->add_option("vehicle", withdrawal->vehicle, "The vehicle id")->required()->check(cli::identifier());
  withdraw_command->add_option("order", withdrawal->order, "The order's name")->required()->check(cli::identifier());
  withdraw_command->add_option("--reason", withdrawal->reason, "Why (shown in the order's progress)");
  withdraw_command->add_option("--wait", withdrawal->wait_seconds,
                               "Also wait up to S seconds until a running order is withdrawn (exit 1 if it ends "
                               "otherwise)")
      ->transform(cli::non_negative());
  add_dds_tool_options(*withdraw_command, withdrawal->dds, 5.0);
  withdraw_command->callback([withdrawal, &context] { context.exit_code = withdraw(*withdrawal); });
}

}  // namespace drover::cli
