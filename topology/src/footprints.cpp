// Boost 1.74's rescale policy, inlined into set operations (intersection, difference),
// trips GCC 12's -Wmaybe-uninitialized on a variable it always sets; silenced for this
// file only.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"

#include "drover/topology/footprints.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <boost/geometry/geometries/multi_polygon.hpp>

namespace drover::topology {

namespace bg = boost::geometry;

namespace {

using MultiPolygon = bg::model::multi_polygon<Polygon>;

Polygon from_corners(std::initializer_list<Point> corners) {
  Polygon polygon;
  for (const auto& corner : corners) bg::append(polygon.outer(), corner);
  bg::correct(polygon);
  return polygon;
}

}  // namespace

Polygon axis_aligned_rectangle(double min_x, double min_y, double max_x, double max_y) {
  return from_corners({Point{min_x, min_y}, Point{min_x, max_y}, Point{max_x, max_y},
                       Point{max_x, min_y}});
}

Polygon vertex_footprint(const Point& center, const FootprintOptions& options) {
  const double r = options.vertex_radius;
  if (!options.vertex_disc) {
    return axis_aligned_rectangle(center.x() - r, center.y() - r, center.x() + r,
                                  center.y() + r);
  }
  Polygon disc;
  for (int corner = 0; corner < options.disc_points; ++corner) {
    const double angle = 2.0 * std::numbers::pi * corner / options.disc_points;
    bg::append(disc.outer(),
               Point{center.x() + r * std::cos(angle), center.y() + r * std::sin(angle)});
  }
  bg::correct(disc);
  return disc;
}

Polygon segment_rectangle(const Point& a, const Point& b, double half_width) {
  const double dx = b.x() - a.x();
  const double dy = b.y() - a.y();
  const double length = std::hypot(dx, dy);
  // Unit normal of the segment, scaled to the half width.
  const double nx = -dy / length * half_width;
  const double ny = dx / length * half_width;
  return from_corners({Point{a.x() + nx, a.y() + ny}, Point{b.x() + nx, b.y() + ny},
                       Point{b.x() - nx, b.y() - ny}, Point{a.x() - nx, a.y() - ny}});
}

std::optional<Polygon> edge_footprint(const Point& from, const Point& to,
                                      const Polygon& from_footprint,
                                      const Polygon& to_footprint,
                                      const FootprintOptions& options) {
  const Polygon rectangle = segment_rectangle(from, to, options.edge_half_width);
  MultiPolygon without_from;
  bg::difference(rectangle, from_footprint, without_from);
  MultiPolygon without_both;
  bg::difference(without_from, to_footprint, without_both);

  const auto largest = std::max_element(
      without_both.begin(), without_both.end(),
      [](const Polygon& lhs, const Polygon& rhs) { return bg::area(lhs) < bg::area(rhs); });
  if (largest == without_both.end()) return std::nullopt;
  Polygon footprint = *largest;
  if (normalize_footprint(footprint)) return std::nullopt;
  return footprint;
}

std::optional<std::string> normalize_footprint(Polygon& polygon) {
  for (const auto& corner : polygon.outer()) {
    if (!std::isfinite(corner.x()) || !std::isfinite(corner.y())) {
      return "a corner has a non-finite coordinate";
    }
    if (std::abs(corner.x()) > kMaxCornerCoordinate ||
        std::abs(corner.y()) > kMaxCornerCoordinate) {
      return "a corner lies more than 1010000 m from the origin on an axis";
    }
  }
  if (!polygon.inners().empty()) return "holes are not supported";
  bg::correct(polygon);
  std::string reason;
  if (!bg::is_valid(polygon, reason)) {
    // A self-intersecting ring with zero net area (a symmetric bow tie) cannot be oriented,
    // and is_valid names the orientation before the self-intersection; say what is wrong.
    if (bg::intersects(polygon)) return "invalid polygon: it intersects itself";
    return "invalid polygon: " + reason;
  }
  if (bg::area(polygon) < kMinFootprintArea) return "area is (nearly) zero";
  return std::nullopt;
}

}  // namespace drover::topology

#pragma GCC diagnostic pop
