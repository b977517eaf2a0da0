// Setup of the logical agent's DDS entities, its callbacks and what it publishes. The
// executor (driving) is in executor.cpp.

#include "agents/logical_agent/src/logical_agent.hpp"

#include <cmath>

#include <fmt/format.h>

#include <spdlog/spdlog.h>

#include "drover/common/identifier.hpp"
#include "drover/dds/wire_error.hpp"
#include "drover/logical_agent/names.hpp"
#include "drover/ran_runner/names.hpp"

namespace drover::logical_agent {

namespace {

/// The topology agents' notices (docs/topology-agent.md "Topics").
constexpr const char* kTopologyNoticeTopic = "drover/topology/notices";

msg::OptionalTime optional_time(const std::optional<TimeNs>& time) {
  msg::OptionalTime out;
  out.present(time.has_value());
  out.ns(time.value_or(0));
  return out;
}

msg::OrderState to_wire(OrderState state) {
  switch (state) {
    case OrderState::queued: return msg::ORDER_QUEUED;
    case OrderState::running: return msg::ORDER_RUNNING;
    case OrderState::finished: return msg::ORDER_FINISHED;
    case OrderState::failed: return msg::ORDER_FAILED;
    case OrderState::withdrawn: return msg::ORDER_WITHDRAWN;
  }
  return msg::ORDER_FAILED;
}

}  // namespace

LogicalAgent::LogicalAgent(std::shared_ptr<const topology::Topology> topology, SharedClock clock,
                           LogicalAgentOptions options, std::optional<OrderJournal> journal)
    : topology_(std::move(topology)),
      clock_(clock),
      options_(std::move(options)),
      book_({.changed = [this](const Order& order) { publish_progress(order); },
             .record = [this](const Order& order, bool added) { return record_order(order, added); },
             .forgotten = [this](const std::string& name) { retire_progress(name); }}),
      journal_(std::move(journal)),
      monitor_(topology_),
      command_prefix_(std::to_string(SharedClock::unix_now())),
      route_ids_(static_cast<std::uint64_t>(SharedClock::unix_now())) {}

Result<std::unique_ptr<LogicalAgent>> LogicalAgent::create(std::shared_ptr<const topology::Topology> topology,
                                                           SharedClock clock, LogicalAgentOptions options) {
  if (auto valid = carp::validate(options.vehicle); !valid) {
    return fail(ErrorCode::invalid_argument, "vehicle profile: " + valid.error().message);
  }
  if (options.lookahead == 0) return fail(ErrorCode::invalid_argument, "lookahead must be at least 1 vertex");
  if (auto problem = charging_problem(options.charge_below, options.charge_to)) {
    return fail(ErrorCode::invalid_argument, "charge_to: " + *problem);
  }
  if (options.vehicle.id.empty()) options.vehicle.id = options.participant.agent_id;
  if (auto valid = check_identifier(options.vehicle.id, "vehicle id"); !valid) return unexpected(valid.error());
  std::optional<OrderJournal> journal;
  std::vector<Order> stored;
  std::optional<std::string> pause;
  if (!options.order_journal.empty()) {
    auto opened = OrderJournal::open(options.order_journal, options.participant.agent_id);
    if (!opened) return unexpected(std::move(opened).error());
    auto loaded = opened->load();
    if (!loaded) return unexpected(std::move(loaded).error());
    auto paused = opened->load_pause();
    if (!paused) return unexpected(std::move(paused).error());
    pause = std::move(*paused);
    journal = std::move(*opened);
    stored = std::move(*loaded);
  }
  std::unique_ptr<LogicalAgent> agent(
      new LogicalAgent(std::move(topology), clock, std::move(options), std::move(journal)));
  agent->restored_ = std::move(stored);
  agent->pause_ = std::move(pause);
  if (agent->pause_) {
    spdlog::warn("the vehicle stays paused, as an operator left it ({})",
                 agent->pause_->empty() ? "no reason given" : *agent->pause_);
  }
  if (auto started = agent->start(); !started) return unexpected(started.error());
  return agent;
}

Status LogicalAgent::start() {
  auto participant = dds::Participant::create(options_.participant);
  if (!participant) return unexpected(participant.error());
  participant_ = std::move(*participant);
  auto services = TopologyServices::create(*participant_, topology_, options_.call_timeout, stopping_);
  if (!services) return unexpected(services.error());
  services_ = std::move(*services);

  auto progress = dds::Writer<msg::OrderProgress>::create(*participant_, kOrderProgressTopic);
  if (!progress) return unexpected(progress.error());
  progress_writer_ = std::move(*progress);
  auto vehicle = dds::Writer<msg::VehicleState>::create(*participant_, kVehicleStateTopic);
  if (!vehicle) return unexpected(vehicle.error());
  vehicle_writer_ = std::move(*vehicle);
  auto alarms =
      dds::Writer<msg::OperatorAlarm>::create(*participant_, kAlarmTopic, alarm_writer_qos());
  if (!alarms) return unexpected(alarms.error());
  alarm_writer_ = std::move(*alarms);
  auto make_way = dds::Writer<msg::MakeWayRequest>::create(*participant_, kMakeWayTopic, dds::TopicQos::events());
  if (!make_way) return unexpected(make_way.error());
  make_way_writer_ = std::move(*make_way);
  // Before the RAN's statuses (an adopted action's outcome is followed from the first) and
  // before orders can arrive (their names are checked against the restored ones).
  restore_orders(std::exchange(restored_, {}));

  dds::HeartbeatOptions beat;
  beat.kind = "logical";
  beat.owns = {vehicle_id()};
  auto heartbeat = dds::HeartbeatPublisher::create(*participant_, clock_, beat);
  if (!heartbeat) return unexpected(heartbeat.error());
  heartbeat_ = std::move(*heartbeat);

  auto ran = ran::RanClient::create(
      *participant_, vehicle_id(), options_.ran_agent, 16, [this](const ran::VehicleStatus& status) { on_status(status); },
      [this](const std::string& refusal) {
        raise_alarm(msg::ALARM_ERROR,
                    fmt::format("vehicle '{}': the statuses of its RAN are refused, so they say nothing of where it is "
                                "or what it does: {}",
                                vehicle_id(), refusal));
      });
  if (!ran) return unexpected(ran.error());
  ran_ = std::move(*ran);

  auto notices = dds::Reader<msg::ReservationNotice>::create(
      *participant_, kTopologyNoticeTopic, [this](const msg::ReservationNotice& notice) { on_notice(notice); },
      events_naming_this_vehicle("agent"));
  if (!notices) return unexpected(notices.error());
  notice_reader_ = std::move(*notices);
  auto asked = dds::Reader<msg::MakeWayRequest>::create(
      *participant_, kMakeWayTopic, [this](const msg::MakeWayRequest& request) { on_make_way(request); },
      events_naming_this_vehicle("vehicle"));
  if (!asked) return unexpected(asked.error());
  make_way_reader_ = std::move(*asked);

  auto server = dds::ServiceServer<msg::OrderRequest, msg::OrderReply>::create(
      *participant_, kServiceArea, kOrderService,
      [this](const msg::OrderRequest& request, dds::ReplyHandle<msg::OrderReply> reply) {
        on_order(request, std::move(reply));
      });
  if (!server) return unexpected(server.error());
  order_server_ = std::move(*server);
  auto withdraw = dds::ServiceServer<msg::OrderWithdrawRequest, msg::OrderWithdrawReply>::create(
      *participant_, kServiceArea, kWithdrawService,
      [this](const msg::OrderWithdrawRequest& request, dds::ReplyHandle<msg::OrderWithdrawReply> reply) {
        on_withdraw(request, std::move(reply));
      });
  if (!withdraw) return unexpected(withdraw.error());
  withdraw_server_ = std::move(*withdraw);
  auto pause = dds::ServiceServer<msg::VehiclePauseRequest, msg::StatusReply>::create(
      *participant_, kServiceArea, kPauseService,
      [this](const msg::VehiclePauseRequest& request, dds::ReplyHandle<msg::StatusReply> reply) {
        on_pause(request, std::move(reply));
      });
  if (!pause) return unexpected(pause.error());
  pause_server_ = std::move(*pause);

  executor_ = std::thread([this] { run(); });
  return {};
}

LogicalAgent::~LogicalAgent() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  if (executor_.joinable()) executor_.join();
  pause_server_.reset();
  withdraw_server_.reset();
  order_server_.reset();
  make_way_reader_.reset();
  notice_reader_.reset();
  ran_.reset();
  heartbeat_.reset();
  make_way_writer_.reset();
  alarm_writer_.reset();
  vehicle_writer_.reset();
  progress_writer_.reset();
  services_.reset();
  participant_.reset();
}

