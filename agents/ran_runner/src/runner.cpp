#include "drover/ran_runner/runner.hpp"

#include <utility>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "drover/common/identifier.hpp"
#include "drover/dds/service_server.hpp"
#include "drover/dds/shutdown_signal.hpp"
#include "drover/dds/wire_error.hpp"
#include "drover/dds/writer.hpp"
#include "drover/ran_runner/wire.hpp"
#include "ran_messages.hpp"

namespace drover::ran {

std::string ran_agent_id(const std::string& vehicle_id) { return "ran-" + vehicle_id; }

// Publishes every report and remembers the last one (for the command replies).
class RanRunner::Sink final : public StatusSink {
 public:
  explicit Sink(std::unique_ptr<dds::Writer<msg::RanStatus>> writer) : writer_(std::move(writer)) {}

  /// The last report delivered, if any.
  std::optional<VehicleStatus> last() const {
    std::lock_guard lock(mutex_);
    return last_;
  }

 protected:
  void deliver(const VehicleStatus& status) override {
    {
      std::lock_guard lock(mutex_);
      last_ = status;
    }
    if (auto written = writer_->write(to_wire(status)); !written) {
      spdlog::warn("{}: status not published: {}", status.vehicle_id, written.error().message);
    }
  }

 private:
  std::unique_ptr<dds::Writer<msg::RanStatus>> writer_;
  mutable std::mutex mutex_;
  std::optional<VehicleStatus> last_;
};

// Serves drover/ran/command: delivers each command to the driver and replies.
class RanRunner::CommandServer {
 public:
  using Server = dds::ServiceServer<msg::RanCommandRequest, msg::RanCommandReply>;

  static Result<std::unique_ptr<CommandServer>> create(dds::Participant& participant,
                                                       RanRunner& runner) {
    auto handler = std::make_unique<CommandServer>(runner);
    auto server = Server::create(
        participant, kServiceArea, kCommandService,
        [raw = handler.get()](const msg::RanCommandRequest& request,
                              dds::ReplyHandle<msg::RanCommandReply> reply) {
          auto sent = reply.send(raw->handle(request));
          if (!sent) spdlog::warn("ran command reply not sent: {}", sent.error().message);
        });
    if (!server) return unexpected(server.error());
    handler->server_ = std::move(*server);
    return handler;
  }

  explicit CommandServer(RanRunner& runner) : runner_(runner) {}

 private:
  /// The id the driver will list the command under (empty for pause / resume).
  static std::string command_id(const msg::RanCommandRequest& request) {
    switch (request.kind()) {
      case msg::RAN_COMMAND_MOVE: return request.move().id();
      case msg::RAN_COMMAND_ACTION: return request.action().id();
      default: return {};
    }
  }

  msg::RanCommandReply handle(const msg::RanCommandRequest& request) {
    msg::RanCommandReply reply;
    const auto refuse = [&](ErrorCode code, std::string message) {
      reply.error(dds::to_wire(Error{code, std::move(message)}));
      return reply;
    };
    if (request.vehicle_id() != runner_.options_.vehicle_id) {
      return refuse(ErrorCode::not_found,
                    fmt::format("this RAN drives vehicle '{}', not '{}'",
                                runner_.options_.vehicle_id, request.vehicle_id()));
    }
    std::optional<ActionCommand> action;
    if (request.kind() == msg::RAN_COMMAND_ACTION) {
      auto converted = from_wire(request.action());
      if (!converted) return refuse(converted.error().code, converted.error().message);
      action = std::move(*converted);
    }
    std::lock_guard lock(runner_.driver_mutex_);
    VehicleDriver& driver = runner_.driver_;
    if (!driver.connected()) {
      return refuse(ErrorCode::unavailable,
                    fmt::format("vehicle '{}' is not connected", runner_.options_.vehicle_id));
    }
    const auto before = runner_.sink_->last();
    const TimeNs now = runner_.clock_.now();
    switch (request.kind()) {
      case msg::RAN_COMMAND_MOVE: driver.on_move(from_wire(request.move()), now); break;
      case msg::RAN_COMMAND_ACTION: driver.on_action(*action, now); break;
      case msg::RAN_COMMAND_CANCEL: driver.on_cancel(request.cancel_id(), now); break;
      case msg::RAN_COMMAND_PAUSE: driver.on_pause(now); break;
      case msg::RAN_COMMAND_RESUME: driver.on_resume(now); break;
      default:
        return refuse(ErrorCode::invalid_argument,
                      fmt::format("unknown command kind {}", static_cast<int>(request.kind())));
    }
    reply.error(dds::wire_ok());
    // The driver's verdict, when it reported the command during the call.
    const auto after = runner_.sink_->last();
    const std::string id = command_id(request);
    const bool reported = after && (!before || after->sequence > before->sequence);
    if (reported && !id.empty()) {
      if (const auto* progress = after->find_command(id)) {
        reply.state(to_string(progress->state));
        reply.code(progress->code);
        reply.reason(progress->reason);
      }
    }
    return reply;
  }

