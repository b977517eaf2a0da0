// droverctl as an operator runs it, a separate process: `agents`, `vehicles`, `pause --all` and `alarms`
// against live agents (dds_test_peer processes, or participants of the test process that
// publish as logical agents do), and its bad usage. Domains 18 and 40..44.

#include <signal.h>

#include <chrono>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "drover/dds/agent_directory.hpp"
#include "drover/dds/heartbeat_publisher.hpp"
#include "drover/dds/writer.hpp"
#include "drover/logical_agent/messages.hpp"
#include "drover/logical_agent/names.hpp"
#include "tests/agents/dds_test_support.hpp"

namespace drover::test {
namespace {

using namespace std::chrono_literals;

class DroverctlTest : public ::testing::Test {
 protected:
  void TearDown() override { children_.clear(); }  // kill -9 and reap, whatever happened

  /// Runs droverctl with `args` to its end. \return its exit status; its output in
  /// `out` and `err`.
  std::optional<ExitStatus> run_droverctl(const std::vector<std::string>& args, std::string& out, std::string& err) {
    const std::string stem = ::testing::TempDir() + "droverctl_" +
                             ::testing::UnitTest::GetInstance()->current_test_info()->name();
    auto child = ChildProcess::spawn(binary_path("droverctl"), args, stem + ".out", stem + ".err");
    if (!child) return std::nullopt;
    children_.push_back(std::move(*child));
    auto status = children_.back().wait_exit(60s);
    out = read_file(stem + ".out");
    err = read_file(stem + ".err");
    return status;
  }

  std::vector<ChildProcess> children_;
};

TEST_F(DroverctlTest, AgentsListsTheLiveAgentsWithKindAndWhatTheyOwn) {
  constexpr std::uint32_t kDomain = 40;
  for (auto [id, kind, owns] : std::vector<std::tuple<std::string, std::string, std::string>>{
           {"router-1", "routing", "zone-a"}, {"topo-east", "topology", "east"}}) {
    auto peer = spawn_peer(kDomain, id, {"--heartbeat", kind, "--owns", owns});
    ASSERT_TRUE(peer.has_value());
    children_.push_back(std::move(*peer));
  }
  {
    // Both agents up before asking (the observer leaves again: it has no heartbeat and
    // would only make droverctl wait for one).
    auto observer = make_participant(kDomain, "observer");
    ASSERT_NE(observer, nullptr);
    auto directory = dds::AgentDirectory::create(*observer);
    ASSERT_TRUE(directory.has_value());
    ASSERT_TRUE((*directory)->wait_until([](const auto& records) { return records.size() == 2; }, kDiscoveryTimeout));
  }

  std::string out, err;
  auto status = run_droverctl({"agents", "--domain", std::to_string(kDomain), "--json", "--timeout", "30"}, out, err);
  ASSERT_TRUE(status.has_value());
  ASSERT_TRUE(status->exited);
  ASSERT_EQ(status->code, 0) << err;
  const auto agents = nlohmann::json::parse(out);
  ASSERT_EQ(agents.size(), 2u) << out;
  EXPECT_EQ(agents[0]["id"], "router-1");
  EXPECT_EQ(agents[0]["kind"], "routing");
  EXPECT_EQ(agents[0]["owns"], nlohmann::json::array({"zone-a"}));
  EXPECT_EQ(agents[1]["id"], "topo-east");
  EXPECT_EQ(agents[1]["kind"], "topology");
  EXPECT_FALSE(agents[1]["version"].get<std::string>().empty());

  status = run_droverctl({"agents", "--domain", std::to_string(kDomain), "--timeout", "30"}, out, err);
  ASSERT_TRUE(status.has_value());
  EXPECT_EQ(status->code, 0) << err;
  EXPECT_NE(out.find("router-1"), std::string::npos) << out;
  EXPECT_NE(out.find("zone-a"), std::string::npos) << out;
}

TEST_F(DroverctlTest, AgentsExitsWithCode3WhenNobodyAnswers) {
  std::string out, err;
  auto status = run_droverctl({"agents", "--domain", "41", "--timeout", "0.5"}, out, err);
  ASSERT_TRUE(status.has_value());
  ASSERT_TRUE(status->exited);
  EXPECT_EQ(status->code, 3);
  EXPECT_NE(err.find("no agent answered on domain 41 within 0.5 s"), std::string::npos) << err;
  EXPECT_TRUE(out.empty()) << out;
}

/// A logical agent as droverctl sees one: its heartbeat, and its vehicle's state.
struct FakeLogicalAgent {
  std::unique_ptr<dds::Participant> participant;
  std::unique_ptr<dds::HeartbeatPublisher> heartbeat;
  std::unique_ptr<dds::Writer<msg::VehicleState>> states;

