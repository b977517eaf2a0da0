// A commander drives a simulated vehicle process (`drover ran-sim`) over DDS through a
// sequence of moves and actions, bad commands, pause, cancel and faults, and sees every
// status it expects. The vehicle runs at time factor 10 on its own domain id.

#include <signal.h>

#include <atomic>
#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "drover/dds/participant.hpp"
#include "drover/ran/validation.hpp"
#include "drover/ran_runner/client.hpp"
#include "drover/topology/topology_file.hpp"
#include "tests/agents/child_process.hpp"

namespace drover::ran {
namespace {

using namespace std::chrono_literals;
using test::ChildProcess;

// Each test its own DDS domain (80..82; every test domain is at most 101, see docs/dds.md).
constexpr std::uint32_t kDomainMoves = 80;
constexpr std::uint32_t kDomainFaults = 81;
constexpr std::uint32_t kDomainOther = 82;
/// Generous bounds for discovery and for a few simulated seconds on a loaded machine.
constexpr auto kTimeout = 30000ms;
constexpr auto kCallTimeout = 10000ms;

std::string source_path(const std::string& relative) {
  const char* dir = std::getenv("DROVER_SOURCE_DIR");
  return std::string(dir != nullptr ? dir : ".") + "/" + relative;
}

class RanSimDds : public ::testing::Test {
 protected:
  /// Starts the simulated vehicle V1 at south-west on `domain` and a commander for it.
  void start(std::uint32_t domain) {
    auto loaded = topology::load_topology_file(source_path("launch/topologies/loop.json"));
    ASSERT_TRUE(loaded);
    world = std::make_unique<topology::Topology>(std::move(*loaded));
    auto child = ChildProcess::spawn(
        test::binary_path("drover"),
        {"ran-sim", "--id", "V1", "--topology", source_path("launch/topologies/loop.json"),
         "--at", "south-west", "--domain", std::to_string(domain), "--time-factor", "10",
         // Operations last 0.5 s of real time: several 50 ms statuses report each running.
         "--load-duration", "5", "--custom-action", "beep=5", "--status-period-ms", "50",
         "--log-level", "warn"});
    ASSERT_TRUE(child);
    vehicle_process.emplace(std::move(*child));
    dds::ParticipantOptions options;
    options.domain_id = domain;
    options.agent_id = "ran-sim-test-commander";
    auto created = dds::Participant::create(options);
    ASSERT_TRUE(created) << created.error().message;
    participant = std::move(*created);
    auto made = RanClient::create(*participant, "V1");
    ASSERT_TRUE(made) << made.error().message;
    client = std::move(*made);
    ASSERT_TRUE(client->wait_for([](const VehicleStatus&) { return true; }, kTimeout))
        << "no status from the simulated vehicle";
  }

  void TearDown() override {
    client.reset();
    participant.reset();
    vehicle_process.reset();  // SIGKILL and reap if a test left it running
  }

  MoveCommand move(std::string id, const std::string& from, const std::string& edge,
                   const std::string& to, double max_speed) const {
    const auto& target = world->vertex(*world->find(to));
    MoveCommand command;
    command.id = std::move(id);
    command.target_vertex = to;
    command.target = {target.position.x(), target.position.y(), std::nullopt};
    command.edge = edge;
    command.max_speed = max_speed;
    for (const auto& entity : {from, edge, to}) {
      command.area.push_back(world->footprint(*world->find(entity)));
    }
    return command;
  }

  /// Waits until the vehicle reports `id` in `state`; fails the test otherwise.
  VehicleStatus wait_state(const CommandId& id, CommandState state) {
    auto status = client->wait_for(
        [&](const VehicleStatus& s) {
          const auto* command = s.find_command(id);
          return command != nullptr && command->state == state;
        },
        kTimeout);
    EXPECT_TRUE(status) << id << " never reported " << to_string(state);
    return status.value_or(VehicleStatus{});
  }

  /// Whether any status received so far listed `id` in `state`.
  bool seen(const CommandId& id, CommandState state) const {
    for (const auto& status : client->history()) {
      const auto* command = status.find_command(id);
      if (command != nullptr && command->state == state) return true;
    }
    return false;
  }

  void expect_accepted(const Result<CommandVerdict>& verdict) {
    ASSERT_TRUE(verdict) << verdict.error().message;
    ASSERT_TRUE(verdict->state.has_value());
    EXPECT_NE(*verdict->state, CommandState::rejected) << verdict->reason;
  }

