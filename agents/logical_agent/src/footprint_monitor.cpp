#include "agents/logical_agent/src/footprint_monitor.hpp"

#include <algorithm>

#include <boost/geometry.hpp>

#include "drover/ran/motion_area.hpp"

namespace drover::logical_agent {

namespace bg = boost::geometry;

FootprintMonitor::FootprintMonitor(std::shared_ptr<const topology::Topology> topology, double tolerance_m2)
    : topology_(std::move(topology)), tolerance_m2_(tolerance_m2) {}

void FootprintMonitor::hold(topology::EntityIndex entity, HeldStep granted_as, bool leftover) {
  held_[entity] = Holding{granted_as, !leftover};
  area_.reset();
}

void FootprintMonitor::drop(topology::EntityIndex entity) {
  held_.erase(entity);
  area_.reset();
}

void FootprintMonitor::forget_steps() {
  for (auto& [entity, holding] : held_) holding.current_route = false;
}

std::optional<HeldStep> FootprintMonitor::granted_as(topology::EntityIndex entity) const {
  const auto found = held_.find(entity);
  if (found == held_.end()) return std::nullopt;
  return found->second.granted_as;
}

std::vector<std::uint32_t> FootprintMonitor::held_steps_of(topology::RouteId route) const {
  std::vector<std::uint32_t> out;
  for (const auto& [entity, holding] : held_) {
    if (holding.granted_as.route == route) out.push_back(holding.granted_as.step);
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<topology::EntityIndex> FootprintMonitor::held() const {
  std::vector<topology::EntityIndex> out;
  for (const auto& [entity, holding] : held_) out.push_back(entity);
  return out;
}

void FootprintMonitor::rebuild_area() const {
  ran::MotionArea parts;
  for (const auto& [entity, holding] : held_) parts.push_back(topology_->footprint(entity));
  area_ = ran::normalized_area(parts);
}

double FootprintMonitor::area_outside(const topology::Polygon& footprint) const {
  if (!area_) rebuild_area();
  return ran::area_outside(footprint, *area_);
}

bool FootprintMonitor::covered_without(const topology::Polygon& footprint, topology::EntityIndex entity) const {
  ran::MotionArea others;
  for (const auto& [other, holding] : held_) {
    if (other != entity) others.push_back(topology_->footprint(other));
  }
  if (others.empty()) return false;
  return ran::area_outside(footprint, ran::normalized_area(others)) <= tolerance_m2_;
}

std::vector<topology::EntityIndex> FootprintMonitor::releasable(const topology::Polygon& footprint,
                                                                std::size_t passed_step) const {
  std::vector<topology::EntityIndex> out;
  for (const auto& [entity, holding] : held_) {
    if (holding.current_route && holding.granted_as.step > passed_step) continue;
    if (bg::intersects(footprint, topology_->footprint(entity)) && !covered_without(footprint, entity)) continue;
    out.push_back(entity);
  }
  return out;
}

}  // namespace drover::logical_agent
