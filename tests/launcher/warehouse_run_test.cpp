// The short warehouse run (domain 98): launch/warehouse.json — two topology agents, a
// routing agent, 8 simulated vehicles with their logical agents, the load generator — runs
// for a fixed simulated time at a high time factor. From its trace alone (no Drover code):
// at least 20 orders finished, and no two vehicles' reported footprints overlap at any
// traced instant.

// GCC 12 reports false maybe-uninitialized warnings inside Boost.Geometry's set operations
// (as in ran/src/motion_area.cpp).
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"

#include <algorithm>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <boost/geometry.hpp>
#include <nlohmann/json.hpp>

#include "drover/topology/conflicts.hpp"
#include "tests/launcher/launch_test_support.hpp"

namespace drover::test {
namespace {

namespace bg = boost::geometry;
using topology::Point;
using topology::Polygon;

using namespace std::chrono_literals;

/// Simulated seconds the run lasts and how much faster than real time it runs: 8 vehicles
/// do a load-and-unload order in about 60-180 simulated seconds each, with waits for one
/// another; 1500 s leaves a wide margin over the 20 orders the test asks for.
constexpr const char* kDurationS = "1500";
constexpr const char* kTimeFactor = "8";

struct Status {
  std::int64_t t = 0;
  std::string vehicle;
  Polygon footprint;
};

Polygon polygon_of(const nlohmann::json& ring) {
  Polygon polygon;
  for (const auto& point : ring) bg::append(polygon.outer(), Point(point[0].get<double>(), point[1].get<double>()));
  bg::correct(polygon);  // orientation and closure as Boost.Geometry wants them
  return polygon;
}

std::string wkt(const Polygon& polygon) {
  std::ostringstream text;
  text << bg::wkt(polygon);
  return text.str();
}

struct Trace {
  std::vector<Status> statuses;
  std::set<std::string> finished_orders;
  std::set<std::string> failed_orders;
};

Trace read_trace(const std::filesystem::path& path) {
  Trace trace;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    const auto entry = nlohmann::json::parse(line);
    const auto type = entry.at("type").get<std::string>();
    if (type == "ran_status") {
      trace.statuses.push_back({entry.at("t").get<std::int64_t>(), entry.at("vehicle").get<std::string>(),
                                polygon_of(entry.at("footprint"))});
    } else if (type == "order") {
      const auto state = entry.at("state").get<std::string>();
      if (state == "finished") trace.finished_orders.insert(entry.at("order").get<std::string>());
      if (state == "failed") trace.failed_orders.insert(entry.at("order").get<std::string>());
    }
  }
  return trace;
}

/// Replays the statuses in time order; each vehicle's footprint holds from its status
/// until its next one. \return a description of every overlap found (at most 10).
std::vector<std::string> overlaps(std::vector<Status> statuses) {
  std::stable_sort(statuses.begin(), statuses.end(), [](const Status& a, const Status& b) { return a.t < b.t; });
  std::map<std::string, const Status*> latest;
  std::vector<std::string> found;
  for (const auto& status : statuses) {
    latest[status.vehicle] = &status;
    for (const auto& [vehicle, other] : latest) {
      if (vehicle == status.vehicle) continue;
      const double area = topology::footprint_overlap_area(status.footprint, other->footprint);
      if (area > topology::kOverlapAreaEpsilon && found.size() < 10) {
        found.push_back(status.vehicle + " at t=" + std::to_string(status.t) + " overlaps " + vehicle +
                        " (its status of t=" + std::to_string(other->t) + ") by " + std::to_string(area) + " m2: " +
                        wkt(status.footprint) + " / " + wkt(other->footprint));
      }
    }
  }
  return found;
}

TEST(WarehouseRun, OverlapCheckSeesOverlapsAndAllowsTouching) {
  const auto square = [](double x, double y) {
    return polygon_of(nlohmann::json::parse("[[" + std::to_string(x) + "," + std::to_string(y) + "],[" +
                                            std::to_string(x + 1) + "," + std::to_string(y) + "],[" +
                                            std::to_string(x + 1) + "," + std::to_string(y + 1) + "],[" +
                                            std::to_string(x) + "," + std::to_string(y + 1) + "]]"));
  };
  // B moves next to A (touching), then A moves away and B follows into its old place.
  EXPECT_TRUE(overlaps({{0, "A", square(0, 0)}, {1, "B", square(1, 0)}, {2, "A", square(5, 0)},
                        {3, "B", square(0.5, 0)}}).empty());
  // B moves into A's square while A's latest status still has it there.
  EXPECT_EQ(overlaps({{0, "A", square(0, 0)}, {1, "B", square(3, 0)}, {3, "B", square(0.5, 0)},
                      {4, "A", square(5, 0)}}).size(), 1u);
  // Out-of-order arrival is replayed in time order: A had left before B arrived.
  EXPECT_TRUE(overlaps({{0, "A", square(0, 0)}, {3, "B", square(0.5, 0)}, {2, "A", square(5, 0)}}).empty());
}

TEST(WarehouseRun, EightVehiclesFinishTwentyOrdersWithoutOverlappingFootprints) {
  const auto dir = scratch_dir("warehouse_run");
  const auto trace_file = dir / "trace.jsonl";
  auto launcher = ChildProcess::spawn(binary_path("drover"),
                                      {"launch", (source_dir() / "launch" / "warehouse.json").string(), "--domain",
                                       "98", "--time-factor", kTimeFactor, "--duration", kDurationS, "--trace",
                                       trace_file.string()},
                                      (dir / "out.txt").string(), (dir / "err.txt").string());
  ASSERT_TRUE(launcher.has_value());
  const auto status = launcher->wait_exit(600s);
  ASSERT_TRUE(status.has_value()) << "the launcher did not end after --duration";
  const auto out = read_file((dir / "out.txt").string());
  EXPECT_TRUE(status->exited && status->code == 0) << out << read_file((dir / "err.txt").string());

  const auto trace = read_trace(trace_file);
  std::set<std::string> vehicles;
  for (const auto& entry : trace.statuses) vehicles.insert(entry.vehicle);
  EXPECT_GE(vehicles.size(), 8u);
  EXPECT_GE(trace.finished_orders.size(), 20u) << out;
  const auto found = overlaps(trace.statuses);
  EXPECT_TRUE(found.empty()) << found.size() << " overlaps, first: " << found.front();
  RecordProperty("finished_orders", static_cast<int>(trace.finished_orders.size()));
  RecordProperty("failed_orders", static_cast<int>(trace.failed_orders.size()));
  RecordProperty("statuses", static_cast<int>(trace.statuses.size()));
  if (!HasFailure()) std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace drover::test
