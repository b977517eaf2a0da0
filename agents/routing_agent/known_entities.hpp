#pragma once
// What a routing agent has learnt of the topology: the entity descriptions the topology
// agents publish (drover/topology/entity, transient-local), by id. It answers the one
// question the agent must settle before planning (docs/routing-agent.md "How it learns"):
// is everything a route from this start could touch described yet?

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "topology.h"

namespace drover::routing_agent {

/// An entity a request needs that no description names yet, and who refers to it.
struct MissingEntity {
  std::string id;
  /// The entity whose description refers to it (an edge end, an out-edge, a conflict);
  /// empty when the request itself named it.
  std::string referenced_by;
};

/// Not thread-safe; the routing agent guards it with its mutex.
class KnownEntities {
 public:
  /// Keeps `description` (replacing an earlier one of the same id).
  /// \return whether anything changed (a repeat of the same description changes nothing).
  bool add(const msg::EntityDescription& description);

  const msg::EntityDescription* find(const std::string& id) const;
  const std::map<std::string, msg::EntityDescription>& all() const noexcept { return entities_; }
  /// Incremented by every change; a model built at generation g is current while it stays g.
  std::uint64_t generation() const noexcept { return generation_; }

  /// The first entity that a route from `start` through `stops` could need and that is not
  /// described: the request's vertices themselves, then, over the component reachable from
  /// `start` by driving (vertex -> out_edges -> the edge's other end), every edge's end
  /// vertices and every member of every reached entity's conflict set (with the end vertices
  /// of those that are edges, so that they can be placed in the model).
  /// \return nullopt when everything is known: the model built from these descriptions
  ///         holds the whole reachable component with complete conflict sets.
  std::optional<MissingEntity> first_missing(const std::string& start,
                                             const std::vector<std::string>& stops);

 private:
  std::map<std::string, msg::EntityDescription> entities_;
  std::uint64_t generation_ = 0;
  /// Starts whose component was found complete at generation complete_generation_.
  std::vector<std::string> complete_starts_;
  std::uint64_t complete_generation_ = 0;
};

}  // namespace drover::routing_agent
