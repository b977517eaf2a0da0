#include "drover/ran_runner/client.hpp"

#include <algorithm>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "drover/dds/wire_error.hpp"
#include "drover/ran_runner/wire.hpp"
#include "ran_messages.hpp"

namespace drover::ran {

namespace {

/// How long a status writer counts as reporting after its last status (TwinWriterWatch): a
/// RAN reports every status period, 100 ms unless configured otherwise.
constexpr std::chrono::seconds kTwinWindow{2};
/// Refusals further apart than a RAN may be silent (the logical agent's 3 s) are told anew.
constexpr std::chrono::seconds kEpisodeGap{3};

msg::SimFaultKind fault_to_wire(SimFault fault) {
  switch (fault) {
    case SimFault::stall: return msg::SIM_FAULT_STALL;
    case SimFault::protective_field: return msg::SIM_FAULT_PROTECTIVE_FIELD;
    case SimFault::clear_protective_field: return msg::SIM_FAULT_CLEAR_PROTECTIVE_FIELD;
    case SimFault::battery_failure: return msg::SIM_FAULT_BATTERY_FAILURE;
    case SimFault::lose_connection: return msg::SIM_FAULT_LOSE_CONNECTION;
    case SimFault::restore_connection: return msg::SIM_FAULT_RESTORE_CONNECTION;
  }
  return msg::SIM_FAULT_STALL;
}

}  // namespace

RanClient::RanClient(std::string vehicle_id, std::string ran_agent, std::size_t history_limit,
                     StatusCallback on_status, RefusalCallback on_refusal)
    : vehicle_id_(std::move(vehicle_id)),
      ran_agent_(std::move(ran_agent)),
      history_limit_(std::max<std::size_t>(history_limit, 1)),
      on_status_(std::move(on_status)),
      on_refusal_(std::move(on_refusal)),
      twins_(kTwinWindow) {}

RanClient::~RanClient() {
  reader_.reset();  // no callback runs after this
}

Result<std::unique_ptr<RanClient>> RanClient::create(dds::Participant& participant,
                                                     std::string vehicle_id,
                                                     std::string ran_agent,
                                                     std::size_t history_limit,
                                                     StatusCallback on_status,
                                                     RefusalCallback on_refusal) {
  if (ran_agent.empty()) ran_agent = ran_agent_id(vehicle_id);
  std::unique_ptr<RanClient> client(new RanClient(std::move(vehicle_id), std::move(ran_agent),
                                                  history_limit, std::move(on_status),
                                                  std::move(on_refusal)));
  auto commands = CommandClient::create(participant, kServiceArea, kCommandService);
  if (!commands) return unexpected(commands.error());
  client->commands_ = std::move(*commands);
  auto faults = FaultClient::create(participant, kServiceArea, kSimFaultService);
  if (!faults) return unexpected(faults.error());
  client->faults_ = std::move(*faults);
  dds::ReaderOptions options;
  options.filter_expression = "vehicle_id = %0";
  options.filter_parameters = {"'" + client->vehicle_id_ + "'"};
  auto reader = dds::Reader<msg::RanStatus>::create(
      participant, kStatusTopic,
      [raw = client.get()](const msg::RanStatus& status, const dds::SampleSource& source) {
        raw->receive(status, source);
      },
      options);
  if (!reader) return unexpected(reader.error());
  client->reader_ = std::move(*reader);
  return client;
}

void RanClient::receive(const msg::RanStatus& wire, const dds::SampleSource& source) {
  auto status = from_wire(wire);
  TwinWriterWatch::Verdict writers;
  {
    std::lock_guard lock(mutex_);
    writers = twins_.observe(source, std::chrono::steady_clock::now());
  }
  if (writers.kind == TwinWriterWatch::Verdict::Kind::wait) {
    // A restarted RAN, or the first statuses of a second one: taken once the earlier writer
    // has been quiet for the window, or refused below once they alternate.
    if (spdlog::should_log(spdlog::level::debug)) {  // the GUIDs are formatted only when logged
      spdlog::debug("status of vehicle '{}' from writer {} waits: {} reported within {} s", vehicle_id_,
                    source.text(), writers.other->text(), kTwinWindow.count());
    }
    return;
  }
  const bool two_rans = writers.kind == TwinWriterWatch::Verdict::Kind::twins;
  if (two_rans) {
    // Which of the two drives the vehicle is unknown, and both take its commands: nothing
    // either says is taken, so the commander treats the RAN as lost until one stops.
    status = fail(ErrorCode::conflict,
                  fmt::format("status of '{}': two RANs report for this vehicle (status writers {} and {}); "
                              "stop the one that does not drive it",
                              wire.vehicle_id(), writers.other->text(), source.text()));
  }
  if (!status) {
    bool began = false;
    {
      std::lock_guard lock(mutex_);
      const auto now = std::chrono::steady_clock::now();
      // A new episode: the first refusal since a status was taken, after a pause longer
      // than a RAN may be silent, or of the other kind (a second RAN among malformed ones).
      began = !refusal_ || now - refusal_->when > kEpisodeGap || refusal_->two_rans != two_rans;
      refusal_ = Refusal{status.error().message, now, two_rans};
    }
    // Told when it begins, not ten times a second (the reasons may name a moving point).
    if (began) {
      spdlog::warn("status of vehicle '{}' ignored: {}", vehicle_id_, status.error().message);
      if (on_refusal_) on_refusal_(status.error().message);
    }
    return;
  }
  {
    std::lock_guard lock(mutex_);
    refusal_.reset();
    // KEEP_LAST 1 and a late join may skip reports, never reorder them; a repeated sample
    // (a replaced RAN starting over at 1) starts a new history.
    if (!history_.empty() && status->sequence <= history_.back().sequence) history_.clear();
    history_.push_back(*status);
    ++received_;
    while (history_.size() > history_limit_) history_.pop_front();
  }
  if (on_status_) on_status_(*status);
  arrived_.notify_all();
}

Result<CommandVerdict> RanClient::send(msg::RanCommandRequest request,
                                       std::chrono::milliseconds timeout) {
  request.vehicle_id(vehicle_id_);
  auto reply = commands_->call(std::move(request), timeout, ran_agent_);
  if (!reply) return unexpected(reply.error());
  if (auto ok = dds::from_wire(reply->error()); !ok) return unexpected(ok.error());
  CommandVerdict verdict;
  if (!reply->state().empty()) {
    verdict.state = command_state_from_string(reply->state());
    if (!verdict.state) {
      return fail(ErrorCode::internal,
                  fmt::format("RAN '{}' replied with unknown command state '{}'", ran_agent_,
                              reply->state()));
    }
  }
  verdict.code = reply->code();
  verdict.reason = reply->reason();
  return verdict;
}

Result<CommandVerdict> RanClient::move(const MoveCommand& command, std::chrono::milliseconds timeout) {
  msg::RanCommandRequest request;
  request.kind(msg::RAN_COMMAND_MOVE);
  request.move(to_wire(command));
  return send(std::move(request), timeout);
}

Result<CommandVerdict> RanClient::action(const ActionCommand& command,
                                         std::chrono::milliseconds timeout) {
  msg::RanCommandRequest request;
  request.kind(msg::RAN_COMMAND_ACTION);
  request.action(to_wire(command));
  return send(std::move(request), timeout);
}

Status RanClient::cancel(const CommandId& command, std::chrono::milliseconds timeout) {
  msg::RanCommandRequest request;
  request.kind(msg::RAN_COMMAND_CANCEL);
  request.cancel_id(command);
  auto sent = send(std::move(request), timeout);
  if (!sent) return unexpected(sent.error());
  return {};
}

Status RanClient::pause(std::chrono::milliseconds timeout) {
  msg::RanCommandRequest request;
  request.kind(msg::RAN_COMMAND_PAUSE);
  auto sent = send(std::move(request), timeout);
  if (!sent) return unexpected(sent.error());
  return {};
}

Status RanClient::resume(std::chrono::milliseconds timeout) {
  msg::RanCommandRequest request;
  request.kind(msg::RAN_COMMAND_RESUME);
  auto sent = send(std::move(request), timeout);
  if (!sent) return unexpected(sent.error());
  return {};
}

Status RanClient::inject_fault(SimFault fault, DurationNs duration,
                               std::chrono::milliseconds timeout) {
  msg::SimFaultRequest request;
  request.vehicle_id(vehicle_id_);
  request.kind(fault_to_wire(fault));
  request.duration_ns(duration);
  auto reply = faults_->call(std::move(request), timeout, ran_agent_);
  if (!reply) return unexpected(reply.error());
  return dds::from_wire(reply->error());
}

std::optional<VehicleStatus> RanClient::latest() const {
  std::lock_guard lock(mutex_);
  if (history_.empty()) return std::nullopt;
  return history_.back();
}

std::optional<VehicleStatus> RanClient::wait_for(
    const std::function<bool(const VehicleStatus&)>& condition,
    std::chrono::milliseconds timeout) const {
  std::unique_lock lock(mutex_);
  // Statuses numbered from `next` on are still to be looked at; the latest one counts.
  std::uint64_t next = received_ > 0 ? received_ : 1;
  std::optional<VehicleStatus> found;
  arrived_.wait_for(lock, timeout, [&] {
    const std::uint64_t oldest = received_ + 1 - history_.size();
    for (std::uint64_t number = std::max(next, oldest); number <= received_; ++number) {
      const VehicleStatus& status = history_[number - oldest];
      if (condition(status)) {
        found = status;
        return true;
      }
    }
    next = received_ + 1;
    return false;
  });
  return found;
}

std::vector<VehicleStatus> RanClient::history() const {
  std::lock_guard lock(mutex_);
  return {history_.begin(), history_.end()};
}

std::optional<std::string> RanClient::refusal(std::chrono::steady_clock::duration max_age) const {
  std::lock_guard lock(mutex_);
  if (!refusal_ || std::chrono::steady_clock::now() - refusal_->when > max_age) return std::nullopt;
  return refusal_->reason;
}

bool RanClient::two_rans() const {
  std::lock_guard lock(mutex_);
  return refusal_ && refusal_->two_rans && std::chrono::steady_clock::now() - refusal_->when <= kTwinWindow;
}

}  // namespace drover::ran
