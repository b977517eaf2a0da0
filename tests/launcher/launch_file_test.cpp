// The launch file parser: a good file becomes the agents' command lines; every kind of bad
// file is refused with its problem named by field, and nothing is returned to start.

#include <cstdlib>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "drover/launcher/launch_file.hpp"

namespace drover::launcher {
namespace {

std::filesystem::path source_dir() {
  const char* dir = std::getenv("DROVER_SOURCE_DIR");
  return dir != nullptr ? dir : DROVER_TEST_SOURCE_DIR;
}

/// A launch file "in" launch/, so that "topologies/loop.json" resolves.
std::filesystem::path launch_path() { return source_dir() / "launch" / "test.json"; }

Result<LaunchFile, LaunchProblems> parse(const std::string& text) {
  return parse_launch_file(text, launch_path(), "/state");
}

/// The problems of a file that must be refused, as "where: what" lines.
std::string problems_of(const std::string& text) {
  auto parsed = parse(text);
  EXPECT_FALSE(parsed.has_value()) << "accepted a bad file:\n" << text;
  if (parsed) return {};
  std::string all;
  for (const auto& problem : parsed.error()) all += problem.where + ": " + problem.what + "\n";
  return all;
}

/// A loop launch file with `agents` as its agent list.
std::string loop_file(const std::string& agents) {
  return R"({"domain": 226, "time_factor": 5, "epoch": 1000, "topology": "topologies/loop.json",
            "vehicle_profiles": {"slow": {"max_speed": 0.5, "load_duration": 2, "length": 0.8}}, "agents": [)" +
         agents + "]}";
}

TEST(LaunchFile, GoodFileBecomesCommandLines) {
  auto parsed = parse(loop_file(R"(
      {"kind": "topology", "db": "loop.db", "restart": "on-failure", "max_restarts": 2},
      {"kind": "routing", "id": "routing-1"},
      {"kind": "ran-sim", "vehicle": "V1", "at": "south-west", "profile": "slow", "loaded": true},
      {"kind": "logical", "vehicle": "V1", "profile": "slow", "lookahead": 3, "db": "V1-orders.db"},
      {"kind": "load-generator", "seed": 7, "stations": ["station", "parking"]})"));
  ASSERT_TRUE(parsed.has_value()) << parsed.error().front().where << ": " << parsed.error().front().what;
  EXPECT_EQ(parsed->domain_id, 226u);
  EXPECT_DOUBLE_EQ(parsed->time_factor, 5.0);
  EXPECT_EQ(parsed->epoch_ns, 1000);
  const auto topology = (source_dir() / "launch" / "topologies" / "loop.json").lexically_normal().string();
  EXPECT_EQ(parsed->topology_file.string(), topology);
  ASSERT_EQ(parsed->agents.size(), 5u);

  const auto& store = parsed->agents[0];
  EXPECT_EQ(store.id, "topology");
  EXPECT_EQ(store.restart, RestartPolicy::on_failure);
  EXPECT_EQ(store.max_restarts, 2);
  EXPECT_EQ(store.options, (std::vector<std::string>{"--id", "topology", "--topology", topology, "--db", "/state/loop.db"}));

  EXPECT_EQ(parsed->agents[1].options, (std::vector<std::string>{"--id", "routing-1"}));

  // The entry's fields in key order (a profile's fields where "profile" comes).
  const auto& ran = parsed->agents[2];
  EXPECT_EQ(ran.id, "ran-V1");
  EXPECT_EQ(ran.vehicle, "V1");
  EXPECT_EQ(ran.options, (std::vector<std::string>{"--agent-id", "ran-V1", "--id", "V1", "--topology", topology,
                                                   "--at", "south-west", "--loaded", "--load-duration", "2",
                                                   "--max-speed", "0.5"}));
  const auto& logical = parsed->agents[3];
  EXPECT_EQ(logical.id, "V1");
  EXPECT_EQ(logical.options, (std::vector<std::string>{"--id", "V1", "--topology", topology, "--db",
                                                       "/state/V1-orders.db", "--lookahead", "3", "--vehicle",
                                                       "/state/V1.vehicle.json"}));
  // The logical agent plans with the profile's speeds: its file is written before it starts.
  ASSERT_EQ(logical.files.size(), 1u);
  EXPECT_EQ(logical.files[0].first, "/state/V1.vehicle.json");
  EXPECT_EQ(logical.files[0].second, "{\"id\":\"V1\",\"length\":0.8,\"max_speed\":0.5}\n");
  EXPECT_EQ(parsed->agents[4].options,
            (std::vector<std::string>{"--id", "load-generator", "--topology", topology, "--seed", "7", "--station",
                                      "station", "--station", "parking"}));
  EXPECT_EQ(subcommand(AgentKind::topology), "topology-agent");
  EXPECT_EQ(subcommand(AgentKind::ran_sim), "ran-sim");
}

TEST(LaunchFile, NotJsonOrNotAnObject) {
  EXPECT_NE(problems_of("{\"agents\": [").find("malformed JSON"), std::string::npos);
  // A number beyond double range is bad input with its place, not an internal error.
  EXPECT_NE(problems_of("{\"name\": \"x\",\n \"domain\": 1e400}")
                .find("line 2, column 16: malformed JSON: number overflow parsing '1e400'"),
            std::string::npos)
      << problems_of("{\"name\": \"x\",\n \"domain\": 1e400}");
  EXPECT_NE(problems_of("[1, 2]").find("must be a JSON object"), std::string::npos);
}

/// A good loop launch file in which, when `twice`, three keys are given a second time:
/// in the header, in a profile and in an agent entry.
std::string file_with_keys_given_twice(bool twice) {
  const std::string header = twice ? R"("time_factor": 10, )" : "";
  const std::string profile = twice ? R"(, "max_speed": 5)" : "";
  const std::string entry = twice ? R"(, "at": "south")" : "";
  return R"({"domain": 226, "time_factor": 1, "epoch": 1000, "topology": "topologies/loop.json", )" + header +
         R"("vehicle_profiles": {"slow": {"max_speed": 0.5, "length": 0.8)" + profile + R"(}},
            "agents": [{"kind": "topology"}, {"kind": "routing"},
                       {"kind": "ran-sim", "vehicle": "V1", "at": "south-west", "profile": "slow")" +
         entry + "}]}";
}

// JSON allows a key twice in one object and the parser keeps the last value: a pasted or
// edited line must not silently win over the one above it.
TEST(LaunchFile, KeysGivenTwiceAreRefusedByTheirPath) {
  auto once = parse(file_with_keys_given_twice(false));
  ASSERT_TRUE(once.has_value()) << once.error().front().where << ": " << once.error().front().what;
  const auto text = problems_of(file_with_keys_given_twice(true));
  EXPECT_EQ(text,
            "time_factor: key given twice in the same object\n"
            "vehicle_profiles.slow.max_speed: key given twice in the same object\n"
            "agents[2].at: key given twice in the same object\n");
}

// The parser takes a NUL byte for the end of the text: what follows one must not vanish.
TEST(LaunchFile, NulByteIsRefusedWithLineAndColumn) {
  const std::string good = loop_file(R"({"kind": "topology"}, {"kind": "routing"})");
  ASSERT_TRUE(parse(good).has_value());
  EXPECT_EQ(problems_of(good + "\n" + '\0' + R"({"agents": []})"),
            "line 3, column 1: malformed JSON: NUL byte (a JSON text cannot contain one)\n");
}

TEST(LaunchFile, MissingOrBadHeaderFields) {
  const auto missing = problems_of(R"({"agents": [{"kind": "routing"}]})");
  EXPECT_NE(missing.find("topology: missing"), std::string::npos) << missing;
  const auto bad = problems_of(R"({"domain": 233, "time_factor": -1, "epoch": "soon", "topology": "topologies/loop.json",
                                   "agents": [{"kind": "routing"}], "colour": "red"})");
  EXPECT_NE(bad.find("domain: must be an integer DDS domain id in 0..232"), std::string::npos) << bad;
  EXPECT_NE(bad.find("time_factor: must be a number > 0 and at most 1000"), std::string::npos) << bad;
  EXPECT_NE(bad.find("epoch: must be \"now\" or an integer"), std::string::npos) << bad;
  EXPECT_NE(bad.find("colour: unknown field"), std::string::npos) << bad;
  // Beyond what a shared clock runs at or starts from (it would overflow), and beyond int64.
  for (const char* epoch : {"-1", "4611686018427387904", "18446744073709551615", "1e30", "1.5"}) {
    const auto huge = problems_of(std::string(R"({"time_factor": 1001, "epoch": )") + epoch +
                                  R"(, "topology": "topologies/loop.json", "agents": [{"kind": "routing"}]})");
    EXPECT_NE(huge.find("time_factor: must be a number > 0 and at most 1000"), std::string::npos) << huge;
    EXPECT_NE(huge.find("epoch: must be \"now\" or an integer from 0 to 4611686018427387903"), std::string::npos)
        << epoch << ": " << huge;
  }
  const auto no_agents = problems_of(R"({"topology": "topologies/loop.json", "agents": []})");
  EXPECT_NE(no_agents.find("agents: must be a non-empty array"), std::string::npos) << no_agents;
}

TEST(LaunchFile, TopologyThatDoesNotLoad) {
  const auto absent = problems_of(R"({"topology": "topologies/absent.json", "agents": [{"kind": "routing"}]})");
  EXPECT_NE(absent.find("topology: "), std::string::npos) << absent;
  EXPECT_NE(absent.find("absent.json"), std::string::npos) << absent;
}

TEST(LaunchFile, UnknownKindAndFieldsAreNamed) {
  const auto text = problems_of(loop_file(R"({"kind": "teleporter"},
      {"kind": "routing", "partition": "west"},
      {"kind": "topology", "restart": "sometimes", "max_restarts": -1})"));
  EXPECT_NE(text.find("agents[0].kind: unknown kind 'teleporter' (expected one of topology, ran-sim"),
            std::string::npos) << text;
  EXPECT_NE(text.find("agents[1].partition: unknown field for kind 'routing'"), std::string::npos) << text;
  EXPECT_NE(text.find("agents[2].restart: must be \"never\" or \"on-failure\""), std::string::npos) << text;
  EXPECT_NE(text.find("agents[2].max_restarts: must be an integer in 0..1000"), std::string::npos) << text;
}

// Values the logical agent would refuse are refused here, so that nothing is started.
TEST(LaunchFile, LogicalAgentFieldsOutOfRange) {
  const auto text = problems_of(loop_file(R"({"kind": "topology"}, {"kind": "routing"},
      {"kind": "ran-sim", "vehicle": "V1", "at": "south-west"},
      {"kind": "logical", "vehicle": "V1", "lookahead": 0, "charge_below": 1.5, "charge_to": -0.1})"));
  EXPECT_NE(text.find("agents[3].lookahead: must be an integer from 1 to 1000"), std::string::npos) << text;
  EXPECT_NE(text.find("agents[3].charge_below: must be a number from 0 to 1"), std::string::npos) << text;
  EXPECT_NE(text.find("agents[3].charge_to: must be a number > 0 and at most 1"), std::string::npos) << text;
}

// Every numeric field has the range of the option it becomes: a value beyond it would start
// the fleet and then stop the agent that refuses it.
TEST(LaunchFile, NumbersBeyondWhatTheirAgentTakesAreRefused) {
  const auto text = problems_of(loop_file(R"({"kind": "topology"}, {"kind": "routing"},
      {"kind": "ran-sim", "vehicle": "V1", "at": "south-west", "heading": 1001, "status_period_ms": 0},
      {"kind": "logical", "vehicle": "V1", "lookahead": 1001, "park_after": 2e9, "route_limit": -1,
       "delay_threshold": 1e10, "error_limit": 0},
      {"kind": "load-generator", "seed": 18446744073709551615, "max_orders": -1})"));
  for (const char* expected : {"agents[2].heading: must be a number from -1000 to 1000",
                               "agents[2].status_period_ms: must be an integer from 1 to 60000",
                               "agents[3].lookahead: must be an integer from 1 to 1000",
                               "agents[3].park_after: must be a number from -1000000000 to 1000000000",
                               "agents[3].route_limit: must be a number from 0 to 1000000000",
                               "agents[3].delay_threshold: must be a number > 0 and at most 1000000000",
                               "agents[3].error_limit: must be a number > 0 and at most 1000000000",
                               "agents[4].seed: must be an integer from 0 to 9007199254740991",
                               "agents[4].max_orders: must be an integer from 0 to 9007199254740991"}) {
    EXPECT_NE(text.find(expected), std::string::npos) << expected << "\n" << text;
  }
}

// The logical agent refuses to charge to 0 (it would never charge); refused before anything starts.
TEST(LaunchFile, ChargingToZeroIsRefused) {
  const auto text = problems_of(loop_file(R"({"kind": "topology"}, {"kind": "routing"},
      {"kind": "ran-sim", "vehicle": "V1", "at": "south-west"},
      {"kind": "logical", "vehicle": "V1", "charge_below": 0, "charge_to": 0})"));
  EXPECT_NE(text.find("agents[3].charge_to: must be a number > 0 and at most 1"), std::string::npos) << text;
  EXPECT_EQ(text.find("charge_below"), std::string::npos) << "0 means never: " << text;
}

// A charge that ends at or under the threshold that starts one would be followed by another
// for ever: refused, against the default of a field left out too.
TEST(LaunchFile, ChargingToNoMoreThanTheThresholdIsRefused) {
  const auto text = problems_of(loop_file(R"({"kind": "topology"}, {"kind": "routing"},
      {"kind": "ran-sim", "vehicle": "V1", "at": "south-west"},
      {"kind": "ran-sim", "vehicle": "V2", "at": "north-east"},
      {"kind": "logical", "vehicle": "V1", "charge_below": 0.95},
      {"kind": "logical", "vehicle": "V2", "charge_below": 0.5, "charge_to": 0.5})"));
  EXPECT_NE(text.find("agents[4].charge_to: the state of charge a charge aims at (0.9) must be above the one "
                      "under which the vehicle charges (0.95)"),
            std::string::npos) << text;
  EXPECT_NE(text.find("agents[5].charge_to: the state of charge a charge aims at (0.5) must be above"),
            std::string::npos) << text;
}

TEST(LaunchFile, VerticesPartitionsAndProfilesMustExist) {
  const auto text = problems_of(loop_file(R"({"kind": "topology", "partition": "north"},
      {"kind": "ran-sim", "vehicle": "V1", "at": "nowhere", "profile": "fast"},
      {"kind": "ran-sim", "vehicle": "V2"},
      {"kind": "load-generator", "stations": ["station", "south-west->south"]})"));
  EXPECT_NE(text.find("agents[0].partition: the topology has no partition 'north'"), std::string::npos) << text;
  EXPECT_NE(text.find("agents[1].at: 'nowhere' is not a vertex of"), std::string::npos) << text;
  EXPECT_NE(text.find("agents[1].profile: names no entry of vehicle_profiles"), std::string::npos) << text;
  EXPECT_NE(text.find("agents[2].at: missing"), std::string::npos) << text;
  EXPECT_NE(text.find("agents[3].stations[1]: 'south-west->south' is not a vertex"), std::string::npos) << text;
}

// Two topology agents owning the same entities: vehicles could be booked onto one entity
// through either.
TEST(LaunchFile, TopologyAgentsThatWouldOwnTheSameEntitiesAreRefused) {
  const auto twice = problems_of(loop_file(R"({"kind": "topology"}, {"kind": "topology", "id": "again"})"));
  EXPECT_NE(twice.find("agents[1]: serves the whole topology, as agents[0] does already"), std::string::npos)
      << twice;
  const auto beside = problems_of(R"({"topology": "topologies/warehouse.json", "agents": [
      {"kind": "topology"}, {"kind": "topology", "partition": "west"}]})");
  EXPECT_NE(beside.find("agents[1].partition: partition 'west' is served by agents[0] already (it serves the whole "
                        "topology)"),
            std::string::npos)
      << beside;
}

// A simulator driving slower than its logical agent plans falls behind every window.
TEST(LaunchFile, AVehicleSimulatedAndPlannedWithDifferentProfilesIsRefused) {
  const auto text = problems_of(loop_file(R"({"kind": "topology"}, {"kind": "routing"},
      {"kind": "ran-sim", "vehicle": "V1", "at": "south-west", "profile": "slow"},
      {"kind": "logical", "vehicle": "V1"})"));
  EXPECT_NE(text.find("agents[3].profile: vehicle 'V1' is planned with no profile but simulated with profile 'slow' "
                      "(agents[2]): name the same profile in both"),
            std::string::npos)
      << text;
}

// What the agents would refuse at start: refused in the file, before anything starts.
TEST(LaunchFile, VehicleIdsAndLogLevelsTheAgentsWouldRefuseAreRefused) {
  const auto text = problems_of(loop_file(R"({"kind": "topology", "log_level": "loud"},
      {"kind": "ran-sim", "id": "sim1", "vehicle": "V\u00011", "at": "south-west"},
      {"kind": "routing", "log_level": "warning"})"));
  EXPECT_NE(text.find("agents[0].log_level: must be one of \"trace\", \"debug\", \"info\", \"warn\", \"error\", "
                      "\"off\""),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("agents[1].vehicle: 'V\\x011' contains the control character 0x01 at byte 1"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("agents[2].log_level: must be one of"), std::string::npos) << text;
}

TEST(LaunchFile, BadProfileFields) {
  const auto text = problems_of(R"({"topology": "topologies/loop.json",
      "vehicle_profiles": {"x": {"max_speed": 0, "warp": 9}, "y": 3}, "agents": [{"kind": "routing"}]})");
  EXPECT_NE(text.find("vehicle_profiles.x.max_speed: must be a number > 0"), std::string::npos) << text;
  EXPECT_NE(text.find("vehicle_profiles.x.warp: unknown field"), std::string::npos) << text;
  EXPECT_NE(text.find("vehicle_profiles.y: must be an object"), std::string::npos) << text;
}

// A vehicle that would take longer than the clock counts to reach any speed: the planner
// refuses it, so the file check does, before any logical agent starts.
TEST(LaunchFile, ProfilesOutsideThePlannersBoundsAreRefused) {
  const auto text = problems_of(R"({"topology": "topologies/loop.json",
      "vehicle_profiles": {"slow": {"acceleration": 1e-19}}, "agents": [{"kind": "routing"}]})");
  EXPECT_NE(text.find("vehicle_profiles.slow: acceleration must be from 0.001 to 100 m/s^2, got 1e-19"),
            std::string::npos)
      << text;
}

// What the agents would refuse at start, after the rest of the fleet started: a battery
// fuller than it holds, orders without two distinct stations to go between.
TEST(LaunchFile, BatteriesOverTheirCapacityAndTooFewStationsAreRefused) {
  const auto text = problems_of(R"({"topology": "topologies/loop.json",
      "vehicle_profiles": {"x": {"battery": 2000}, "y": {"battery": 600, "battery_capacity": 500},
                           "z": {"battery": 400, "battery_capacity": 500}},
      "agents": [{"kind": "routing"},
                 {"kind": "load-generator", "id": "twice", "stations": ["station", "station"]},
                 {"kind": "load-generator", "id": "loop-stations"}]})");
  EXPECT_NE(text.find("vehicle_profiles.x.battery: must be at most the battery capacity (1000 Wh)"), std::string::npos)
      << text;
  EXPECT_NE(text.find("vehicle_profiles.y.battery: must be at most the battery capacity (500 Wh)"), std::string::npos)
      << text;
  EXPECT_EQ(text.find("vehicle_profiles.z"), std::string::npos) << text;
  EXPECT_NE(text.find("agents[1].stations: a station is named twice"), std::string::npos) << text;
  EXPECT_NE(text.find("agents[2].stations: the topology's stations: orders need at least two distinct stations, "
                      "got 1 (name them)"),
            std::string::npos) << text;
}

TEST(LaunchFile, DuplicateIdsAndVehicles) {
  const auto text = problems_of(loop_file(R"({"kind": "routing"}, {"kind": "routing"},
      {"kind": "ran-sim", "vehicle": "V1", "at": "south-west"},
      {"kind": "ran-sim", "vehicle": "V1", "id": "other", "at": "north-east"},
      {"kind": "logical", "vehicle": "V2", "id": "V3"},
      {"kind": "ran-sim", "vehicle": "V4", "id": "bad id!", "at": "charger"},
      {"kind": "topology", "db": "shared.db"}, {"kind": "logical", "vehicle": "V5", "db": "/state/shared.db"})"));
  EXPECT_NE(text.find("agents[1].id: agent id 'routing' is used by agents[0] too"), std::string::npos) << text;
  EXPECT_NE(text.find("agents[7].db: journal /state/shared.db is agents[6].db's too (one journal per agent)"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("agents[3].vehicle: vehicle 'V1' has a ran-sim at agents[2] already"), std::string::npos)
      << text;
  EXPECT_NE(text.find("agents[4].id: a logical agent's id is its vehicle id"), std::string::npos) << text;
  EXPECT_NE(text.find("agents[5].id: "), std::string::npos) << text;
}

TEST(LaunchFile, VehiclesMustNotStartOnOneOrConflictingVertices) {
  const auto same = problems_of(loop_file(R"({"kind": "ran-sim", "vehicle": "V1", "at": "south"},
      {"kind": "ran-sim", "vehicle": "V2", "at": "south"})"));
  EXPECT_NE(same.find("agents[1].at: 'south' is, or conflicts with, the start of agents[0]"), std::string::npos)
      << same;
  // Apart: accepted.
  EXPECT_TRUE(parse(loop_file(R"({"kind": "ran-sim", "vehicle": "V1", "at": "south"},
      {"kind": "ran-sim", "vehicle": "V2", "at": "north"})")).has_value());
}

TEST(LaunchFile, EveryPartitionNeedsATopologyAgent) {
  // The warehouse has partitions west and east.
  const std::string text = R"({"topology": "topologies/warehouse.json", "agents": [
      {"kind": "topology", "partition": "west"}, {"kind": "topology", "partition": "west", "id": "again"}]})";
  const auto problems = problems_of(text);
  EXPECT_NE(problems.find("agents: no topology agent serves partition 'east'"), std::string::npos) << problems;
  EXPECT_NE(problems.find("agents[1].partition: partition 'west' is served by agents[0] already"),
            std::string::npos) << problems;
}

TEST(LaunchFile, UnreadableFile) {
  auto loaded = load_launch_file("/nonexistent/launch.json", "/state");
  ASSERT_FALSE(loaded.has_value());
  EXPECT_EQ(loaded.error().front().what, "cannot open: No such file or directory");
  // A device is refused, not read until memory runs out.
  auto device = load_launch_file("/dev/zero", "/state");
  ASSERT_FALSE(device.has_value());
  EXPECT_EQ(device.error().front().what, "is a device or socket, not a file");
}

TEST(LaunchFile, BundledWarehouseIsValid) {
  auto loaded = load_launch_file(source_dir() / "launch" / "warehouse.json", "/state");
  ASSERT_TRUE(loaded.has_value()) << loaded.error().front().where << ": " << loaded.error().front().what;
  std::size_t vehicles = 0;
  for (const auto& agent : loaded->agents) vehicles += agent.kind == AgentKind::ran_sim ? 1 : 0;
  EXPECT_GE(vehicles, 8u);
}

}  // namespace
}  // namespace drover::launcher
