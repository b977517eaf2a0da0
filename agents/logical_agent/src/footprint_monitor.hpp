#pragma once
// Footprint monitoring (no DDS): the vehicle's reported footprint must stay inside the
// footprints of the entities allocated to it; an allocated entity the footprint no longer
// touches, and which the vehicle has passed, is to be released.

#include <cstddef>
#include <map>
#include <memory>
#include <optional>
#include <vector>

#include "drover/ran/commands.hpp"
#include "drover/topology/model.hpp"

namespace drover::logical_agent {

class FootprintMonitor {
 public:
  /// \param tolerance_m2  how much of the footprint may lie outside (round-off).
  FootprintMonitor(std::shared_ptr<const topology::Topology> topology, double tolerance_m2 = 1e-3);

  /// The vehicle holds `entity` as step `step` of its current route; nullopt: a leftover of
  /// an earlier route (behind the vehicle whatever its step).
  void hold(topology::EntityIndex entity, std::optional<std::size_t> step);
  void drop(topology::EntityIndex entity);
  /// Marks every held entity a leftover of an earlier route (a new route begins).
  void forget_steps();
  bool holds(topology::EntityIndex entity) const { return held_.count(entity) != 0; }
  /// The current route's step `entity` is held as; nullopt for a leftover or an entity
  /// not held.
  std::optional<std::size_t> step_of(topology::EntityIndex entity) const {
    const auto found = held_.find(entity);
    return found == held_.end() ? std::nullopt : found->second;
  }
  std::vector<topology::EntityIndex> held() const;

  /// Area (m^2) of `footprint` outside the union of the held entities' footprints.
  double area_outside(const topology::Polygon& footprint) const;
  /// Whether `footprint` lies inside the held footprints (within the tolerance).
  bool inside(const topology::Polygon& footprint) const { return area_outside(footprint) <= tolerance_m2_; }

  /// Held entities whose step is at most `passed_step` (the vehicle is past them) or that
  /// are leftovers, and which `footprint` no longer needs: it does not touch them, or lies
  /// inside the other held entities' footprints (within the tolerance). Ascending by entity.
  /// Releasing an entity the footprint still touches is safe in the second case: the
  /// vehicle stays inside entities it holds, and no other agent holds anything whose
  /// footprint overlaps those (I1). It matters: a vehicle standing on a vertex always
  /// touches the edge it came by, and a route that steps aside onto a vertex and comes
  /// back must give that edge and the vertex it left to the agent passing in between.
  std::vector<topology::EntityIndex> releasable(const topology::Polygon& footprint, std::size_t passed_step) const;

 private:
  void rebuild_area() const;
  /// Whether `footprint` lies inside the held footprints other than `entity`'s.
  bool covered_without(const topology::Polygon& footprint, topology::EntityIndex entity) const;

  std::shared_ptr<const topology::Topology> topology_;
  double tolerance_m2_;
  std::map<topology::EntityIndex, std::optional<std::size_t>> held_;
  mutable std::optional<ran::MotionArea> area_;  ///< normalized union, rebuilt on demand
};

}  // namespace drover::logical_agent