dds::ReaderOptions LogicalAgent::events_naming_this_vehicle(const std::string& field) const {
  dds::ReaderOptions options;
  options.qos = dds::TopicQos::events();
  options.filter_expression = field + " = %0";
  options.filter_parameters = {"'" + vehicle_id() + "'"};
  return options;
}

void LogicalAgent::on_order(const msg::OrderRequest& request, dds::ReplyHandle<msg::OrderReply> reply) {
  if (request.header().responder().empty()) {
    // Every logical agent sees an unaddressed request: taking it would queue it many times.
    const Error refused{ErrorCode::invalid_argument,
                        "order '" + request.order() + "': header.responder must name the vehicle it is for"};
    if (auto sent = reply.send_error(refused); !sent) spdlog::warn("reply not sent: {}", sent.error().message);
    return;
  }
  msg::OrderReply answer;
  OrderSpec spec;
  spec.name = request.order();
  for (const auto& destination : request.destinations()) {
    OrderSpec::Stop stop{destination.location(), destination.operation(), {}};
    for (const auto& property : destination.properties()) stop.properties[property.name()] = property.value();
    spec.destinations.push_back(std::move(stop));
  }
  for (const auto& property : request.properties()) spec.properties[property.name()] = property.value();
  auto order = make_order(*topology_, spec);
  if (order) {
    // What the vehicle cannot do is refused now, not failed at the destination after the
    // drive. Without a status heard now, the RAN decides there.
    std::lock_guard lock(mutex_);
    if (const auto* status = heard_status()) {
      if (Status performed = check_operations(*order, *status); !performed) order = unexpected(performed.error());
    }
  }
  if (!order) {
    spdlog::warn("order refused: {}", order.error().message);
    if (auto sent = reply.send_error(order.error()); !sent) spdlog::warn("reply not sent: {}", sent.error().message);
    return;
  }
  Result<std::size_t> position = 0;
  {
    std::lock_guard lock(mutex_);
    position = book_.add(std::move(*order), clock_.now());
    ++events_;
  }
  wake_.notify_all();
  if (!position) {
    spdlog::warn("order refused: {}", position.error().message);
    if (auto sent = reply.send_error(position.error()); !sent) spdlog::warn("reply not sent: {}", sent.error().message);
    return;
  }
  spdlog::info("order '{}' queued at position {}", spec.name, *position);
  answer.queue_position(static_cast<std::uint32_t>(*position));
  if (auto sent = reply.send(std::move(answer)); !sent) spdlog::warn("reply not sent: {}", sent.error().message);
}

