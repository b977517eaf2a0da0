#pragma once
// Conflict sets: which entities' footprints overlap. Computed once when a topology is built.

#include <span>
#include <vector>

#include "drover/topology/geometry.hpp"
#include "drover/topology/model.hpp"

namespace drover::topology {

/// Two footprints overlap when the area of their intersection exceeds this (m^2, i.e. one
/// square millimetre). Footprints that only touch (share boundary points or segments) have
/// an intersection of area zero, so they never conflict, even where floating-point
/// rounding of generated footprints leaves a sliver of overlap far thinner than this.
inline constexpr double kOverlapAreaEpsilon = 1e-6;

/// The area (m^2) of the intersection of `a` and `b`; 0 when they are disjoint or only touch.
/// \pre both are corrected, valid polygons.
double footprint_overlap_area(const Polygon& a, const Polygon& b);

/// True when the interiors of `a` and `b` overlap (intersection area > kOverlapAreaEpsilon).
/// \pre both are corrected, valid polygons.
bool footprints_overlap(const Polygon& a, const Polygon& b);

/// C(e) for every footprint: the indices of the other footprints that overlap it
/// (footprints_overlap), sorted ascending, symmetric, never containing e itself.
/// Candidates come from a Boost.Geometry R-tree of bounding boxes, so the cost grows with
/// the number of nearby pairs, not with the square of the entity count.
std::vector<std::vector<EntityIndex>> compute_conflict_sets(
    std::span<const Polygon* const> footprints);

}  // namespace drover::topology
