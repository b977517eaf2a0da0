// TopologyBuilder: validation with diagnostics, generated footprints, moves, conflict sets.

#include "drover/topology/topology_builder.hpp"

#include <algorithm>
#include <random>

#include <gtest/gtest.h>

#include "drover/topology/conflicts.hpp"
#include "drover/topology/footprints.hpp"

namespace drover::topology {
namespace {

namespace bg = boost::geometry;

VertexSpec vertex(std::string id, double x, double y) {
  VertexSpec spec;
  spec.id = std::move(id);
  spec.x = x;
  spec.y = y;
  return spec;
}

EdgeSpec edge(std::string id, std::string from, std::string to, bool bidirectional = false) {
  EdgeSpec spec;
  spec.id = std::move(id);
  spec.from = std::move(from);
  spec.to = std::move(to);
  spec.bidirectional = bidirectional;
  return spec;
}

Polygon ring(std::initializer_list<Point> corners) {
  Polygon polygon;
  for (const auto& corner : corners) bg::append(polygon.outer(), corner);
  return polygon;
}

bool in_conflict(const Topology& topology, std::string_view a, std::string_view b) {
  const auto conflicts = topology.conflicts(*topology.find(a));
  return std::find(conflicts.begin(), conflicts.end(), *topology.find(b)) != conflicts.end();
}

Topology build_ok(TopologyBuilder builder) {
  auto result = std::move(builder).build();
  if (!result) {
    for (const auto& d : result.error()) ADD_FAILURE() << d.where << ": " << d.what;
  }
  EXPECT_TRUE(result.has_value());
  return std::move(result).value();
}

Diagnostics build_errors(TopologyBuilder builder) {
  auto result = std::move(builder).build();
  EXPECT_FALSE(result.has_value()) << "the builder accepted invalid input";
  if (result) return {};
  return std::move(result).error();
}

bool has_diagnostic(const Diagnostics& diagnostics, std::string_view where,
                    std::string_view what_part) {
  return std::any_of(diagnostics.begin(), diagnostics.end(), [&](const Diagnostic& d) {
    return d.where == where && d.what.find(what_part) != std::string::npos;
  });
}

std::string dump(const Diagnostics& diagnostics) {
  std::string text;
  for (const auto& d : diagnostics) text += d.where + ": " + d.what + "\n";
  return text;
}

TEST(TopologyBuilder, CrossingEdgesWithoutSharedVertexConflict) {
  TopologyBuilder builder("cross");
  builder.add_vertex(vertex("w", 0, 0));
  builder.add_vertex(vertex("e", 10, 0));
  builder.add_vertex(vertex("s", 5, -5));
  builder.add_vertex(vertex("n", 5, 5));
  builder.add_edge(edge("we", "w", "e"));
  builder.add_edge(edge("sn", "s", "n"));
  const Topology topology = build_ok(std::move(builder));

  EXPECT_TRUE(in_conflict(topology, "we", "sn"));
  EXPECT_TRUE(in_conflict(topology, "sn", "we"));
  // Generated edge footprints leave out the end vertices' footprints: they only touch.
  EXPECT_FALSE(in_conflict(topology, "we", "w"));
  EXPECT_FALSE(in_conflict(topology, "we", "e"));
  EXPECT_EQ(topology.conflict_pair_count(), 1u);
}

TEST(TopologyBuilder, VertexBesideAnEdgeThatPassesTooCloseConflicts) {
  TopologyBuilder builder("beside");
  builder.add_vertex(vertex("a", 0, 0));
  builder.add_vertex(vertex("b", 10, 0));
  builder.add_vertex(vertex("near", 5, 0.8));  // square reaches down to y = 0.3 < 0.5
  builder.add_vertex(vertex("far", 3, 2.0));
  builder.add_edge(edge("ab", "a", "b", true));
  const Topology topology = build_ok(std::move(builder));

  EXPECT_TRUE(in_conflict(topology, "near", "ab"));
  EXPECT_TRUE(in_conflict(topology, "ab", "near"));
  EXPECT_FALSE(in_conflict(topology, "far", "ab"));
}

TEST(TopologyBuilder, TouchingFootprintsDoNotConflict) {
  TopologyBuilder builder("touch");
  builder.add_vertex(vertex("a", 0, 0));
  builder.add_vertex(vertex("b", 10, 0));
  builder.add_vertex(vertex("touching", 5, 1.0));   // square [4.5,5.5]x[0.5,1.5]
  builder.add_vertex(vertex("corner", 11.0, 1.0));  // touches b's square at one corner
  builder.add_vertex(vertex("c", 20, 0));
  builder.add_edge(edge("ab", "a", "b"));
  builder.add_edge(edge("bc", "b", "c"));  // continues ab in a straight line
  const Topology topology = build_ok(std::move(builder));

  EXPECT_FALSE(in_conflict(topology, "touching", "ab"));
  EXPECT_FALSE(in_conflict(topology, "corner", "b"));
  EXPECT_FALSE(in_conflict(topology, "ab", "bc"));
  EXPECT_EQ(topology.conflict_pair_count(), 0u);
}

TEST(TopologyBuilder, GivenFootprintOrientationDoesNotMatter) {
  for (const bool clockwise : {true, false}) {
    TopologyBuilder builder("orientation");
    auto a = vertex("a", 0, 0);
    a.footprint = clockwise ? ring({{-1, -1}, {-1, 1}, {1, 1}, {1, -1}})
                            : ring({{-1, -1}, {1, -1}, {1, 1}, {-1, 1}});
    builder.add_vertex(std::move(a));
    builder.add_vertex(vertex("b", 1.2, 0));  // its square [0.7,1.7] overlaps a's
    const Topology topology = build_ok(std::move(builder));
    EXPECT_TRUE(in_conflict(topology, "a", "b")) << (clockwise ? "clockwise" : "ccw");
    EXPECT_FALSE(topology.vertex(0).footprint_generated);
    EXPECT_TRUE(topology.vertex(1).footprint_generated);
    EXPECT_NEAR(bg::area(topology.vertex(0).footprint), 4.0, 1e-12);
  }
}

TEST(TopologyBuilder, MovesFollowEdgeDirection) {
  TopologyBuilder builder("moves");
  builder.add_vertex(vertex("a", 0, 0));
  builder.add_vertex(vertex("b", 3, 4));
  builder.add_vertex(vertex("c", 6, 0));
  builder.add_edge(edge("ab", "a", "b"));        // one way
  builder.add_edge(edge("bc", "b", "c", true));  // both ways
  const Topology topology = build_ok(std::move(builder));

  const EntityIndex a = *topology.find("a");
  const EntityIndex b = *topology.find("b");
  const EntityIndex c = *topology.find("c");
  const EntityIndex ab = *topology.find("ab");
  const EntityIndex bc = *topology.find("bc");
  ASSERT_EQ(topology.moves_from(a).size(), 1u);
  EXPECT_EQ(topology.moves_from(a)[0].edge, ab);
  EXPECT_EQ(topology.moves_from(a)[0].to, b);
  ASSERT_EQ(topology.moves_from(b).size(), 1u);  // not back along the one-way edge
  EXPECT_EQ(topology.moves_from(b)[0].to, c);
  ASSERT_EQ(topology.moves_from(c).size(), 1u);
  EXPECT_EQ(topology.moves_from(c)[0].edge, bc);
  EXPECT_EQ(topology.moves_from(c)[0].to, b);
  // Length from the vertex distance when absent.
  EXPECT_DOUBLE_EQ(topology.edge(ab).length, 5.0);
  EXPECT_TRUE(topology.is_edge(ab));
  EXPECT_EQ(topology.id(bc), "bc");
}

TEST(TopologyBuilder, DiscFootprintsAreGeneratedWhenAsked) {
  FootprintOptions options;
  options.vertex_disc = true;
  options.disc_points = 12;
  options.vertex_radius = 1.0;
  TopologyBuilder builder("discs", options);
  builder.add_vertex(vertex("a", 0, 0));
  builder.add_vertex(vertex("b", 5, 0));
  builder.add_edge(edge("ab", "a", "b"));
  const Topology topology = build_ok(std::move(builder));
  const auto& disc = topology.vertex(0).footprint;
  EXPECT_EQ(disc.outer().size(), 13u);  // 12 corners plus the closing point
  EXPECT_TRUE(bg::is_valid(topology.edge(*topology.find("ab")).footprint));
  EXPECT_FALSE(in_conflict(topology, "ab", "a"));
}

// Ids travel as DDS keys: one of 256 bytes or more could not be published, and a NUL
// would cut it short on the wire, so that "left-1\0" and "left-1" became one entity.
TEST(TopologyBuilder, RefusesIdsThatCannotTravelAsDdsKeys) {
  TopologyBuilder builder("ids");
  auto longest = vertex(std::string(255, 'v'), 0, 0);
  longest.where = "vertices[0]";
  builder.add_vertex(longest);
  auto too_long = vertex(std::string(256, 'w'), 5, 0);
  too_long.where = "vertices[1]";
  builder.add_vertex(too_long);
  auto with_nul = vertex(std::string("left-1\0", 7), 10, 0);
  with_nul.where = "vertices[2]";
  builder.add_vertex(with_nul);
  auto with_tab = vertex("a\tb", 15, 0);
  with_tab.where = "vertices[3]";
  builder.add_vertex(with_tab);

  const Diagnostics diagnostics = build_errors(std::move(builder));
  const std::string all = dump(diagnostics);
  EXPECT_TRUE(has_diagnostic(diagnostics, "vertices[1].id", "is 256 bytes long, at most 255 are allowed")) << all;
  EXPECT_TRUE(has_diagnostic(diagnostics, "vertices[2].id", "contains the control character 0x00 at byte 6"))
      << all;
  EXPECT_TRUE(has_diagnostic(diagnostics, "vertices[3].id", "contains the control character 0x09 at byte 1"))
      << all;
  EXPECT_EQ(diagnostics.size(), 3u) << all;  // 255 bytes are fine
}

TEST(TopologyBuilder, ReportsEveryProblemWithWhereItIs) {
  TopologyBuilder builder("bad");
  auto a = vertex("a", 0, 0);
  a.where = "vertices[0]";
  builder.add_vertex(a);
  auto duplicate = vertex("a", 1, 1);
  duplicate.where = "vertices[1]";
  builder.add_vertex(duplicate);
  auto bow_tie = vertex("bow", 5, 5);
  bow_tie.where = "vertices[2]";
  bow_tie.footprint = ring({{0, 0}, {2, 2}, {2, 0}, {0, 2}});
  builder.add_vertex(bow_tie);
  builder.add_vertex(vertex("", 7, 7));  // no where: named by position

  auto unknown = edge("e0", "a", "nowhere");
  unknown.where = "edges[0]";
  builder.add_edge(unknown);
  auto zero_length = edge("e1", "a", "bow");
  zero_length.where = "edges[1]";
  zero_length.length = 0.0;
  builder.add_edge(zero_length);
  auto negative_speed = edge("e2", "bow", "a");
  negative_speed.where = "edges[2]";
  negative_speed.max_speed = -1.0;
  builder.add_edge(negative_speed);
  auto clash = edge("bow", "a", "bow");  // an edge id that a vertex already uses
  clash.where = "edges[3]";
  builder.add_edge(clash);
  auto loop = edge("e4", "a", "a");
  loop.where = "edges[4]";
  loop.restrictions.max_payload = -5.0;
  builder.add_edge(loop);

  const Diagnostics diagnostics = build_errors(std::move(builder));
  const std::string all = dump(diagnostics);
  EXPECT_TRUE(has_diagnostic(diagnostics, "vertices[1].id", "duplicate id 'a'")) << all;
  EXPECT_TRUE(has_diagnostic(diagnostics, "vertices[1].id", "vertices[0]")) << all;
  EXPECT_TRUE(has_diagnostic(diagnostics, "vertices[2].footprint", "intersects itself")) << all;
  EXPECT_TRUE(has_diagnostic(diagnostics, "vertices[3].id", "must not be empty")) << all;
  EXPECT_TRUE(has_diagnostic(diagnostics, "edges[0].to", "unknown vertex 'nowhere'")) << all;
  EXPECT_TRUE(has_diagnostic(diagnostics, "edges[1].length", "positive")) << all;
  EXPECT_TRUE(has_diagnostic(diagnostics, "edges[2].max_speed", "positive")) << all;
  EXPECT_TRUE(has_diagnostic(diagnostics, "edges[3].id", "duplicate id 'bow'")) << all;
  EXPECT_TRUE(has_diagnostic(diagnostics, "edges[4].to", "must differ")) << all;
  EXPECT_TRUE(has_diagnostic(diagnostics, "edges[4].restrictions.max_payload", "non-negative"))
      << all;
  EXPECT_EQ(diagnostics.size(), 9u) << all;
}

TEST(TopologyBuilder, RejectsNonFiniteNumbersAndBadOptions) {
  FootprintOptions options;
  options.vertex_radius = 0;
  options.disc_points = 2;
  TopologyBuilder builder("nan", options);
  builder.add_vertex(vertex("a", std::numeric_limits<double>::quiet_NaN(), 0));
  auto b = vertex("b", 1, std::numeric_limits<double>::infinity());
  b.restrictions.max_speed = 0.0;
  builder.add_vertex(b);
  auto ab = edge("ab", "a", "b");
  ab.length = std::numeric_limits<double>::infinity();
  builder.add_edge(ab);

  const Diagnostics diagnostics = build_errors(std::move(builder));
  const std::string all = dump(diagnostics);
  EXPECT_TRUE(has_diagnostic(diagnostics, "footprint_options.vertex_radius", "from 0.01 to 10000"))
      << all;
  EXPECT_TRUE(has_diagnostic(diagnostics, "footprint_options.disc_points", "between 3 and 256")) << all;
  EXPECT_TRUE(has_diagnostic(diagnostics, "vertices[0].x", "finite")) << all;
  EXPECT_TRUE(has_diagnostic(diagnostics, "vertices[1].y", "finite")) << all;
  EXPECT_TRUE(has_diagnostic(diagnostics, "vertices[1].restrictions.max_speed", "positive"))
      << all;
  EXPECT_TRUE(has_diagnostic(diagnostics, "edges[0].length", "finite")) << all;
}

// Far out, or with tiny generated footprints, doubles would round two vertices on one spot
// (or a few metres apart) to footprints that no longer overlap: they would silently stop
// conflicting. Such files are refused, naming the field.
TEST(TopologyBuilder, RefusesCoordinatesAndSizesWhereFootprintsLoseTheirArea) {
  FootprintOptions tiny;
  tiny.vertex_radius = 1e-9;
  tiny.edge_half_width = 1e19;
  TopologyBuilder builder("far", tiny);
  builder.add_vertex(vertex("a", 1e16, 0));
  builder.add_vertex(vertex("b", 0, -2e6));
  builder.add_vertex(vertex("c", 1e6, -1e6));  // on the limit: allowed
  auto ab = edge("ab", "a", "b");
  ab.length = 1e300;
  builder.add_edge(ab);
  auto bc = edge("bc", "b", "c");
  bc.footprint = axis_aligned_rectangle(0, -1e6, kMaxCornerCoordinate + 1, -1e6 + 1);
  builder.add_edge(bc);

  const Diagnostics diagnostics = build_errors(std::move(builder));
  const std::string all = dump(diagnostics);
  EXPECT_TRUE(has_diagnostic(diagnostics, "footprint_options.vertex_radius", "from 0.01 to 10000"))
      << all;
  EXPECT_TRUE(has_diagnostic(diagnostics, "footprint_options.edge_half_width", "from 0.01 to 10000"))
      << all;
  EXPECT_TRUE(has_diagnostic(diagnostics, "vertices[0].x", "within 1000000 m")) << all;
  EXPECT_TRUE(has_diagnostic(diagnostics, "vertices[1].y", "within 1000000 m")) << all;
  EXPECT_TRUE(has_diagnostic(diagnostics, "edges[0].length", "at most 10000000")) << all;
  EXPECT_TRUE(has_diagnostic(diagnostics, "edges[1].footprint", "more than 1010000 m")) << all;
  EXPECT_EQ(diagnostics.size(), 6u) << all;
}

TEST(TopologyBuilder, TheSmallestGeneratedFootprintsStillConflictOnOneSpot) {
  for (const bool disc : {false, true}) {
    FootprintOptions options;
    options.vertex_radius = kMinFootprintOption;
    options.edge_half_width = kMinFootprintOption;
    options.vertex_disc = disc;
    options.disc_points = 3;
    TopologyBuilder builder("spot", options);
    builder.add_vertex(vertex("a", kMaxCoordinate, -kMaxCoordinate));
    builder.add_vertex(vertex("b", kMaxCoordinate, -kMaxCoordinate));
    auto built = std::move(builder).build();
    ASSERT_TRUE(built.has_value()) << dump(built.error());
    EXPECT_EQ(built->conflict_pair_count(), 1u) << "disc " << disc;
  }
}

// Agents pass a topology on with its generated footprints written out (a routing agent
// rebuilds it from the topology agents' descriptions): those at the edge of the coordinates
// must read back as given footprints.
TEST(TopologyBuilder, GeneratedFootprintsAtTheLimitReadBackAsGiven) {
  FootprintOptions options;
  options.vertex_radius = kMaxFootprintOption;
  TopologyBuilder generated("edge-of-map", options);
  generated.add_vertex(vertex("a", kMaxCoordinate, -kMaxCoordinate));
  auto first = std::move(generated).build();
  ASSERT_TRUE(first.has_value()) << dump(first.error());

  TopologyBuilder given("edge-of-map");
  auto a = vertex("a", kMaxCoordinate, -kMaxCoordinate);
  a.footprint = first->vertex(0).footprint;
  given.add_vertex(a);
  auto second = std::move(given).build();
  EXPECT_TRUE(second.has_value()) << dump(second.error());
}

TEST(TopologyBuilder, EdgeBetweenVerticesTooCloseForAFootprintIsReported) {
  TopologyBuilder builder("close");
  builder.add_vertex(vertex("a", 0, 0));
  builder.add_vertex(vertex("b", 0.8, 0));  // the squares cover the whole segment
  builder.add_vertex(vertex("c", 0, 0));    // same position as a
  builder.add_edge(edge("ab", "a", "b"));
  builder.add_edge(edge("ac", "a", "c"));
  const Diagnostics diagnostics = build_errors(std::move(builder));
  const std::string all = dump(diagnostics);
  EXPECT_TRUE(has_diagnostic(diagnostics, "edges[0].footprint", "cannot be generated")) << all;
  EXPECT_TRUE(has_diagnostic(diagnostics, "edges[1].length", "same position")) << all;
}

// The R-tree search must find exactly the pairs an exhaustive comparison finds.
TEST(TopologyBuilder, ConflictSetsMatchExhaustiveComparison) {
  // Vertices on a jittered 9x9 grid (spacing 4 m, jitter up to 1 m, so no two are closer
  // than 2 m and every edge keeps a footprint), joined by random edges that cross a lot.
  std::mt19937 random(20240611);
  std::uniform_real_distribution<double> jitter(-1.0, 1.0);
  TopologyBuilder builder("random");
  constexpr int kSide = 9;
  for (int i = 0; i < kSide * kSide; ++i) {
    builder.add_vertex(vertex("v" + std::to_string(i), 4.0 * (i % kSide) + jitter(random),
                              4.0 * (i / kSide) + jitter(random)));
  }
  std::uniform_int_distribution<int> pick(0, kSide * kSide - 1);
  for (int i = 0; i < 120;) {
    const int from = pick(random);
    const int to = pick(random);
    if (from == to) continue;
    builder.add_edge(edge("e" + std::to_string(i++), "v" + std::to_string(from),
                          "v" + std::to_string(to), from % 2 == 0));
  }
  auto result = std::move(builder).build();
  ASSERT_TRUE(result.has_value()) << dump(result.error());
  const Topology& topology = *result;

  std::size_t pairs_found = 0;
  for (EntityIndex e = 0; e < topology.entity_count(); ++e) {
    std::vector<EntityIndex> expected;
    for (EntityIndex f = 0; f < topology.entity_count(); ++f) {
      if (f != e && footprints_overlap(topology.footprint(e), topology.footprint(f))) {
        expected.push_back(f);
      }
    }
    const auto actual = topology.conflicts(e);
    EXPECT_EQ(std::vector<EntityIndex>(actual.begin(), actual.end()), expected) << "entity " << e;
    pairs_found += expected.size();
  }
  EXPECT_EQ(topology.conflict_pair_count(), pairs_found / 2);
  EXPECT_GT(topology.conflict_pair_count(), 0u);
}

}  // namespace
}  // namespace drover::topology