void LogicalAgent::on_withdraw(const msg::OrderWithdrawRequest& request,
                               dds::ReplyHandle<msg::OrderWithdrawReply> reply) {
  msg::OrderWithdrawReply answer;
  Result<OrderState> state = OrderState::queued;
  if (request.header().responder().empty()) {
    // As for orders: every logical agent sees an unaddressed request.
    state = fail(ErrorCode::invalid_argument,
                 "withdraw '" + request.order() + "': header.responder must name the vehicle of the order");
  } else {
    {
      std::lock_guard lock(mutex_);
      state = book_.withdraw(request.order(), request.reason(), clock_.now());
      if (const Order* order = book_.find(request.order())) answer.state(to_wire(order->state));
      ++events_;
    }
    wake_.notify_all();
  }
  if (!state) {
    spdlog::warn("withdrawal refused: {}", state.error().message);
    answer.error(dds::to_wire(state.error()));
  } else {
    spdlog::info("order '{}' {} ({})", request.order(),
                 *state == OrderState::withdrawn ? "withdrawn" : "being withdrawn",
                 request.reason().empty() ? "no reason given" : request.reason());
  }
  if (auto sent = reply.send(std::move(answer)); !sent) spdlog::warn("reply not sent: {}", sent.error().message);
}

void LogicalAgent::on_pause(const msg::VehiclePauseRequest& request, dds::ReplyHandle<msg::StatusReply> reply) {
  const char* what = request.paused() ? "pause" : "resume";
  Status outcome;
  if (request.header().responder().empty()) {
    // As for orders: every logical agent sees an unaddressed request.
    outcome = fail(ErrorCode::invalid_argument, std::string(what) + ": header.responder must name the vehicle");
  } else {
    std::optional<std::string> next;
    if (request.paused()) next = request.reason();
    {
      std::lock_guard lock(mutex_);
      // Stored first: a pause the journal lost would end with a restart, unnoticed.
      if (journal_) outcome = journal_->store_pause(next);
      if (outcome) {
        pause_ = std::move(next);
        ++events_;
      }
    }
    wake_.notify_all();
  }
  if (!outcome) {
    spdlog::warn("{} refused: {}", what, outcome.error().message);
  } else if (request.paused()) {
    spdlog::info("paused by '{}' ({})", reply.requester(), request.reason().empty() ? "no reason given" : request.reason());
  } else {
    spdlog::info("resumed by '{}'", reply.requester());
  }
  msg::StatusReply answer;
  if (!outcome) answer.error(dds::to_wire(outcome.error()));
  if (auto sent = reply.send(std::move(answer)); !sent) spdlog::warn("reply not sent: {}", sent.error().message);
}

