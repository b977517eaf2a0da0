// Making way: a vehicle standing for good where another one's route must go (idle on a
// station, or waiting for a route of its own) is asked to drive aside to a free parking
// vertex. Without it two vehicles waiting for each other's place would wait until their
// orders fail (the route limit), like openTCS's idle vehicles that block a destination.

#include <utility>

#include <spdlog/spdlog.h>

#include "agents/logical_agent/src/logical_agent.hpp"

namespace drover::logical_agent {

namespace {

/// A blocked requester asks the same blocker again after this long (shared clock).
constexpr DurationNs kMakeWayRepeat = seconds_to_ns(10);
/// A request older than this is dropped unanswered: the requester, if still blocked, has
/// asked again by then.
constexpr DurationNs kMakeWayValid = seconds_to_ns(20);

}  // namespace

void LogicalAgent::ask_make_way(const std::vector<std::string>& blockers, topology::EntityIndex goal) {
  const TimeNs now = clock_.now();
  for (const auto& blocker : blockers) {
    if (blocker == vehicle_id()) continue;
    auto [asked, first] = make_way_asked_.try_emplace(blocker, now);
    if (!first && now - asked->second < kMakeWayRepeat) continue;
    asked->second = now;
    msg::MakeWayRequest request;
    request.requester(vehicle_id());
    request.vehicle(blocker);
    request.location(topology_->id(goal));
    request.time().ns(now);
    if (auto written = make_way_writer_->write(request); !written) {
      spdlog::warn("request to make way not published: {}", written.error().message);
      continue;
    }
    spdlog::info("asking '{}' to make way (it stands in the way to '{}')", blocker, topology_->id(goal));
  }
}

std::optional<std::string> LogicalAgent::make_way_requested() {
  std::lock_guard lock(mutex_);
  if (!make_way_) return std::nullopt;
  if (clock_.now() - make_way_->time > kMakeWayValid) {
    make_way_.reset();
    return std::nullopt;
  }
  return make_way_->requester;
}

bool LogicalAgent::make_way(const std::string& requester) {
  {
    std::lock_guard lock(mutex_);
    make_way_.reset();
  }
  if (making_way_ || !vertex_) return false;
  spdlog::info("making way for '{}': leaving '{}' for a free parking vertex", requester, topology_->id(*vertex_));
  making_way_ = true;
  const Activity driving = drive_activity_;  // the order's drive resumes afterwards
  // Nested in the order's drive: a pause meanwhile is the outer drive's to notice itself,
  // so a later real failure of it is not taken for a stop for the pause.
  const bool stopped_for_pause = std::exchange(stopped_for_pause_, false);
  const bool moved = drive_to_nearest(topology::VertexKind::parking, false);
  drive_activity_ = driving;
  stopped_for_pause_ = stopped_for_pause;
  making_way_ = false;
  if (!moved) spdlog::info("could not make way for '{}': no free parking vertex reachable", requester);
  return moved;
}

}  // namespace drover::logical_agent
