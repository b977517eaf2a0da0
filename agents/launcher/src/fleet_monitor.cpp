#include "drover/launcher/fleet_monitor.hpp"

#include "agents/topology_agent/topology_agent.hpp"
#include "drover/logical_agent/messages.hpp"
#include "drover/logical_agent/names.hpp"
#include "drover/ran/status.hpp"
#include "drover/ran_runner/names.hpp"
#include "ran_status_message.hpp"

namespace drover::launcher {

namespace {

std::optional<TimeNs> time_of(const msg::OptionalTime& time) {
  return time.present() ? std::optional<TimeNs>(time.ns()) : std::nullopt;
}

nlohmann::json status_line(const msg::RanStatus& status) {
  nlohmann::json footprint = nlohmann::json::array();
  for (const auto& point : status.footprint().ring()) footprint.push_back({point.x(), point.y()});
  nlohmann::json errors = nlohmann::json::array();
  for (const auto& error : status.errors()) errors.push_back(error.level() + ":" + error.code());
  return {{"vehicle", status.vehicle_id()},
          {"seq", status.sequence_number()},
          {"pose", {status.pose().x(), status.pose().y(), status.pose().theta()}},
          {"speed", status.linear_speed()},
          {"footprint", std::move(footprint)},
          {"errors", std::move(errors)}};
}

const char* order_state_name(msg::OrderState state) {
  switch (state) {
    case msg::ORDER_QUEUED: return "queued";
    case msg::ORDER_RUNNING: return "running";
    case msg::ORDER_FINISHED: return "finished";
    case msg::ORDER_FAILED: return "failed";
    case msg::ORDER_WITHDRAWN: return "withdrawn";
  }
  return "unknown";
}

/// The time of the latest step the progress reports.
TimeNs progress_time(const msg::OrderProgress& progress) {
  for (const auto* time : {&progress.finished(), &progress.started(), &progress.created()}) {
    if (time->present()) return time->ns();
  }
  return 0;
}

nlohmann::json order_line(const msg::OrderProgress& progress) {
  const auto optional_time = [](const msg::OptionalTime& time) {
    return time.present() ? nlohmann::json(time.ns()) : nlohmann::json(nullptr);
  };
  return {{"order", progress.order()},
          {"vehicle", progress.vehicle()},
          {"state", order_state_name(progress.state())},
          {"destination", progress.destination()},
          {"destinations", progress.destination_count()},
          {"created", optional_time(progress.created())},
          {"started", optional_time(progress.started())},
          {"finished", optional_time(progress.finished())},
          {"failure", progress.failure()}};
}

const char* event_name(msg::TopologyEventKind kind) {
  switch (kind) {
    case msg::EVENT_RESERVED: return "reservation";
    case msg::EVENT_ABORTED: return "abort";
    case msg::EVENT_EXPIRED: return "expiry";
    case msg::EVENT_ALLOCATED: return "allocation";
    case msg::EVENT_RELEASED: return "release";
    case msg::EVENT_CANCELLED: return "cancel";
    case msg::EVENT_LOCKED: return "lock";
    case msg::EVENT_UNLOCKED: return "unlock";
    case msg::EVENT_DELAYED: return "delay";
  }
  return "unknown";
}

nlohmann::json event_line(const msg::TopologyEvent& event) {
  // An open end (kForever) is written as null: JSON readers need not know the sentinel.
  // Route ids are 64-bit: written as strings, which every JSON reader keeps exact.
  const auto end = event.window().end() == kForever ? nlohmann::json(nullptr) : nlohmann::json(event.window().end());
  return {{"source", event.source()},  {"serial", event.serial()},   {"event", event_name(event.kind())},
          {"agent", event.agent()},    {"route", std::to_string(event.route())},     {"step", event.step()},
          {"entity", event.entity()},  {"window", {event.window().start(), end}},
          {"shift", event.shift()},    {"lock_id", event.lock_id()}, {"reason", event.reason()}};
}

}  // namespace

Result<std::unique_ptr<FleetMonitor>> FleetMonitor::create(dds::Participant& participant, TraceWriter* trace) {
  std::unique_ptr<FleetMonitor> monitor(new FleetMonitor(trace));
  FleetMonitor* self = monitor.get();
  // Statuses: a deeper reader history than the writers' KEEP_LAST 1, so that a burst while
  // the trace is written loses nothing the writer still has.
  dds::ReaderOptions status_options;
  status_options.qos = dds::TopicQos::state(64);
  auto statuses = dds::Reader<msg::RanStatus>::create(
      participant, ran::kStatusTopic, [self](const msg::RanStatus& status) { self->on_status(status); },
      status_options);
  if (!statuses) return unexpected(statuses.error());
  monitor->status_reader_ = std::move(*statuses);
  dds::ReaderOptions progress_options;
  progress_options.qos = dds::TopicQos::state(16);
  auto progress = dds::Reader<msg::OrderProgress>::create(
      participant, logical_agent::kOrderProgressTopic,
      [self](const msg::OrderProgress& update) { self->on_progress(update); }, progress_options);
  if (!progress) return unexpected(progress.error());
  monitor->progress_reader_ = std::move(*progress);
  auto events = dds::Reader<msg::TopologyEvent>::create(
      participant, topology_agent::kEventTopic,
      [self](const msg::TopologyEvent& event) { self->on_topology_event(event); },
      dds::ReaderOptions{dds::TopicQos::events(), {}, {}});
  if (!events) return unexpected(events.error());
  monitor->event_reader_ = std::move(*events);
  return monitor;
}

FleetMonitor::~FleetMonitor() {
  // Readers first: their callbacks use the rest.
  event_reader_.reset();
  progress_reader_.reset();
  status_reader_.reset();
}

void FleetMonitor::on_status(const msg::RanStatus& status) {
  if (trace_ != nullptr) trace_->write(status.time().ns(), "ran_status", status_line(status));
  std::lock_guard lock(mutex_);
  ++statuses_;
  moving_[status.vehicle_id()] = !ran::standing_still(status.linear_speed(), status.angular_speed());
}

void FleetMonitor::on_progress(const msg::OrderProgress& progress) {
  OrderOutcome outcome = OrderOutcome::open;
  if (progress.state() == msg::ORDER_FINISHED) outcome = OrderOutcome::finished;
  if (progress.state() == msg::ORDER_FAILED) outcome = OrderOutcome::failed;
  if (progress.state() == msg::ORDER_WITHDRAWN) outcome = OrderOutcome::withdrawn;
  if (trace_ != nullptr) trace_->write(progress_time(progress), "order", order_line(progress));
  std::lock_guard lock(mutex_);
  orders_.update(progress.vehicle(), progress.order(), outcome, time_of(progress.created()), time_of(progress.finished()));
}

void FleetMonitor::on_topology_event(const msg::TopologyEvent& event) {
  if (trace_ != nullptr) trace_->write(event.time(), "topology_event", event_line(event));
  std::lock_guard lock(mutex_);
  ++topology_events_;
}

FleetFigures FleetMonitor::figures() const {
  std::lock_guard lock(mutex_);
  FleetFigures figures;
  figures.orders = orders_.figures();
  figures.vehicles_reporting = moving_.size();
  for (const auto& [vehicle, moving] : moving_) figures.vehicles_moving += moving ? 1 : 0;
  figures.statuses = statuses_;
  figures.topology_events = topology_events_;
  return figures;
}

}  // namespace drover::launcher
