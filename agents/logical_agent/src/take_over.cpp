// The logical agent taking over from an earlier life of itself (a crash, a kill -9): the
// orders it stored, what it left at the topology agents, and commands it gave that the RAN
// still runs.

#include <algorithm>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include "agents/logical_agent/src/logical_agent.hpp"

namespace drover::logical_agent {

namespace {
/// How long (real time) the start waits for the topology agents to say what an earlier
/// life left: the vehicle is not protected by a hold of its vertex until then.
constexpr std::chrono::seconds kTakeOverPatience{5};
/// take_over_late: how long one try waits for answers, and the pause between tries.
constexpr std::chrono::milliseconds kLateTakeOverTry{1000};
constexpr std::chrono::seconds kLateTakeOverPause{1};
}  // namespace

void LogicalAgent::restore_orders(std::vector<Order> orders) {
  if (!journal_) return;
  const TimeNs now = clock_.now();
  std::size_t unfinished = 0;
  std::lock_guard lock(mutex_);
  for (Order& order : orders) {
    const bool open = is_open(order.state);
    std::optional<std::string> lost;
    for (std::size_t i = 0; i < order.destinations.size(); ++i) {
      Destination& destination = order.destinations[i];
      const auto entity = topology_->find(destination.location_id);
      if (entity && topology_->is_vertex(*entity)) {
        destination.location = *entity;
      } else if (!lost) {
        lost = fmt::format("destination {}: '{}' is not a vertex of topology '{}'", i, destination.location_id,
                           topology_->name());
      }
    }
    if (open && lost) {
      // Stored for another topology file (edited since): it cannot be driven.
      order.state = OrderState::failed;
      order.finished = now;
      order.failure = "restored after a restart of the agent, but " + *lost;
      if (Status stored = record_order(order, false); !stored) spdlog::error("{}", stored.error().message);
      raise_alarm(msg::ALARM_ERROR,
                  "order '" + order.name + "' of vehicle '" + vehicle_id() + "' failed: " + order.failure);
      continue;
    }
    if (!open) continue;
    ++unfinished;
    if (order.state == OrderState::running && order.action_command) adopted_command_ = order.action_command;
  }
  const std::size_t count = orders.size();
  book_.restore(std::move(orders));
  spdlog::info("order journal {}: {} order(s) restored, {} of them unfinished", journal_->file().string(), count,
               unfinished);
}

Status LogicalAgent::resume_action(const ran::CommandId& command, const Destination& destination) {
  const std::string what =
      fmt::format("action '{}' at '{}' (RAN command '{}')", destination.operation, destination.location_id, command);
  const auto action = operation_action(destination);
  set_activity(action && action->kind == ran::ActionKind::charge ? Activity::charging : Activity::operating);
  // Listed now, the command is followed from this status on; if not, the RAN never got it
  // or restarted too.
  CommandWatch watch = watch_from_now();
  const auto status = latest_status();
  const bool listed = status && status->find_command(command) != nullptr;
  if (listed) watch.observe(*status, command, std::chrono::steady_clock::now());
  Status outcome;
  if (!listed) {
    outcome = fail(ErrorCode::unavailable,
                   "the logical agent restarted while " + what +
                       " was under way, and the RAN does not report that command: whether it was done is unknown "
                       "(check the vehicle, then send the rest of the order again)");
  } else {
    spdlog::info("restored order: waiting for the outcome of {}, commanded by an earlier life", what);
    outcome = await_action(command, destination.operation, watch);
  }
  std::lock_guard lock(mutex_);
  adopted_command_.reset();
  ended_commands_.erase(command);
  return outcome;
}

bool LogicalAgent::take_over() {
  const auto give_up = std::chrono::steady_clock::now() + kTakeOverPatience;
  auto holdings = services_->holdings(vehicle_id(), give_up);
  if (!holdings) {
    if (stopping_) return false;
    // Nothing to take over is known; the agent works on (its holds may then wait behind
    // what the earlier life left, as before this check existed).
    spdlog::error("what an earlier life of '{}' left at the topology agents is unknown: {}", vehicle_id(),
                  holdings.error().message);
    return true;
  }
  if (!holdings->unanswered.empty()) {
    // Never seen or silent: what an earlier life left there is asked again once they have a
    // live owner (take_over_late); a hold of a vertex in another partition does not wait.
    spdlog::error("partition(s) {} did not say within {} s what an earlier life of '{}' left there", 
                  fmt::join(holdings->unanswered, ", "), kTakeOverPatience.count(), vehicle_id());
    unknown_partitions_ = holdings->unanswered;
  }
  adopt_leftovers(*holdings, {});
  return true;
}

void LogicalAgent::adopt_leftovers(const Holdings& left, const std::vector<std::string>& partitions) {
  if (left.held.empty() && left.routes.empty()) return;
  std::vector<std::string> held_ids;
  for (const auto& [entity, step] : left.held) {
    monitor_.hold(entity, step, true);
    held_ids.push_back(topology_->id(entity));
  }
  spdlog::warn("taking over from an earlier life of '{}': it holds [{}] and left {} route(s) reserved, now cancelled",
               vehicle_id(), fmt::join(held_ids, ", "), left.routes.size());
  for (const auto route : left.routes) {
    if (auto cancelled = services_->cancel_route(vehicle_id(), route, monitor_.held_steps_of(route), partitions);
        !cancelled) {
      spdlog::warn("route {} of an earlier life not cancelled everywhere: {}", route, cancelled.error().message);
    }
  }
}

bool LogicalAgent::take_over_late(const std::string& partition) {
  const auto known = [&] {
    return partition.empty() ||
           std::find(unknown_partitions_.begin(), unknown_partitions_.end(), partition) == unknown_partitions_.end();
  };
  const auto now = std::chrono::steady_clock::now();
  if (unknown_partitions_.empty() || now < next_late_take_over_) return known();
  next_late_take_over_ = now + kLateTakeOverPause;
  std::vector<std::string> reachable;
  for (const auto& unknown : unknown_partitions_) {
    if (services_->owner_of_partition(unknown)) reachable.push_back(unknown);
  }
  if (reachable.empty()) return known();
  // One short try: an owner that seems live but does not answer (just crashed) must not
  // keep the executor from its vehicle; the pause counts from the end of the try.
  auto holdings = services_->holdings(vehicle_id(), now + kLateTakeOverTry, reachable);
  next_late_take_over_ = std::chrono::steady_clock::now() + kLateTakeOverPause;
  if (!holdings) {
    spdlog::warn("what an earlier life of '{}' left in partition(s) {} is still unknown: {}", vehicle_id(),
                 fmt::join(reachable, ", "), holdings.error().message);
    return known();
  }
  std::vector<std::string> answered;
  for (const auto& partition : reachable) {
    if (std::find(holdings->unanswered.begin(), holdings->unanswered.end(), partition) != holdings->unanswered.end()) {
      continue;
    }
    answered.push_back(partition);
    std::erase(unknown_partitions_, partition);
  }
  if (answered.empty()) return known();
  Holdings left;
  for (const auto& [entity, step] : holdings->held) {
    if (!own_routes_.contains(step.route) && !monitor_.holds(entity)) left.held.emplace_back(entity, step);
  }
  for (const auto route : holdings->routes) {
    if (!own_routes_.contains(route)) left.routes.push_back(route);
  }
  spdlog::info("partition(s) {} answered what an earlier life of '{}' left there", fmt::join(answered, ", "),
               vehicle_id());
  adopt_leftovers(left, answered);
  if (!left.held.empty()) {
    // Leftovers go once the footprint leaves them; a vehicle that stands (parked, say)
    // would otherwise keep them until it next drives.
    if (const auto status = recent_standing_status()) release_passed(*status);
  }
  if (unknown_partitions_.empty()) own_routes_.clear();
  return known();
}

bool LogicalAgent::earlier_commands_running(const ran::VehicleStatus& status) {
  const std::string ours = command_prefix_ + "-";
  std::optional<ran::CommandId> adopted;
  {
    std::lock_guard lock(mutex_);
    adopted = adopted_command_;
  }
  // The adopted action is the restored order's to wait for (resume_action), however long.
  const auto running = std::find_if(status.commands.begin(), status.commands.end(), [&](const auto& command) {
    return !ran::is_terminal(command.state) && command.id.rfind(ours, 0) != 0 && command.id != adopted;
  });
  const TimeNs now = clock_.now();
  if (running == status.commands.end()) {
    if (!earlier_commands_since_) return false;
    // Still braking, for a while at most (a status that never shows it still must not keep
    // the vehicle from being held for ever).
    if (!ran::standing_still(status.linear_speed, status.angular_speed) &&
        now - *earlier_commands_since_ <= 2 * options_.error_limit) {
      return true;
    }
    spdlog::info("the commands this life did not give have ended");
    earlier_commands_since_.reset();
    earlier_commands_cancelled_ = false;
    return false;
  }
  if (!earlier_commands_since_) {
    spdlog::info("command '{}' (not this life's) still runs: waiting for it to end", running->id);
    earlier_commands_since_ = now;
  } else if (now - *earlier_commands_since_ > options_.error_limit && !earlier_commands_cancelled_) {
    // A vehicle paused for good, an action that never ends: stopped as stop_vehicle stops
    // this life's moves (a cancel ends the command named and all queued after it), once.
    earlier_commands_cancelled_ = true;
    if (auto cancelled = ran_->cancel(running->id, options_.call_timeout); !cancelled) {
      spdlog::warn("cancel of command '{}' not taken: {}", running->id, cancelled.error().message);
    } else {
      spdlog::warn("command '{}' (not this life's) cancelled after running for {:.1f} s", running->id,
                   ns_to_seconds(now - *earlier_commands_since_));
    }
  }
  return true;
}

}  // namespace drover::logical_agent
