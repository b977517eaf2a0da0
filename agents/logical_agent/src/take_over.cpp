// The logical agent taking over from an earlier life of itself (a crash, a kill -9): what
// that life left at the topology agents, and commands it gave that the RAN still runs.

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
}  // namespace

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
    // Never seen or silent: what an earlier life left there stays (a hold of the vertex
    // must not wait for it).
    spdlog::error("partition(s) {} did not say within {} s what an earlier life of '{}' left there", 
                  fmt::join(holdings->unanswered, ", "), kTakeOverPatience.count(), vehicle_id());
  }
  if (holdings->held.empty() && holdings->routes.empty()) return true;
  std::vector<std::string> held_ids;
  for (const auto& [entity, step] : holdings->held) {
    monitor_.hold(entity, step);
    held_ids.push_back(topology_->id(entity));
  }
  monitor_.forget_steps();  // leftovers: released once the footprint leaves them
  spdlog::warn("taking over from an earlier life of '{}': it holds [{}] and left {} route(s) reserved, now cancelled",
               vehicle_id(), fmt::join(held_ids, ", "), holdings->routes.size());
  for (const auto route : holdings->routes) {
    if (auto cancelled = services_->cancel_route(vehicle_id(), route, monitor_.held_steps_of(route));
        !cancelled) {
      spdlog::warn("route {} of an earlier life not cancelled everywhere: {}", route, cancelled.error().message);
    }
  }
  return true;
}

bool LogicalAgent::earlier_commands_running(const ran::VehicleStatus& status) {
  const std::string ours = command_prefix_ + "-";
  const auto running = std::find_if(status.commands.begin(), status.commands.end(), [&](const auto& command) {
    return !ran::is_terminal(command.state) && command.id.rfind(ours, 0) != 0;
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
