#include "drover/launcher/load_generator.hpp"

#include <spdlog/spdlog.h>

#include "drover/dds/wire_error.hpp"
#include "drover/logical_agent/messages.hpp"
#include "drover/logical_agent/names.hpp"

namespace drover::launcher {

namespace {

bool free_for_work(const msg::VehicleState& state) {
  return (state.state() == msg::VEHICLE_IDLE || state.state() == msg::VEHICLE_PARKING) &&
         state.order().empty() && state.queued_orders() == 0;
}

msg::OrderDestination destination(const std::string& location, const std::string& operation) {
  msg::OrderDestination stop;
  stop.location(location);
  stop.operation(operation);
  return stop;
}

}  // namespace

LoadGenerator::LoadGenerator(LoadGeneratorOptions options)
    : options_(std::move(options)),
      served_(options_.vehicles.begin(), options_.vehicles.end()),
      picker_(options_.stations, options_.seed) {}

std::optional<std::string> stations_problem(const std::vector<std::string>& stations) {
  const std::set<std::string> distinct(stations.begin(), stations.end());
  if (distinct.size() != stations.size()) return "a station is named twice";
  if (distinct.size() < 2) {
    return "orders need at least two distinct stations, got " + std::to_string(distinct.size());
  }
  return std::nullopt;
}

Result<std::unique_ptr<LoadGenerator>> LoadGenerator::create(dds::Participant& participant,
                                                             LoadGeneratorOptions options) {
  if (auto problem = stations_problem(options.stations)) {
    return fail(ErrorCode::invalid_argument, "the load generator's stations: " + *problem);
  }
  if (options.order_prefix.empty()) options.order_prefix = participant.agent_id();
  std::unique_ptr<LoadGenerator> generator(new LoadGenerator(std::move(options)));
  LoadGenerator* self = generator.get();
  auto orders = OrderClient::create(participant, logical_agent::kServiceArea, logical_agent::kOrderService);
  if (!orders) return unexpected(orders.error());
  generator->orders_ = std::move(*orders);
  auto progress = dds::Reader<msg::OrderProgress>::create(
      participant, logical_agent::kOrderProgressTopic,
      [self](const msg::OrderProgress& update) { self->on_progress(update); },
      dds::ReaderOptions{dds::TopicQos::state(16), {}, {}});
  if (!progress) return unexpected(progress.error());
  generator->progress_reader_ = std::move(*progress);
  auto vehicles = dds::Reader<msg::VehicleState>::create(
      participant, logical_agent::kVehicleStateTopic,
      [self](const msg::VehicleState& state) { self->on_vehicle(state); });
  if (!vehicles) return unexpected(vehicles.error());
  generator->vehicle_reader_ = std::move(*vehicles);
  return generator;
}

LoadGenerator::~LoadGenerator() {
  // Readers first (their callbacks send orders), then the client.
  vehicle_reader_.reset();
  progress_reader_.reset();
  orders_.reset();
}

LoadFigures LoadGenerator::figures() const {
  std::lock_guard lock(mutex_);
  return figures_;
}

void LoadGenerator::on_vehicle(const msg::VehicleState& state) {
  if (!served_.empty() && !served_.contains(state.vehicle())) return;
  {
    std::lock_guard lock(mutex_);
    vehicles_[state.vehicle()] = state;
  }
  consider(state.vehicle());
}

void LoadGenerator::on_progress(const msg::OrderProgress& progress) {
  const bool ended = progress.state() == msg::ORDER_FINISHED || progress.state() == msg::ORDER_FAILED ||
                     progress.state() == msg::ORDER_WITHDRAWN;
  if (!ended) return;
  std::string vehicle;
  {
    std::lock_guard lock(mutex_);
    const auto ours = outstanding_.find(progress.vehicle());
    if (ours == outstanding_.end() || ours->second != progress.order()) return;
    outstanding_.erase(ours);
    switch (progress.state()) {
      case msg::ORDER_FINISHED: ++figures_.finished; break;
      case msg::ORDER_WITHDRAWN: ++figures_.withdrawn; break;
      default: ++figures_.failed; break;
    }
    vehicle = progress.vehicle();
    // Destination 0 loads; ending after it unfinished leaves the load on the vehicle.
    if (progress.state() != msg::ORDER_FINISHED && progress.destination() >= 1) {
      may_carry_.insert(vehicle);
    } else if (progress.state() == msg::ORDER_FINISHED) {
      may_carry_.erase(vehicle);
    }
  }
  if (progress.state() == msg::ORDER_FAILED) {
    spdlog::warn("order '{}' of vehicle '{}' failed: {}", progress.order(), vehicle, progress.failure());
  }
  consider(vehicle);
}

void LoadGenerator::consider(const std::string& vehicle) {
  std::string order;
  std::pair<std::string, std::string> stations;
  {
    std::lock_guard lock(mutex_);
    const auto state = vehicles_.find(vehicle);
    if (state == vehicles_.end() || !free_for_work(state->second) || outstanding_.contains(vehicle) ||
        left_out_.contains(vehicle)) {
      return;
    }
    if (options_.max_orders != 0 && next_number_ > options_.max_orders) return;
    order = options_.order_prefix + "-" + std::to_string(next_number_++);
    stations = picker_.next();
    if (may_carry_.contains(vehicle)) stations.first.clear();
    outstanding_[vehicle] = order;  // claimed before sending: the other reader sends nothing
  }
  send(vehicle, order, stations.first, stations.second);
}

void LoadGenerator::send(const std::string& vehicle, const std::string& order, const std::string& from,
                         const std::string& to) {
  msg::OrderRequest request;
  request.order(order);
  if (from.empty()) {
    request.destinations({destination(to, "unload")});
  } else {
    request.destinations({destination(from, "load"), destination(to, "unload")});
  }
  auto reply = orders_->call(request, options_.request_timeout, vehicle);
  std::string problem;
  bool invalid = false;  // for this vehicle, whatever the stations: the next would fail alike
  if (!reply) {
    problem = reply.error().message;
  } else if (reply->error().code() != msg::ERROR_NONE) {
    const Error refusal = dds::from_wire(reply->error()).error();
    problem = refusal.message;
    invalid = refusal.code == ErrorCode::invalid_argument;
  }
  std::lock_guard lock(mutex_);
  if (problem.empty()) {
    ++figures_.queued;
    if (from.empty()) {
      spdlog::info("order '{}' to '{}': unload at {} (what an earlier order may have left on it)", order, vehicle, to);
    } else {
      spdlog::info("order '{}' to '{}': load at {}, unload at {}", order, vehicle, from, to);
    }
    return;
  }
  ++figures_.refused;
  if (auto ours = outstanding_.find(vehicle); ours != outstanding_.end() && ours->second == order) {
    outstanding_.erase(ours);  // its next state report tries again
  }
  if (invalid && left_out_.insert(vehicle).second) {
    ++figures_.left_out;
    spdlog::error("order '{}' to '{}' refused as invalid: {}; vehicle '{}' gets no more orders", order, vehicle,
                  problem, vehicle);
    return;
  }
  spdlog::warn("order '{}' to '{}' not queued: {}", order, vehicle, problem);
}

}  // namespace drover::launcher
