#include "agents/logical_agent/src/order_book.hpp"

#include <algorithm>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "drover/common/identifier.hpp"

namespace drover::logical_agent {

const char* to_string(OrderState state) noexcept {
  switch (state) {
    case OrderState::queued: return "queued";
    case OrderState::running: return "running";
    case OrderState::finished: return "finished";
    case OrderState::failed: return "failed";
    case OrderState::withdrawn: return "withdrawn";
  }
  return "unknown";
}

std::optional<ran::ActionCommand> operation_action(const Destination& destination) {
  const std::string& operation = destination.operation;
  if (operation.empty() || operation == "NOP" || operation == "park") return std::nullopt;
  ran::ActionCommand action;
  if (const auto kind = ran::action_kind_from_string(operation)) {
    action.kind = *kind;
  } else {
    action.kind = ran::ActionKind::custom;
  }
  action.name = operation;
  action.parameters = destination.properties;
  return action;
}

Result<Order> make_order(const topology::Topology& topology, const OrderSpec& spec) {
  if (auto valid = check_identifier(spec.name, "order name"); !valid) return unexpected(valid.error());
  if (spec.destinations.empty()) {
    return fail(ErrorCode::invalid_argument, "order '" + spec.name + "': no destination");
  }
  Order order;
  order.name = spec.name;
  order.properties = spec.properties;
  for (std::size_t i = 0; i < spec.destinations.size(); ++i) {
    const auto& stop = spec.destinations[i];
    const auto entity = topology.find(stop.location);
    if (!entity || !topology.is_vertex(*entity)) {
      return fail(ErrorCode::invalid_argument, "order '" + spec.name + "': destination " + std::to_string(i) +
                                                   ": '" + stop.location + "' is not a vertex of topology '" +
                                                   topology.name() + "'");
    }
    order.destinations.push_back(Destination{*entity, stop.location, stop.operation, stop.properties});
  }
  return order;
}

Status check_operations(const Order& order, const ran::VehicleStatus& status, std::size_t from) {
  for (std::size_t i = from; i < order.destinations.size(); ++i) {
    const auto& operation = order.destinations[i].operation;
    if (!operation_action(order.destinations[i]) || status.performs(operation)) continue;
    return fail(ErrorCode::invalid_argument,
                fmt::format("order '{}': destination {}: vehicle '{}' does not perform '{}' (its RAN performs: {})",
                            order.name, i, status.vehicle_id, operation, fmt::join(status.actions, ", ")));
  }
  return {};
}

Result<std::size_t> OrderBook::add(Order order, TimeNs now) {
  if (find(order.name) != nullptr) {
    return fail(ErrorCode::conflict, "order '" + order.name + "' is known already");
  }
  order.state = OrderState::queued;
  order.destination = 0;
  order.created = now;
  orders_.push_back(std::move(order));
  if (Status stored = record(orders_.back(), true); !stored) {
    orders_.pop_back();
    return unexpected(std::move(stored).error());
  }
  publish(orders_.back());
  return static_cast<std::size_t>(
      std::count_if(orders_.begin(), orders_.end(), [](const Order& o) { return is_open(o.state); }));
}

Order* OrderBook::running() {
  for (auto& order : orders_) {
    if (order.state == OrderState::running) return &order;
  }
  return nullptr;
}

const Order* OrderBook::current() const { return const_cast<OrderBook*>(this)->running(); }

const Order* OrderBook::start_next(TimeNs now) {
  if (Order* order = running()) return order;
  for (auto& order : orders_) {
    if (order.state != OrderState::queued) continue;
    order.state = OrderState::running;
    order.started = now;
    changed(order);
    return &order;
  }
  return nullptr;
}

bool OrderBook::advance(TimeNs now) {
  Order* order = running();
  if (order == nullptr) return false;
  ++order->destination;
  order->action_command.reset();
  if (order->destination >= order->destinations.size()) {
    order->state = OrderState::finished;
    order->finished = now;
    publish_ended(*order);
    return false;
  }
  changed(*order);
  return true;
}

Status OrderBook::action_commanded(const std::string& command) {
  Order* order = running();
  if (order == nullptr) return {};
  order->action_command = command;
  return record(*order);
}

void OrderBook::fail_current(const std::string& reason, TimeNs now) {
  Order* order = running();
  if (order == nullptr) return;
  order->state = OrderState::failed;
  order->finished = now;
  order->failure = reason;
  publish_ended(*order);
}

Result<OrderState> OrderBook::withdraw(const std::string& name, const std::string& reason, TimeNs now) {
  Order* found = const_cast<Order*>(find(name));  // find is const; the book is ours to change
  if (found == nullptr) return fail(ErrorCode::not_found, "no order '" + name + "'");
  Order& order = *found;
  switch (order.state) {
    case OrderState::queued:
      order.state = OrderState::withdrawn;
      order.finished = now;
      order.failure = reason;
      publish_ended(order);  // may forget it: `order` is not read again
      return OrderState::withdrawn;
    case OrderState::running:
      if (!order.withdrawal) {
        order.withdrawal = reason;
        (void)record(order);  // failures are the recorder's to report (see Recorder)
      }
      break;
    case OrderState::finished:
    case OrderState::failed:
    case OrderState::withdrawn:
      return fail(ErrorCode::conflict,
                  "order '" + name + "' has ended already (" + to_string(order.state) + ")");
  }
  return order.state;
}

bool OrderBook::withdrawal_pending() const {
  const Order* order = current();
  return order != nullptr && order->withdrawal.has_value();
}

void OrderBook::end_withdrawn(TimeNs now) {
  Order* order = running();
  if (order == nullptr) return;
  order->state = OrderState::withdrawn;
  order->finished = now;
  order->failure = order->withdrawal.value_or("");
  order->withdrawal.reset();
  publish_ended(*order);
}

void OrderBook::restore(std::vector<Order> orders) {
  for (Order& order : orders) {
    if (!is_open(order.state)) ++ended_;
    orders_.push_back(std::move(order));
  }
  forget_oldest_ended(false);
  for (const Order& order : orders_) publish(order);
}

void OrderBook::publish_ended(const Order& order) {
  changed(order);
  ++ended_;
  forget_oldest_ended();
}

void OrderBook::forget_oldest_ended(bool published) {
  while (ended_ > ended_kept_ && !orders_.empty()) {
    if (is_open(orders_.front().state)) break;  // older ended ones wait behind it
    const std::string name = std::move(orders_.front().name);
    orders_.pop_front();
    --ended_;
    if (published && hooks_.forgotten) hooks_.forgotten(name);
  }
}

std::size_t OrderBook::queued_count() const {
  return static_cast<std::size_t>(
      std::count_if(orders_.begin(), orders_.end(), [](const Order& o) { return o.state == OrderState::queued; }));
}

const Order* OrderBook::find(const std::string& name) const {
  for (const auto& order : orders_) {
    if (order.name == name) return &order;
  }
  return nullptr;
}

}  // namespace drover::logical_agent
