// GCC 12 reports false maybe-uninitialized warnings inside Boost.Geometry's set operations;
// silenced for its headers only (they are first included here, through motion_area.hpp).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include "drover/ran/motion_area.hpp"

#include <boost/geometry.hpp>
#include <boost/geometry/geometries/multi_point.hpp>
#pragma GCC diagnostic pop
#include <Eigen/Geometry>

namespace drover::ran {

namespace bg = boost::geometry;
using topology::Point;
using topology::Polygon;

Polygon footprint_at(const Polygon& vehicle_frame, const Pose& pose) {
  const Eigen::Isometry2d transform =
      Eigen::Translation2d(pose.x, pose.y) * Eigen::Rotation2Dd(pose.theta);
  Polygon placed;
  for (const Point& corner : vehicle_frame.outer()) {
    const Eigen::Vector2d p = transform * Eigen::Vector2d(corner.x(), corner.y());
    placed.outer().emplace_back(p.x(), p.y());
  }
  // A rotation keeps the winding; correct() only closes the ring if the input was open.
  bg::correct(placed);
  return placed;
}

MotionArea normalized_area(const MotionArea& area) {
  MotionArea merged;
  for (Polygon part : area) {
    bg::correct(part);
    if (!bg::is_valid(part)) continue;
    MotionArea next;
    bg::union_(merged, part, next);
    merged = std::move(next);
  }
  return merged;
}

double area_outside(const Polygon& shape, const MotionArea& normalized) {
  MotionArea outside;
  bg::difference(shape, normalized, outside);
  return bg::area(outside);
}

Polygon swept_by_translation(const Polygon& shape, double dx, double dy) {
  bg::model::multi_point<Point> corners;
  for (const Point& corner : shape.outer()) {
    corners.push_back(corner);
    corners.emplace_back(corner.x() + dx, corner.y() + dy);
  }
  Polygon hull;
  bg::convex_hull(corners, hull);
  return hull;
}

}  // namespace drover::ran
