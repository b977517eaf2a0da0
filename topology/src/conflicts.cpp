// Boost 1.74's rescale policy, inlined into set operations (intersection, difference),
// trips GCC 12's -Wmaybe-uninitialized on a variable it always sets; silenced for this
// file only.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"

#include "drover/topology/conflicts.hpp"

#include <algorithm>
#include <utility>

#include <boost/geometry/geometries/multi_polygon.hpp>
#include <boost/geometry/index/rtree.hpp>

namespace drover::topology {

namespace bg = boost::geometry;
namespace bgi = boost::geometry::index;

namespace {

double box_overlap_area(const Box& a, const Box& b) {
  const double width = std::min(a.max_corner().x(), b.max_corner().x()) -
                       std::max(a.min_corner().x(), b.min_corner().x());
  const double height = std::min(a.max_corner().y(), b.max_corner().y()) -
                        std::max(a.min_corner().y(), b.min_corner().y());
  return width > 0 && height > 0 ? width * height : 0.0;
}

}  // namespace

double footprint_overlap_area(const Polygon& a, const Polygon& b) {
  // The intersection of the bounding boxes bounds the intersection of the polygons: a cheap
  // rejection of pairs that merely touch, which is most pairs on a grid.
  if (box_overlap_area(bg::return_envelope<Box>(a), bg::return_envelope<Box>(b)) <=
      kOverlapAreaEpsilon) {
    return 0.0;
  }
  bg::model::multi_polygon<Polygon> common;
  bg::intersection(a, b, common);
  return bg::area(common);
}

bool footprints_overlap(const Polygon& a, const Polygon& b) {
  return footprint_overlap_area(a, b) > kOverlapAreaEpsilon;
}

std::vector<std::vector<EntityIndex>> compute_conflict_sets(
    std::span<const Polygon* const> footprints) {
  using Entry = std::pair<Box, EntityIndex>;
  std::vector<Entry> entries;
  entries.reserve(footprints.size());
  for (std::size_t i = 0; i < footprints.size(); ++i) {
    entries.emplace_back(bg::return_envelope<Box>(*footprints[i]),
                         static_cast<EntityIndex>(i));
  }
  // Constructing from a range uses the packing algorithm: a balanced tree in one pass.
  const bgi::rtree<Entry, bgi::rstar<16>> tree(entries.begin(), entries.end());

  std::vector<std::vector<EntityIndex>> conflicts(footprints.size());
  std::vector<Entry> candidates;
  for (const auto& [box, e] : entries) {
    candidates.clear();
    tree.query(bgi::intersects(box), std::back_inserter(candidates));
    for (const auto& [candidate_box, f] : candidates) {
      // Each unordered pair is tested once, from its lower index.
      if (f <= e || box_overlap_area(box, candidate_box) <= kOverlapAreaEpsilon) continue;
      if (footprints_overlap(*footprints[e], *footprints[f])) {
        conflicts[e].push_back(f);
        conflicts[f].push_back(e);
      }
    }
  }
  for (auto& set : conflicts) std::sort(set.begin(), set.end());
  return conflicts;
}

}  // namespace drover::topology

#pragma GCC diagnostic pop
