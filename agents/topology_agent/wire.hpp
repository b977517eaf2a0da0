#pragma once
// Conversions between the topology library's types and the messages of idl/topology.idl.
// On the wire entities are named by their string ids; indices are local to a process, so
// every conversion goes through the Topology.

#include <string>
#include <vector>

#include "drover/common/result.hpp"
#include "drover/topology/model.hpp"
#include "drover/topology/timeline.hpp"
#include "topology.h"

namespace drover::topology_agent {

/// The static description of `entity` as published on drover/topology/entity.
/// \pre entity < topology.entity_count()
msg::EntityDescription to_wire_description(const topology::Topology& topology,
                                           topology::EntityIndex entity);

/// The wire form of an interval and back (no validation: the TimelineSet checks windows).
msg::Interval to_wire(const topology::Interval& interval);
topology::Interval from_wire(const msg::Interval& interval);

/// The wire form of a reservation (entity and origin by id).
msg::Reservation to_wire(const topology::Topology& topology, const topology::Reservation& item);

/// A reservation received on the wire. \return it, or not_found naming the unknown entity
/// or origin id.
Result<topology::Reservation> from_wire(const topology::Topology& topology,
                                        const msg::Reservation& item);

/// Lock ids are "<topology agent id>/<number>", unique across topology agents.
std::string wire_lock_id(const std::string& agent_id, topology::LockId id);

/// The timeline of `entity` as published on drover/topology/timeline; locks are named with
/// wire_lock_id(agent_id, ...).
msg::TimelineState to_wire_timeline(const topology::Topology& topology, const std::string& agent_id,
                                    topology::EntityIndex entity, const topology::Timeline& timeline);

}  // namespace drover::topology_agent
