#pragma once
// 2-D geometry types shared by the topology library and everything above it.

#include <boost/geometry.hpp>
#include <boost/geometry/geometries/point_xy.hpp>
#include <boost/geometry/geometries/polygon.hpp>

namespace drover::topology {

/// A point in metres, in the plant's frame.
using Point = boost::geometry::model::d2::point_xy<double>;
/// A footprint: clockwise, closed polygon (Boost.Geometry's defaults), metres.
using Polygon = boost::geometry::model::polygon<Point>;
/// An axis-aligned box, used by the R-tree.
using Box = boost::geometry::model::box<Point>;

}  // namespace drover::topology