void LogicalAgent::on_notice(const msg::ReservationNotice& notice) {
  {
    std::lock_guard lock(mutex_);
    notices_.push_back(notice);
    ++events_;
  }
  wake_.notify_all();
}

void LogicalAgent::on_make_way(const msg::MakeWayRequest& request) {
  if (request.vehicle() != vehicle_id()) return;
  {
    std::lock_guard lock(mutex_);
    make_way_ = MakeWay{request.requester(), request.location(), request.time().ns()};
    ++events_;
  }
  wake_.notify_all();
}

void LogicalAgent::on_status(const ran::VehicleStatus& status) {
  {
    std::lock_guard lock(mutex_);
    status_ = status;
    status_received_ = std::chrono::steady_clock::now();
    for (const auto& command : status.commands) {
      if (ran::is_terminal(command.state) &&
          (command.id.rfind(command_prefix_, 0) == 0 || command.id == adopted_command_)) {
        ended_commands_.emplace(command.id, command);
      }
    }
    ++events_;
  }
  wake_.notify_all();
}

void LogicalAgent::publish_progress(const Order& order) {
  msg::OrderProgress progress;
  progress.order(order.name);
  progress.vehicle(vehicle_id());
  progress.state(to_wire(order.state));
  progress.destination(static_cast<std::uint32_t>(order.destination));
  progress.destination_count(static_cast<std::uint32_t>(order.destinations.size()));
  progress.created(optional_time(order.created));
  progress.started(optional_time(order.started));
  progress.finished(optional_time(order.finished));
  progress.failure(order.failure);
  spdlog::info("order '{}': {} (destination {}/{}){}", order.name, to_string(order.state), order.destination,
               order.destinations.size(), order.failure.empty() ? "" : ": " + order.failure);
  if (auto written = progress_writer_->write(progress); !written) {
    spdlog::warn("order progress not published: {}", written.error().message);
  }
}

void LogicalAgent::retire_progress(const std::string& name) {
  msg::OrderProgress key;
  key.order(name);
  key.vehicle(vehicle_id());
  if (auto retired = progress_writer_->retire(key); !retired) {
    spdlog::warn("progress of forgotten order '{}' not retired: {}", name, retired.error().message);
  }
}