  RanRunner& runner_;
  std::unique_ptr<Server> server_;
};

RanRunner::RanRunner(SharedClock clock, VehicleDriver& driver, RanRunnerOptions options)
    : clock_(clock), driver_(driver), options_(std::move(options)) {}

Result<std::unique_ptr<RanRunner>> RanRunner::create(dds::Participant& participant,
                                                     SharedClock clock, VehicleDriver& driver,
                                                     RanRunnerOptions options) {
  if (auto valid = check_identifier(options.vehicle_id, "ran runner: vehicle id"); !valid) {
    return unexpected(valid.error());
  }
  if (options.status_period.count() <= 0) {
    return fail(ErrorCode::invalid_argument, "ran runner: status period must be positive");
  }
  std::unique_ptr<RanRunner> runner(new RanRunner(clock, driver, std::move(options)));
  auto writer = dds::Writer<msg::RanStatus>::create(participant, kStatusTopic);
  if (!writer) return unexpected(writer.error());
  runner->sink_ = std::make_unique<Sink>(std::move(*writer));
  {
    std::lock_guard lock(runner->driver_mutex_);
    driver.start(*runner->sink_, clock.now());
  }
  auto server = CommandServer::create(participant, *runner);
  if (!server) return unexpected(server.error());
  runner->server_ = std::move(*server);
  runner->tick_thread_ = std::thread([raw = runner.get()] { raw->tick_loop(); });
  return runner;
}

RanRunner::~RanRunner() {
  {
    std::lock_guard lock(tick_mutex_);
    stopping_ = true;
  }
  tick_wake_.notify_all();
  if (tick_thread_.joinable()) tick_thread_.join();
  server_.reset();  // no handler runs after this
  std::lock_guard lock(driver_mutex_);
  driver_.stop(clock_.now());
}

void RanRunner::with_driver(const std::function<void(TimeNs now)>& action) {
  std::lock_guard lock(driver_mutex_);
  action(clock_.now());
  driver_.on_tick(clock_.now());
}

void RanRunner::tick_loop() {
  std::unique_lock lock(tick_mutex_);
  auto next = std::chrono::steady_clock::now();
  while (!stopping_) {
    next += options_.status_period;
    if (tick_wake_.wait_until(lock, next, [&] { return stopping_; })) break;
    lock.unlock();
    {
      std::lock_guard driver_lock(driver_mutex_);
      driver_.on_tick(clock_.now());
    }
    lock.lock();
    // After a stall (a loaded machine), tick again at once but do not try to catch up.
    next = std::max(next, std::chrono::steady_clock::now() - options_.status_period);
  }
}

Result<std::unique_ptr<RanNode>> RanNode::create(VehicleDriver& driver, const RanNodeOptions& options,
                                                 SharedClock clock) {
  dds::ParticipantOptions participant_options;
  participant_options.domain_id = options.domain_id;
  participant_options.agent_id =
      options.agent_id.empty() ? ran_agent_id(options.vehicle_id) : options.agent_id;
  participant_options.xml_profile_file = options.xml_profile_file;
  std::unique_ptr<RanNode> node(new RanNode());
  auto participant = dds::Participant::create(participant_options);
  if (!participant) return unexpected(participant.error());
  node->participant_ = std::move(*participant);

  dds::HeartbeatOptions heartbeat;
  heartbeat.kind = "ran";
  heartbeat.owns = {options.vehicle_id};
  auto beating = dds::HeartbeatPublisher::create(*node->participant_, clock, heartbeat);
  if (!beating) return unexpected(beating.error());
  node->heartbeat_ = std::move(*beating);

  RanRunnerOptions runner_options;
  runner_options.vehicle_id = options.vehicle_id;
  runner_options.status_period = options.status_period;
  auto runner = RanRunner::create(*node->participant_, clock, driver, runner_options);
  if (!runner) return unexpected(runner.error());
  node->runner_ = std::move(*runner);
  return node;
}

RanNode::~RanNode() {
  // Reverse order of creation: everything on the participant goes before it.
  runner_.reset();
  heartbeat_.reset();
  participant_.reset();
}

Status run_ran_node(VehicleDriver& driver, const RanNodeOptions& options, SharedClock clock) {
  if (auto installed = dds::install_shutdown_handlers(); !installed) return installed;
  auto node = RanNode::create(driver, options, clock);
  if (!node) return unexpected(node.error());
  spdlog::info("RAN for vehicle '{}' running as agent '{}' on domain {}", options.vehicle_id,
               (*node)->participant().agent_id(), options.domain_id);
  dds::wait_for_shutdown();
  return {};
}

}  // namespace drover::ran