  std::unique_ptr<topology::Topology> world;
  std::optional<ChildProcess> vehicle_process;
  std::unique_ptr<dds::Participant> participant;
  std::unique_ptr<RanClient> client;
};

TEST_F(RanSimDds, DrivesMovesAndActionsAndReportsEveryState) {
  ASSERT_NO_FATAL_FAILURE(start(kDomainMoves));
  const auto first = *client->latest();
  EXPECT_EQ(first.vehicle_id, "V1");
  EXPECT_DOUBLE_EQ(first.pose.x, 0.0);
  EXPECT_EQ(first.load, LoadState::empty);

  expect_accepted(client->move(move("m1", "south-west", "south-west->south", "south", 1.5), kCallTimeout));
  expect_accepted(client->move(move("m2", "south", "south->south-east", "south-east", 1.5), kCallTimeout));
  expect_accepted(client->action({"load", ActionKind::load, "", {}}, kCallTimeout));
  expect_accepted(client->action({"beep", ActionKind::custom, "beep", {}}, kCallTimeout));

  // Bad commands are rejected with their reason; the vehicle keeps going.
  auto unknown = move("bad-vertex", "south-east", "south-east->station", "station", 1.0);
  unknown.target_vertex = "atlantis";
  auto verdict = client->move(unknown, kCallTimeout);
  ASSERT_TRUE(verdict);
  EXPECT_TRUE(verdict->rejected());
  EXPECT_EQ(verdict->code, rejection_code::kUnknownVertex);
  verdict = client->move(move("bad-speed", "south-east", "south-east->station", "station", -1),
                         kCallTimeout);
  ASSERT_TRUE(verdict);
  EXPECT_EQ(verdict->code, rejection_code::kInvalidSpeed);
  auto narrow = move("bad-area", "south-east", "south-east->station", "station", 1.0);
  narrow.area.erase(narrow.area.begin() + 1);  // without the edge's footprint
  verdict = client->move(narrow, kCallTimeout);
  ASSERT_TRUE(verdict);
  EXPECT_EQ(verdict->code, rejection_code::kOutsideArea);
  verdict = client->action({"dance", ActionKind::custom, "dance", {}}, kCallTimeout);
  ASSERT_TRUE(verdict);
  EXPECT_EQ(verdict->code, rejection_code::kUnsupportedAction);

  const auto done = wait_state("beep", CommandState::finished);
  for (const char* id : {"m1", "m2", "load", "beep"}) {
    EXPECT_TRUE(seen(id, CommandState::running)) << id << " never reported running";
  }
  EXPECT_DOUBLE_EQ(done.pose.x, 8.0);
  EXPECT_DOUBLE_EQ(done.pose.y, 0.0);
  EXPECT_EQ(done.load, LoadState::loaded);
  for (const char* id : {"m1", "m2", "load"}) {
    EXPECT_EQ(done.find_command(id)->state, CommandState::finished) << id;
  }
  EXPECT_EQ(done.find_command("bad-vertex")->state, CommandState::rejected);

  // Reports arrive in order, stamped with the shared clock, and the vehicle never
  // exceeded the edges' limit (1.5 m/s) in any of them.
  const auto history = client->history();
  ASSERT_GE(history.size(), 2u);
  for (std::size_t i = 1; i < history.size(); ++i) {
    EXPECT_GT(history[i].sequence, history[i - 1].sequence);
    EXPECT_GE(history[i].time, history[i - 1].time);
    EXPECT_LE(history[i].linear_speed, 1.5 + 1e-9);
  }
}

TEST_F(RanSimDds, PauseCancelAndFaults) {
  ASSERT_NO_FATAL_FAILURE(start(kDomainFaults));
  // Slow moves (0.4 m/s), so that the commands below reach the vehicle while it drives.
  expect_accepted(client->move(move("m1", "south-west", "south-west->south", "south", 0.4), kCallTimeout));
  wait_state("m1", CommandState::running);

  ASSERT_TRUE(client->pause(kCallTimeout));
  const auto paused = client->wait_for(
      [](const VehicleStatus& s) { return s.paused && s.linear_speed == 0; }, kTimeout);
  ASSERT_TRUE(paused);
  EXPECT_EQ(paused->find_command("m1")->state, CommandState::running);
  ASSERT_TRUE(client->resume(kCallTimeout));
  wait_state("m1", CommandState::finished);

  // A stall: a recoverable error while it lasts, then it is gone.
  ASSERT_TRUE(client->inject_fault(SimFault::stall, seconds_to_ns(3), kCallTimeout));
  const auto stalled = client->wait_for([](const VehicleStatus& s) { return s.has_error("stall"); }, kTimeout);
  ASSERT_TRUE(stalled);
  EXPECT_EQ(stalled->errors.front().level, ErrorLevel::recoverable);
  ASSERT_TRUE(client->wait_for([](const VehicleStatus& s) { return !s.has_error("stall"); }, kTimeout));

  // Cancel the running move: it brakes and ends cancelled, the next one with it.
  expect_accepted(client->move(move("m2", "south", "south->south-east", "south-east", 0.4), kCallTimeout));
  expect_accepted(client->move(move("m3", "south-east", "south-east->station", "station", 1.0), kCallTimeout));
  wait_state("m2", CommandState::running);
  ASSERT_TRUE(client->cancel("m2", kCallTimeout));
  const auto cancelled = wait_state("m3", CommandState::cancelled);
  EXPECT_EQ(cancelled.find_command("m2")->state, CommandState::cancelled);

  // A protective field stops the vehicle until cleared.
  ASSERT_TRUE(client->inject_fault(SimFault::protective_field, 0, kCallTimeout));
  ASSERT_TRUE(client->wait_for([](const VehicleStatus& s) { return s.has_error("protective_field"); },
                               kTimeout));
  ASSERT_TRUE(client->inject_fault(SimFault::clear_protective_field, 0, kCallTimeout));
  ASSERT_TRUE(client->wait_for([](const VehicleStatus& s) { return !s.has_error("protective_field"); },
                               kTimeout));

  // A lost connection: commands are refused as unavailable until it is restored.
  ASSERT_TRUE(client->inject_fault(SimFault::lose_connection, 0, kCallTimeout));
  const auto refused = client->action({"late", ActionKind::load, "", {}}, kCallTimeout);
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().code, ErrorCode::unavailable);
  const auto last_before = client->latest()->sequence;
  ASSERT_TRUE(client->inject_fault(SimFault::restore_connection, 0, kCallTimeout));
  ASSERT_TRUE(client->wait_for([&](const VehicleStatus& s) { return s.sequence > last_before; },
                               kTimeout));