Status LogicalAgent::record_order(const Order& order, bool added) {
  if (!journal_) return {};
  Status stored = added ? journal_->add(order) : journal_->update(order);
  if (!stored) {
    // A new order is refused instead (its sender hears why); a change is stored later.
    if (!added) unsaved_orders_[order.name] = order;
    if (!journal_failing_) {
      journal_failing_ = true;
      raise_alarm(msg::ALARM_CRITICAL,
                  fmt::format("vehicle '{}': its order journal cannot be written ({}): new orders are refused while "
                              "it lasts, and a restart of its agent now would lose or repeat work",
                              vehicle_id(), stored.error().message));
    }
    return stored;
  }
  unsaved_orders_.erase(order.name);
  for (auto it = unsaved_orders_.begin(); it != unsaved_orders_.end();) {
    if (!journal_->update(it->second)) return stored;
    it = unsaved_orders_.erase(it);
  }
  if (journal_failing_) {
    journal_failing_ = false;
    raise_alarm(msg::ALARM_INFO, fmt::format("vehicle '{}': its order journal is written again", vehicle_id()));
  }
  return stored;
}

void LogicalAgent::raise_alarm(msg::AlarmSeverity severity, const std::string& text) {
  // The log says as much as the alarm: a warning is no error.
  const auto level = severity == msg::ALARM_INFO      ? spdlog::level::info
                     : severity == msg::ALARM_WARNING ? spdlog::level::warn
                                                      : spdlog::level::err;
  spdlog::log(level, "alarm: {}", text);
  msg::OperatorAlarm alarm;
  alarm.agent(vehicle_id());
  alarm.vehicle(vehicle_id());
  alarm.severity(severity);
  alarm.text(text);
  alarm.time().ns(clock_.now());
  if (auto written = alarm_writer_->write(alarm); !written) {
    spdlog::warn("alarm not published: {}", written.error().message);
  }
}

void LogicalAgent::set_activity(Activity activity) {
  if (activity_ == activity) return;
  if (activity == Activity::idle) idle_since_ = clock_.now();
  activity_ = activity;
  publish_vehicle_state(true);
}

void LogicalAgent::publish_vehicle_state(bool force) {
  static constexpr msg::VehicleActivity kWire[] = {
      msg::VEHICLE_IDLE,     msg::VEHICLE_DRIVING, msg::VEHICLE_OPERATING, msg::VEHICLE_PARKING,
      msg::VEHICLE_CHARGING, msg::VEHICLE_WAITING, msg::VEHICLE_ERROR,     msg::VEHICLE_PAUSED};
  msg::VehicleState state;
  state.vehicle(vehicle_id());
  state.ran(options_.ran_agent.empty() ? ran::ran_agent_id(vehicle_id()) : options_.ran_agent);
  state.state(kWire[static_cast<int>(activity_)]);
  if (vertex_) state.vertex(topology_->id(*vertex_));
  {
    std::lock_guard lock(mutex_);
    if (const Order* order = book_.current()) state.order(order->name);
    state.queued_orders(static_cast<std::uint32_t>(book_.queued_count()));
    state.paused(pause_.has_value());
    state.pause_reason(pause_.value_or(""));
    if (status_) {
      state.state_of_charge(status_->battery.state_of_charge);
      state.moving(!ran::standing_still(status_->linear_speed, status_->angular_speed));
    }
  }
  const auto real_now = std::chrono::steady_clock::now();
  const bool changed = state.state() != last_published_.state() || state.vertex() != last_published_.vertex() ||
                       state.order() != last_published_.order() || state.moving() != last_published_.moving() ||
                       state.queued_orders() != last_published_.queued_orders() ||
                       state.paused() != last_published_.paused() ||
                       state.pause_reason() != last_published_.pause_reason();
  if (!force && !changed && real_now - last_publication_ < std::chrono::seconds(1)) return;
  state.time().ns(clock_.now());
  last_published_ = state;
  last_publication_ = real_now;
  if (auto written = vehicle_writer_->write(state); !written) {
    spdlog::warn("vehicle state not published: {}", written.error().message);
  }
}

ran::CommandId LogicalAgent::next_command_id() {
  return command_prefix_ + "-" + std::to_string(++command_counter_);
}

}  // namespace drover::logical_agent
