#pragma once
// Conversions between the route service's messages (idl/routing.idl) and the CARP
// library's request and route. Entities travel as ids; indices are the model's own.

#include "drover/carp/route.hpp"
#include "drover/common/result.hpp"
#include "drover/topology/model.hpp"
#include "routing.h"

namespace drover::routing_agent {

/// The carp vehicle profile a request carries (not validated: the planner does that).
carp::VehicleProfile from_wire(const msg::VehicleProfileMsg& vehicle);
msg::VehicleProfileMsg to_wire(const carp::VehicleProfile& vehicle);

/// The plan request of a route request on `topology`; start_time <= 0 means `now`.
/// \return it, or invalid_argument naming the field: a start or stop that is not a vertex
///         of the topology, a negative dwell, no stops.
Result<carp::PlanRequest> to_plan_request(const topology::Topology& topology, const msg::RouteRequest& request,
                                          TimeNs now);

/// Fills the route fields of `reply` (steps by entity id, stops, distance, times).
void fill_route(const topology::Topology& topology, const carp::Route& route, msg::RouteReply& reply);

}  // namespace drover::routing_agent
