#pragma once
// Footprint geometry: generating the footprints a file leaves out, and checking the ones it
// gives. All polygons leave these functions corrected (clockwise, closed), so the
// orientation of the input never matters.

#include <optional>
#include <string>

#include "drover/topology/geometry.hpp"
#include "drover/topology/model.hpp"

namespace drover::topology {

/// The generated footprint of a vertex at `center`: an axis-aligned square of half side
/// `options.vertex_radius`, or (options.vertex_disc) a regular polygon with
/// `options.disc_points` corners inscribed in the circle of that radius.
/// \pre options are valid (radius > 0 and finite, disc_points >= 3).
Polygon vertex_footprint(const Point& center, const FootprintOptions& options);

/// The segment from `a` to `b` buffered by `half_width` on both sides, with flat ends:
/// a rectangle whose short sides pass through `a` and `b`. \pre a != b, half_width > 0.
Polygon segment_rectangle(const Point& a, const Point& b, double half_width);

/// An axis-aligned rectangle [min_x, max_x] x [min_y, max_y]. \pre min < max on both axes.
Polygon axis_aligned_rectangle(double min_x, double min_y, double max_x, double max_y);

/// The generated footprint of an edge: segment_rectangle(from, to, edge_half_width) minus
/// the footprints of its end vertices. Where the difference falls apart, the largest piece
/// is kept (the others are slivers at the rectangle's corners).
/// \return the footprint, or nullopt when the end vertices' footprints cover the whole
///         rectangle (less than kMinFootprintArea is left).
std::optional<Polygon> edge_footprint(const Point& from, const Point& to,
                                      const Polygon& from_footprint,
                                      const Polygon& to_footprint,
                                      const FootprintOptions& options);

/// The most corners a generated disc may have (more buys no accuracy, only cost).
inline constexpr int kMaxDiscPoints = 256;

/// Footprints smaller than this (m^2) are treated as empty.
inline constexpr double kMinFootprintArea = 1e-6;

/// How far (m) from the origin, on each axis, a vertex may lie. A plant fits many times
/// over, and at this scale a double resolves positions to well below a micrometre, so
/// footprints and their overlaps keep their area (far out, two vertices a few metres apart,
/// or two tiny squares on one spot, would round to the same corners and stop conflicting).
inline constexpr double kMaxCoordinate = 1e6;

/// The range (m) of `vertex_radius` and `edge_half_width`: at the least, a generated
/// footprint's area (and two coinciding ones' overlap) is far above kMinFootprintArea, so
/// vertices on one spot always conflict; at the most, it stays near kMaxCoordinate.
inline constexpr double kMinFootprintOption = 0.01;
inline constexpr double kMaxFootprintOption = 1e4;

/// How far (m) from the origin, on each axis, a footprint's corner may lie: as far as a
/// generated footprint of a vertex within kMaxCoordinate reaches, so that a topology
/// written out with its generated footprints reads back (as agents pass it on).
inline constexpr double kMaxCornerCoordinate = kMaxCoordinate + kMaxFootprintOption;

/// The longest length (m) an edge may be given: more than any two points within
/// kMaxCoordinate lie apart.
inline constexpr double kMaxEdgeLength = 1e7;

/// Corrects `polygon` in place (orientation, closing point) and checks that it can serve
/// as a footprint: corners within kMaxCornerCoordinate of the origin on each axis, valid per
/// boost::geometry::is_valid (no self-intersection, no spikes, at least three distinct
/// corners), no holes, area of at least kMinFootprintArea.
/// \return nullopt when it is usable, otherwise the reason it is not.
std::optional<std::string> normalize_footprint(Polygon& polygon);

}  // namespace drover::topology
