#pragma once
// One planned route while the vehicle drives it (no DDS): which steps are allocated, which
// moves were commanded, where the vehicle is along the route, how late it runs, and the
// windows as delays move them. Steps alternate vertex, edge, vertex, ...; step 0 is the
// vertex the vehicle starts from (held when the route begins).

#include <cstddef>
#include <memory>
#include <optional>
#include <vector>

#include "drover/carp/vehicle.hpp"
#include "drover/common/clock.hpp"
#include "drover/ran/commands.hpp"
#include "drover/topology/model.hpp"
#include "drover/topology/timeline.hpp"

namespace drover::logical_agent {

/// The RAN command to drive along `edge` to `target`, one of its ends, from its other end
/// or from part-way along it: at most `max_speed`, the edge's and its restriction's limits
/// (as the RAN checks them, ran/src/validation.cpp); its motion area the footprints of the
/// edge and both its ends.
ran::MoveCommand move_along(const topology::Topology& world, topology::EntityIndex edge, topology::EntityIndex target,
                            const std::string& id, double max_speed);

class RouteTracker {
 public:
  /// \pre steps alternate vertex, edge, vertex of `topology`, starting and ending at a
  ///      vertex (the routing agent guarantees it); at least one step.
  RouteTracker(std::shared_ptr<const topology::Topology> topology, topology::RouteId route,
               std::vector<topology::RouteStep> steps);

  topology::RouteId id() const noexcept { return route_; }
  std::size_t size() const noexcept { return steps_.size(); }
  const topology::RouteStep& step(std::size_t index) const { return steps_.at(index); }
  const std::vector<topology::RouteStep>& steps() const noexcept { return steps_; }
  std::size_t last() const noexcept { return steps_.size() - 1; }

  /// Follows a delay: the window of `from_step` ends `by` later, later steps move by `by`
  /// (open ends stay open). Out-of-range from_step: nothing.
  void shift(std::size_t from_step, DurationNs by);

  // ---- allocation, in route order ----
  /// Steps [0, allocated()) are allocated.
  std::size_t allocated() const noexcept { return allocated_; }
  /// The next step to allocate when it lies within `lookahead` vertices past `position_step`
  /// (the step the vehicle is on); nullopt when all are allocated or it is too far ahead.
  std::optional<std::size_t> next_to_allocate(std::size_t position_step, std::size_t lookahead) const;
  /// Records that step allocated() is allocated now.
  void mark_allocated() { ++allocated_; }

  // ---- moves, only onto allocated steps ----
  /// The vertex step the last commanded move ends at (0: none commanded).
  std::size_t commanded() const noexcept { return commanded_; }
  /// The next edge step to command when it and its target vertex are allocated.
  std::optional<std::size_t> next_move() const;
  /// The move along edge step `edge_step` (to the vertex after it), its motion area the
  /// footprints of the vertex before, the edge and the vertex after; commanded() moves on.
  ran::MoveCommand command_move(std::size_t edge_step, const std::string& id, double max_speed);

  // ---- where the vehicle is ----
  /// The vertex step the vehicle reached last (moves finished in order).
  std::size_t reached() const noexcept { return reached_; }
  void mark_reached(std::size_t vertex_step) { reached_ = std::max(reached_, vertex_step); }
  /// The step the vehicle is on: the vertex it reached, or the edge after it when a move
  /// from there is commanded.
  std::size_t position_step() const noexcept {
    return commanded_ > reached_ ? reached_ + 1 : reached_;
  }
  bool arrived() const noexcept { return reached_ == last(); }

  /// Metres from `position` to the vertex of `vertex_step` along the route: straight to
  /// the next vertex ahead of reached(), then along the edges.
  double remaining_distance(const topology::Point& position, std::size_t vertex_step) const;

  /// How late the vehicle will be at the next vertex ahead (planned arrival = its window's
  /// start), estimated from where it is, its speed and its profile; nullopt when arrived.
  /// Negative: early.
  std::optional<DurationNs> lateness(const topology::Point& position, double speed,
                                     const carp::VehicleProfile& vehicle, TimeNs now) const;

 private:
  std::shared_ptr<const topology::Topology> topology_;
  topology::RouteId route_;
  std::vector<topology::RouteStep> steps_;
  std::size_t allocated_ = 0;
  std::size_t commanded_ = 0;
  std::size_t reached_ = 0;
};

}  // namespace drover::logical_agent
