#pragma once
// Footprint monitoring (no DDS): the vehicle's reported footprint must stay inside the
// footprints of the entities allocated to it; an allocated entity the footprint no longer
// touches, and which the vehicle has passed, is to be released.

#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <vector>

#include "drover/ran/commands.hpp"
#include "drover/topology/model.hpp"
#include "drover/topology/timeline.hpp"

namespace drover::logical_agent {

/// The route step an allocation was granted as.
struct HeldStep {
  topology::RouteId route = 0;
  std::uint32_t step = 0;
  friend bool operator==(const HeldStep&, const HeldStep&) = default;
};

class FootprintMonitor {
 public:
  /// \param tolerance_m2  how much of the footprint may lie outside (round-off).
  FootprintMonitor(std::shared_ptr<const topology::Topology> topology, double tolerance_m2 = 1e-3);

  /// The vehicle holds `entity`, granted as `granted_as`, a step of its current route
  /// (`leftover`: of an earlier route, behind the vehicle whatever its step).
  void hold(topology::EntityIndex entity, HeldStep granted_as, bool leftover = false);
  void drop(topology::EntityIndex entity);
  /// Marks every held entity a leftover of an earlier route (a new route begins): behind
  /// the vehicle whatever its step.
  void forget_steps();
  bool holds(topology::EntityIndex entity) const { return held_.count(entity) != 0; }
  /// The route step `entity` was granted as (of the current route or an earlier one);
  /// nullopt when not held. Its release gives up that step's shadows too.
  std::optional<HeldStep> granted_as(topology::EntityIndex entity) const;
  /// The steps of `route` still held, ascending (what a cancel of the route must keep).
  std::vector<std::uint32_t> held_steps_of(topology::RouteId route) const;
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
  struct Holding {
    HeldStep granted_as;
    bool current_route = true;  ///< false: a leftover of an earlier route
  };
  std::map<topology::EntityIndex, Holding> held_;
  mutable std::optional<ran::MotionArea> area_;  ///< normalized union, rebuilt on demand
};

}  // namespace drover::logical_agent
