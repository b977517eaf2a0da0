#pragma once
// The routing agent's local view of the topology: a Topology built from the entity
// descriptions it has learnt, the CARP planner on it, and the replica of the published
// timelines (a TimelineSet in which every known entity is "owned"), kept current by
// apply(). Rebuilt whenever new descriptions arrived (they are static, so that stops
// soon after start). No DDS calls: the agent feeds it samples.

#include <memory>
#include <string>
#include <vector>

#include "agents/routing_agent/known_entities.hpp"
#include "drover/carp/planner.hpp"
#include "drover/carp/routing_graph.hpp"
#include "drover/common/result.hpp"
#include "drover/topology/model.hpp"
#include "drover/topology/timeline.hpp"
#include "topology.h"

namespace drover::routing_agent {

class RouteModel {
 public:
  /// Builds the model from every described vertex and every described edge whose two end
  /// vertices are described (the others cannot be placed yet). Conflict sets are those the
  /// descriptions give (restricted to described entities), so the reservations it expands
  /// are exactly what the owners expect.
  /// \return the model, or internal naming the first description the topology builder
  ///         rejected.
  static Result<std::unique_ptr<RouteModel>> build(const KnownEntities& known,
                                                   carp::PlannerOptions options);

  /// Takes in a timeline its owner published. Entities the model does not hold are
  /// ignored (false); reservations whose origin it does not hold keep no origin.
  bool apply(const msg::TimelineState& state);

  const topology::Topology& topology() const noexcept { return *topology_; }
  /// The replica as published: versions for prepares.
  topology::TimelineSet& timelines() noexcept { return timelines_; }
  /// What routes are planned on: the replica with every route step's copies widened to
  /// their hull (TimelineSet::widen_to_step_hulls), rebuilt after apply() changed it.
  const topology::TimelineSet& planning_timelines();
  carp::Planner& planner() noexcept { return planner_; }
  /// The partition that owns `entity`. \pre entity < topology().entity_count()
  const std::string& partition(topology::EntityIndex entity) const { return topology_->partition(entity); }

 private:
  RouteModel(std::shared_ptr<const topology::Topology> topology,
             std::shared_ptr<const carp::RoutingGraph> graph,
             std::vector<std::vector<topology::EntityIndex>> conflict_sets, carp::PlannerOptions options);

  std::shared_ptr<const topology::Topology> topology_;
  std::shared_ptr<const carp::RoutingGraph> graph_;
  carp::Planner planner_;
  topology::TimelineSet timelines_;
  topology::TimelineSet planning_;
  bool planning_stale_ = true;
};

}  // namespace drover::routing_agent