  /// With `write_state` false it only beats: its state never arrives.
  FakeLogicalAgent(std::uint32_t domain, const msg::VehicleState& state, bool write_state = true) {
    participant = make_participant(domain, state.vehicle());
    if (!participant) return;
    dds::HeartbeatOptions beat;
    beat.kind = "logical";
    beat.owns = {state.vehicle()};
    auto created = dds::HeartbeatPublisher::create(*participant, SharedClock::wall(), beat);
    EXPECT_TRUE(created.has_value());
    if (created) heartbeat = std::move(*created);
    auto writer = dds::Writer<msg::VehicleState>::create(*participant, logical_agent::kVehicleStateTopic);
    EXPECT_TRUE(writer.has_value());
    if (!writer) return;
    states = std::move(*writer);
    if (write_state) {
      EXPECT_TRUE(states->write(state).has_value());
    }
  }
  ~FakeLogicalAgent() {
    states.reset();
    heartbeat.reset();
  }
};

msg::VehicleState vehicle_state(const std::string& vehicle, msg::VehicleActivity activity, const std::string& vertex,
                                const std::string& order, double state_of_charge, bool moving) {
  msg::VehicleState state;
  state.vehicle(vehicle);
  state.ran("ran-" + vehicle);
  state.state(activity);
  state.vertex(vertex);
  state.order(order);
  state.queued_orders(order.empty() ? 0 : 2);
  state.state_of_charge(state_of_charge);
  state.moving(moving);
  state.time().ns(seconds_to_ns(1000));
  return state;
}

TEST_F(DroverctlTest, VehiclesShowsWhatEveryVehicleIsDoing) {
  constexpr std::uint32_t kDomain = 42;
  FakeLogicalAgent v1(kDomain, vehicle_state("V1", msg::VEHICLE_DRIVING, "aisle-3", "o-17", 0.8, true));
  FakeLogicalAgent v2(kDomain, vehicle_state("V2", msg::VEHICLE_CHARGING, "charger-1", "", 0.15, false));
  auto pausing = vehicle_state("V3", msg::VEHICLE_DRIVING, "aisle-4", "o-18", 0.5, true);
  pausing.paused(true);
  pausing.pause_reason("aisle blocked");
  FakeLogicalAgent v3(kDomain, pausing);
  ASSERT_TRUE(v1.states && v2.states && v3.states);

  std::string out, err;
  auto status = run_droverctl({"vehicles", "--domain", std::to_string(kDomain), "--json", "--timeout", "30"}, out, err);
  ASSERT_TRUE(status.has_value());
  ASSERT_EQ(status->code, 0) << err;
  const auto listed = nlohmann::json::parse(out);
  ASSERT_EQ(listed.size(), 3u) << out;
  EXPECT_EQ(listed[0]["vehicle"], "V1");
  EXPECT_EQ(listed[0]["state"], "driving");
  EXPECT_EQ(listed[0]["vertex"], "aisle-3");
  EXPECT_EQ(listed[0]["order"], "o-17");
  EXPECT_EQ(listed[0]["queued_orders"], 2);
  EXPECT_EQ(listed[0]["moving"], true);
  EXPECT_DOUBLE_EQ(listed[0]["state_of_charge"].get<double>(), 0.8);
  EXPECT_EQ(listed[1]["vehicle"], "V2");
  EXPECT_EQ(listed[1]["state"], "charging");
  EXPECT_EQ(listed[1]["order"], "");
  EXPECT_EQ(listed[1]["paused"], false);
  EXPECT_EQ(listed[2]["state"], "driving");
  EXPECT_EQ(listed[2]["paused"], true);
  EXPECT_EQ(listed[2]["pause_reason"], "aisle blocked");

  status = run_droverctl({"vehicles", "--domain", std::to_string(kDomain), "--timeout", "30"}, out, err);
  ASSERT_TRUE(status.has_value());
  ASSERT_EQ(status->code, 0) << err;
  EXPECT_NE(out.find("VEHICLE"), std::string::npos) << out;
  EXPECT_NE(out.find("charging  charger-1"), std::string::npos) << out;
  EXPECT_NE(out.find("15 %"), std::string::npos) << out;
  // Still driving its last moves, paused: the table says so, with the reason.
  EXPECT_NE(out.find("pausing   aisle-4"), std::string::npos) << out;
  EXPECT_NE(out.find("50 %     aisle blocked"), std::string::npos) << out;
}

TEST_F(DroverctlTest, PauseAndResumeExitWithCode3WhenNoLogicalAgentAnswersAndRefuseBadOptions) {
  std::string out, err;
  for (const char* command : {"pause", "resume"}) {
    auto status = run_droverctl({command, "V9", "--domain", "43", "--timeout", "0.5"}, out, err);
    ASSERT_TRUE(status.has_value());
    EXPECT_EQ(status->code, 3) << command << ": " << err;
    EXPECT_NE(err.find("vehicle 'V9'"), std::string::npos) << err;
    status = run_droverctl({command, "--domain", "43"}, out, err);
    ASSERT_TRUE(status.has_value());
    EXPECT_EQ(status->code, 2) << command << " without a vehicle: " << err;
    status = run_droverctl({command, "V9", "--all", "--domain", "43"}, out, err);
    ASSERT_TRUE(status.has_value());
    EXPECT_EQ(status->code, 2) << command << " with a vehicle and --all: " << err;
    EXPECT_NE(err.find("name one VEHICLE or give --all"), std::string::npos) << err;
    status = run_droverctl({command, "--all", "--domain", "43", "--timeout", "0.5"}, out, err);
    ASSERT_TRUE(status.has_value());
    EXPECT_EQ(status->code, 3) << command << " --all with no logical agent: " << err;
    EXPECT_NE(err.find("no logical agent answered on domain 43 within 0.5 s"), std::string::npos) << err;
  }
  auto status = run_droverctl({"pause", "V9", "--wait", "-1", "--domain", "43"}, out, err);
  ASSERT_TRUE(status.has_value());
  EXPECT_EQ(status->code, 2) << err;
}

TEST_F(DroverctlTest, PauseAllAsksEveryLiveVehicleLeavesPausedOnesAsTheyAreAndFailsNamingOneThatDoesNotAnswer) {
  // Two logical agents as droverctl sees them, with no pause service: V7 idle, V8 paused by
  // an operator for a reason of its own.
  constexpr std::uint32_t kDomain = 18;
  const std::string domain = std::to_string(kDomain);
  FakeLogicalAgent v7(kDomain, vehicle_state("V7", msg::VEHICLE_IDLE, "aisle-1", "", 0.9, false));
  auto paused = vehicle_state("V8", msg::VEHICLE_PAUSED, "aisle-2", "", 0.9, false);
  paused.paused(true);
  paused.pause_reason("bumper check");
  FakeLogicalAgent v8(kDomain, paused);
  std::string out, err;
  // V7 is asked and does not answer: exit 1 naming it; V8 is left as it is.
  // Discovery ends once both states are in; --timeout only bounds a loaded machine.
  auto status = run_droverctl({"pause", "--all", "--reason", "shift change", "--domain", domain, "--timeout", "10"},
                              out, err);
  ASSERT_TRUE(status.has_value());
  EXPECT_EQ(status->code, 1) << out << err;
  EXPECT_NE(err.find("vehicle 'V7'"), std::string::npos) << err;
  EXPECT_NE(out.find("vehicle 'V8' already paused ('bumper check'): left as it is"), std::string::npos) << out;
  EXPECT_EQ(err.find("vehicle 'V8'"), std::string::npos) << err;
  // Resuming those paused for another reason: V8 stays paused, V7 is not paused; nothing
  // is asked, so nothing fails.
  status = run_droverctl({"resume", "--all", "--reason", "shift change", "--domain", domain, "--timeout", "10"}, out,
                         err);
  ASSERT_TRUE(status.has_value());
  EXPECT_EQ(status->code, 0) << out << err;
  EXPECT_NE(out.find("vehicle 'V8' left paused ('bumper check')"), std::string::npos) << out;
  EXPECT_NE(out.find("vehicle 'V7' not paused"), std::string::npos) << out;
  // --reason on the resume of one named vehicle is bad usage.
  status = run_droverctl({"resume", "V8", "--reason", "bumper check", "--domain", domain}, out, err);
  ASSERT_TRUE(status.has_value());
  EXPECT_EQ(status->code, 2) << err;
  EXPECT_NE(err.find("--reason on resume chooses among --all"), std::string::npos) << err;
}

TEST_F(DroverctlTest, PauseAndResumeAllAskNoVehicleWhoseStateDidNotArriveAndFailNamingIt) {
  // Whether V6 is paused already (by an operator, for a reason of its own) is unknown: a
  // fleet-wide pause would replace that reason, and a later `resume --all --reason` lift it.
  constexpr std::uint32_t kDomain = 56;
  const std::string domain = std::to_string(kDomain);
  FakeLogicalAgent v6(kDomain, vehicle_state("V6", msg::VEHICLE_PAUSED, "aisle-1", "", 0.9, false), false);
  std::string out, err;
  // The whole --timeout passes each time (the state never comes): long enough for V6's
  // heartbeat to be heard on a loaded machine, or it would not count as live.
  for (const std::string command : {"pause", "resume"}) {
    auto status = run_droverctl({command, "--all", "--reason", "shift change", "--domain", domain, "--timeout", "10"},
                                out, err);
    ASSERT_TRUE(status.has_value());
    EXPECT_EQ(status->code, 1) << command << ": " << out << err;
    EXPECT_NE(err.find("error: vehicle 'V6' not " + command + "d: its state did not arrive within 10 s"),
              std::string::npos)
        << command << ": " << err;
  }
}

TEST_F(DroverctlTest, VehiclesExitsWithCode3WhenNoLogicalAgentAnswers) {
  std::string out, err;
  auto status = run_droverctl({"vehicles", "--domain", "43", "--timeout", "0.5"}, out, err);
  ASSERT_TRUE(status.has_value());
  EXPECT_EQ(status->code, 3);
  EXPECT_NE(err.find("no logical agent answered on domain 43 within 0.5 s"), std::string::npos) << err;
}

TEST_F(DroverctlTest, OrdersExitsWithCode3WhenNoLogicalAgentAnswersAndRefusesBadOptions) {
  std::string out, err;
  auto status = run_droverctl({"orders", "--domain", "43", "--vehicle", "V9", "--timeout", "0.5"}, out, err);
  ASSERT_TRUE(status.has_value());
  EXPECT_EQ(status->code, 3);
  EXPECT_NE(err.find("no logical agent of vehicle 'V9' answered on domain 43 within 0.5 s"), std::string::npos) << err;
  status = run_droverctl({"orders", "--domain", "43", "--timeout", "soon"}, out, err);
  ASSERT_TRUE(status.has_value());
  EXPECT_EQ(status->code, 2) << err;
}

TEST_F(DroverctlTest, AlarmsShowsTheKeptAlarmsThenFollowsNewOnesFromTheChosenSeverityUntilSigterm) {
  constexpr std::uint32_t kDomain = 44;
  auto agent = make_participant(kDomain, "V1");
  ASSERT_TRUE(agent);
  auto writer = dds::Writer<msg::OperatorAlarm>::create(*agent, logical_agent::kAlarmTopic,
                                                      logical_agent::alarm_writer_qos());
  ASSERT_TRUE(writer.has_value());
  const auto alarm = [](msg::AlarmSeverity severity, const std::string& text) {
    msg::OperatorAlarm a;
    a.agent("V1");
    a.vehicle("V1");
    a.severity(severity);
    a.text(text);
    a.time().ns(seconds_to_ns(12.5));
    return a;
  };
  // Raised before droverctl started: the agent keeps it, so it is shown all the same.
  ASSERT_TRUE((*writer)->write(alarm(msg::ALARM_CRITICAL, "left its allocated area")).has_value());

  const std::string out_file = ::testing::TempDir() + "droverctl_alarms.out";
  const std::string err_file = ::testing::TempDir() + "droverctl_alarms.err";
  auto child = ChildProcess::spawn(binary_path("droverctl"),
                                   {"alarms", "--domain", std::to_string(kDomain), "--min-severity", "warning",
                                    "--json"},
                                   out_file, err_file);
  ASSERT_TRUE(child.has_value());
  children_.push_back(std::move(*child));
  ASSERT_TRUE((*writer)->wait_for_readers(1, kDiscoveryTimeout));
  ASSERT_TRUE((*writer)->write(alarm(msg::ALARM_INFO, "route re-planned")).has_value());
  // A RAN's reason may carry a line break or bytes that are not UTF-8: still one valid line.
  ASSERT_TRUE((*writer)->write(alarm(msg::ALARM_ERROR, "caf\xe9\nforged")).has_value());

  // The kept critical one shows first, then the error one (written after the info one, on a
  // reliable topic: that one arrived before it and was left out).
  std::string out;
  const auto deadline = std::chrono::steady_clock::now() + kDiscoveryTimeout;
  while (out.find("forged") == std::string::npos && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    out = read_file(out_file);
  }
  children_.back().signal(SIGTERM);
  const auto status = children_.back().wait_exit(30s);
  ASSERT_TRUE(status.has_value());
  EXPECT_TRUE(status->exited && status->code == 0) << read_file(err_file);
  out = read_file(out_file);
  std::istringstream lines(out);
  std::string line;
  std::vector<nlohmann::json> shown;
  while (std::getline(lines, line)) shown.push_back(nlohmann::json::parse(line));
  ASSERT_EQ(shown.size(), 2u) << out;
  EXPECT_EQ(shown[0]["severity"], "critical");
  EXPECT_EQ(shown[0]["vehicle"], "V1");
  EXPECT_EQ(shown[0]["text"], "left its allocated area");
  EXPECT_EQ(shown[0]["time_ns"], seconds_to_ns(12.5));
  EXPECT_EQ(shown[1]["severity"], "error");
  EXPECT_EQ(shown[1]["text"], "caf\xef\xbf\xbd\nforged");  // U+FFFD for the stray byte
}

TEST_F(DroverctlTest, BadUsageExitsWithCode2AndSaysWhy) {
  std::string out, err;
  auto status = run_droverctl({"agents", "--domain", "999"}, out, err);
  ASSERT_TRUE(status.has_value());
  EXPECT_EQ(status->code, 2);
  EXPECT_NE(err.find("--domain"), std::string::npos) << err;

  status = run_droverctl({"agents", "--timeout", "-1"}, out, err);
  ASSERT_TRUE(status.has_value());
  EXPECT_EQ(status->code, 2);
  EXPECT_NE(err.find("--timeout"), std::string::npos) << err;

  status = run_droverctl({"order", "withdraw", "V1"}, out, err);
  ASSERT_TRUE(status.has_value());
  EXPECT_EQ(status->code, 2);
  EXPECT_NE(err.find("order is required"), std::string::npos) << err;

  status = run_droverctl({"order", "withdraw", "V1", "o1", "--wait", "-3"}, out, err);
  ASSERT_TRUE(status.has_value());
  EXPECT_EQ(status->code, 2);
  EXPECT_NE(err.find("--wait"), std::string::npos) << err;

  status = run_droverctl({"alarms", "--min-severity", "loud"}, out, err);
  ASSERT_TRUE(status.has_value());
  EXPECT_EQ(status->code, 2);
  EXPECT_NE(err.find("--min-severity 'loud'"), std::string::npos) << err;

  status = run_droverctl({"alarms", "--duration", "-1"}, out, err);
  ASSERT_TRUE(status.has_value());
  EXPECT_EQ(status->code, 2);
  EXPECT_NE(err.find("--duration"), std::string::npos) << err;

  // An empty vehicle would address whichever logical agent answers first.
  status = run_droverctl({"order", "send", "", "left-4:NOP"}, out, err);
  ASSERT_TRUE(status.has_value());
  EXPECT_EQ(status->code, 2);
  EXPECT_NE(err.find("vehicle: must not be empty"), std::string::npos) << err;

  status = run_droverctl({"order", "send", "V1", "left-4:NOP", "--name", std::string(256, 'n')}, out, err);
  ASSERT_TRUE(status.has_value());
  EXPECT_EQ(status->code, 2);
  EXPECT_NE(err.find("is 256 bytes long, at most 255 are allowed"), std::string::npos) << err;

  // Lock ids as the topology agent writes them, or nothing is asked: "t/01" is not lock 1.
  for (const std::string bad : {"topology/1x", "topology/2/3", "topology/01", "topology/", "/1"}) {
    status = run_droverctl({"unlock", bad, "--timeout", "1"}, out, err);
    ASSERT_TRUE(status.has_value());
    EXPECT_EQ(status->code, 2) << bad;
    EXPECT_NE(err.find("is not a lock id"), std::string::npos) << bad << ": " << err;
  }

  // Lock times beyond the shared clock's range, checked before anything goes on the network.
  for (const auto& [from, until] : {std::pair{"-5", "forever"}, std::pair{"0", "9223372036854775806"},
                                    std::pair{"now", "+3000000h"}}) {
    status = run_droverctl({"lock", "bar-3", "--from", from, "--until", until, "--reason", "r", "--timeout", "1"}, out,
                           err);
    ASSERT_TRUE(status.has_value());
    EXPECT_EQ(status->code, 2) << from << " " << until;
    EXPECT_NE(err.find("is outside the shared clock's range"), std::string::npos) << from << " " << until << ": " << err;
  }

  // An empty operation would be sent as NOP: the vehicle would drive there and do nothing.
  status = run_droverctl({"order", "send", "V1", "left-0:", "left-4:unload"}, out, err);
  ASSERT_TRUE(status.has_value());
  EXPECT_EQ(status->code, 2);
  EXPECT_NE(err.find("destination 'left-0:': expected LOCATION:OPERATION"), std::string::npos) << err;

  // A default name <vehicle>-<time> too long for a name: the operator never gave it.
  status = run_droverctl({"order", "send", std::string(250, 'v'), "left-4:NOP"}, out, err);
  ASSERT_TRUE(status.has_value());
  EXPECT_EQ(status->code, 2);
  EXPECT_NE(err.find("the default order name <vehicle>-<time> is"), std::string::npos) << err;
  EXPECT_NE(err.find("give one with --name"), std::string::npos) << err;

  // 0 would mean "until Ctrl-C": a script meant to stop would never end.
  status = run_droverctl({"alarms", "--duration", "0"}, out, err);
  ASSERT_TRUE(status.has_value());
  EXPECT_EQ(status->code, 2);
  EXPECT_NE(err.find("--duration"), std::string::npos) << err;

  // Empty ids would go out as "not given" (any routing agent, the default operator) or ask
  // the network about an entity no topology can have; 0 would be sent as "now".
  const std::vector<std::pair<std::vector<std::string>, std::string>> empty_ids{
      {{"order", "withdraw", "V1", ""}, "order"},
      {{"route", "left-0", "left-4", "--agent", ""}, "--agent"},
      {{"route", "left-0", "left-4", "--for", ""}, "--for"},
      {{"route", "left-0", "left-4", "--vehicle", ""}, "--vehicle"},
      {{"route", "", "left-4"}, "FROM"},
      {{"route", "left-0", "left-4", "--start-time", "0"}, "--start-time"},
      {{"lock", "", "--from", "now", "--until", "forever", "--reason", "r"}, "ENTITY"},
      {{"lock", "bar-3", "--from", "now", "--until", "forever", "--reason", "r", "--operator", ""}, "--operator"},
      {{"release", "", "--from", "V1"}, "ENTITY"},
      {{"timeline", ""}, "ENTITY"},
  };
  for (const auto& [args, option] : empty_ids) {
    status = run_droverctl(args, out, err);
    ASSERT_TRUE(status.has_value());
    EXPECT_EQ(status->code, 2) << args[0] << " " << option << ": " << err;
    EXPECT_NE(err.find(option), std::string::npos) << args[0] << " " << option << ": " << err;
  }
}

}  // namespace
}  // namespace drover::test
