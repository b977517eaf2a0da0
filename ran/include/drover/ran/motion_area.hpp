#pragma once
// Geometry a driver needs to keep its vehicle inside its motion area: place the vehicle's
// footprint at a pose, merge the parts of a motion area, and measure how much of a
// footprint lies outside it.

#include "drover/ran/commands.hpp"

namespace drover::ran {

/// The vehicle's footprint placed at `pose`: `vehicle_frame` is given with the vehicle's
/// reference point at the origin, facing +x; it is rotated by pose.theta, then translated.
topology::Polygon footprint_at(const topology::Polygon& vehicle_frame, const Pose& pose);

/// The union of the parts of `area` as a valid multi-polygon (the parts of a MotionArea may
/// overlap). Parts that are not valid polygons after boost::geometry::correct are skipped.
MotionArea normalized_area(const MotionArea& area);

/// The area (m^2) of `shape` that lies outside `normalized` (a normalized_area result).
double area_outside(const topology::Polygon& shape, const MotionArea& normalized);

/// The region a convex shape sweeps when translated from `shape` by (dx, dy): the convex
/// hull of its start and end placements (for a non-convex shape a superset, so checking it
/// against an area errs on the safe side).
topology::Polygon swept_by_translation(const topology::Polygon& shape, double dx, double dy);

}  // namespace drover::ran