  // A battery failure is fatal: the vehicle refuses everything afterwards.
  ASSERT_TRUE(client->inject_fault(SimFault::battery_failure, 0, kCallTimeout));
  const auto failed = client->wait_for([](const VehicleStatus& s) { return s.has_error("battery_failure"); },
                                       kTimeout);
  ASSERT_TRUE(failed);
  const auto after = client->action({"c1", ActionKind::charge, "", {}}, kCallTimeout);
  ASSERT_TRUE(after);
  EXPECT_EQ(after->code, rejection_code::kNotReady);

  // The process shuts down cleanly on SIGINT.
  vehicle_process->signal(SIGINT);
  const auto exit = vehicle_process->wait_exit(kTimeout);
  ASSERT_TRUE(exit);
  EXPECT_TRUE(exit->exited);
  EXPECT_EQ(exit->code, 0);
}

TEST_F(RanSimDds, CommandsForAnotherVehicleAreRefused) {
  ASSERT_NO_FATAL_FAILURE(start(kDomainOther));
  // A second client of V1, told of every status by callback.
  std::atomic<int> callbacks{0};
  auto watcher = RanClient::create(*participant, "V1", {}, 1,
                                   [&](const VehicleStatus& status) {
                                     if (status.vehicle_id == "V1") ++callbacks;
                                   });
  ASSERT_TRUE(watcher);
  ASSERT_TRUE((*watcher)->wait_for([](const VehicleStatus&) { return true; }, kTimeout));
  EXPECT_GE(callbacks.load(), 1);
  EXPECT_EQ((*watcher)->history().size(), 1u);  // the history limit

  auto other = RanClient::create(*participant, "V2", ran_agent_id("V1"));
  ASSERT_TRUE(other);
  const auto verdict = (*other)->action({"x", ActionKind::load, "", {}}, kCallTimeout);
  ASSERT_FALSE(verdict);
  EXPECT_EQ(verdict.error().code, ErrorCode::not_found);
}

}  // namespace
}  // namespace drover::ran
