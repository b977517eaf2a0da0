// `drover launch` as a process (domains 79, 94..97): it starts the agents of a launch file,
// prefixes their lines with their agent ids, restarts a crashed agent whose entry says so,
// stops on SIGTERM and after --duration with exit 0, exits 1 when an agent failed for good
// and 2 for a bad launch file, before starting anything; its agents never outlive it.

#include <signal.h>

#include <algorithm>
#include <regex>

#include "tests/launcher/launch_test_support.hpp"

namespace drover::test {
namespace {

using namespace std::chrono_literals;

std::string loop_launch(int domain, const std::string& agents) {
  return R"({"name": "loop test", "domain": )" + std::to_string(domain) +
         R"(, "time_factor": 10, "topology": ")" + (source_dir() / "launch/topologies/loop.json").string() +
         R"(", "agents": [)" + agents + "]}";
}

/// The pids of the "started <id>" notes, in order.
std::vector<pid_t> started_pids(const std::string& output, const std::string& id) {
  std::vector<pid_t> pids;
  const std::regex started("\\[launcher\\] started " + id + " \\([a-z-]+, pid ([0-9]+)\\)");
  for (std::sregex_iterator it(output.begin(), output.end(), started), end; it != end; ++it) {
    pids.push_back(static_cast<pid_t>(std::stol((*it)[1].str())));
  }
  return pids;
}

/// `drover launch DIR/fleet.json EXTRA...`, its stdout and stderr in DIR/out.txt and
/// DIR/err.txt.
std::optional<ChildProcess> start_launch(const std::filesystem::path& dir,
                                         const std::vector<std::string>& extra = {}) {
  std::vector<std::string> arguments{"launch", (dir / "fleet.json").string()};
  arguments.insert(arguments.end(), extra.begin(), extra.end());
  return ChildProcess::spawn(binary_path("drover"), arguments, (dir / "out.txt").string(),
                             (dir / "err.txt").string());
}

TEST(LauncherProcess, StartsPrefixesRestartsAndStopsOnSigterm) {
  const auto dir = scratch_dir("launch_restart");
  write_text(dir / "fleet.json", loop_launch(94, R"(
      {"kind": "topology"},
      {"kind": "ran-sim", "vehicle": "V1", "at": "south-west"},
      {"kind": "ran-sim", "vehicle": "V2", "at": "north-east", "restart": "on-failure", "max_restarts": 3})"));
  auto launcher = start_launch(dir);
  ASSERT_TRUE(launcher.has_value());
  const auto err = dir / "err.txt";

  // Every agent's own lines arrive with its id in front.
  ASSERT_TRUE(wait_for_output(err, [](const std::string& text) {
    return text.find("[topology] ") != std::string::npos &&
           text.find("[ran-V1] ") != std::string::npos && text.find("simulated vehicle 'V1'") != std::string::npos &&
           text.find("[ran-V2] ") != std::string::npos && text.find("simulated vehicle 'V2'") != std::string::npos;
  })) << read_file(err.string());
  const auto first = started_pids(read_file(err.string()), "ran-V2");
  ASSERT_EQ(first.size(), 1u);

  // A crash: the launcher starts it again.
  ASSERT_EQ(::kill(first.front(), SIGKILL), 0);
  ASSERT_TRUE(wait_for_output(err, [](const std::string& text) {
    return text.find("[launcher] ran-V2 killed by signal 9 (SIGKILL); restarting (1/3)") != std::string::npos &&
           count_of(text, "simulated vehicle 'V2'") == 2;
  })) << read_file(err.string());
  const auto pids = started_pids(read_file(err.string()), "ran-V2");
  ASSERT_EQ(pids.size(), 2u);
  EXPECT_NE(pids[1], pids[0]);
  // The others were not touched.
  EXPECT_EQ(started_pids(read_file(err.string()), "ran-V1").size(), 1u);

  launcher->signal(SIGTERM);
  const auto status = launcher->wait_exit(60s);
  ASSERT_TRUE(status.has_value()) << "the launcher did not stop";
  EXPECT_TRUE(status->exited);
  EXPECT_EQ(status->code, 0) << read_file(err.string());
  const auto out = read_file((dir / "out.txt").string());
  EXPECT_NE(out.find("stopped on signal SIGTERM"), std::string::npos) << out;
  EXPECT_NE(out.find("agent ran-V2: 1 restart(s); last failure: killed by signal 9 (SIGKILL)"), std::string::npos) << out;
  // Every agent ended with the launcher (reaped by it: no such process any more).
  for (auto pid : started_pids(read_file(err.string()), "[a-zA-Z0-9-]+")) {
    EXPECT_NE(::kill(pid, 0), 0) << "agent pid " << pid << " outlived the launcher";
  }
  EXPECT_NE(read_file(err.string()).find("[ran-V1] "), std::string::npos);
  std::filesystem::remove_all(dir);
}

/// True while `pid` is a process that has not ended (a zombie has ended: when the
/// launcher is gone, whoever adopts its agents may reap them late).
bool running(pid_t pid) {
  const std::string stat = read_file("/proc/" + std::to_string(pid) + "/stat");
  const auto state = stat.rfind(") ");  // the state follows the command name
  return state != std::string::npos && stat.at(state + 2) != 'Z';
}

TEST(LauncherProcess, AgentsEndWhenTheLauncherIsKilled) {
  const auto dir = scratch_dir("launch_killed");
  write_text(dir / "fleet.json", loop_launch(79, R"(
      {"kind": "topology"},
      {"kind": "ran-sim", "vehicle": "V1", "at": "south-west"})"));
  // A killed launcher cannot remove a temporary state directory: it gets one in ours.
  auto launcher = start_launch(dir, {"--state-dir", (dir / "state").string()});
  ASSERT_TRUE(launcher.has_value());
  const auto err = dir / "err.txt";
  ASSERT_TRUE(wait_for_output(err, [](const std::string& text) {
    return text.find("simulated vehicle 'V1'") != std::string::npos &&
           text.find("[topology] ") != std::string::npos;
  })) << read_file(err.string());
  const auto agents = started_pids(read_file(err.string()), "[a-zA-Z0-9-]+");
  ASSERT_EQ(agents.size(), 2u);

  // No chance to stop them in order: each agent gets SIGTERM from the kernel instead.
  launcher->signal(SIGKILL);
  ASSERT_TRUE(launcher->wait_exit(60s).has_value());
  const auto deadline = std::chrono::steady_clock::now() + 60s;
  const auto any_running = [&agents] {
    return std::any_of(agents.begin(), agents.end(), running);
  };
  while (any_running() && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(50ms);
  }
  for (const pid_t pid : agents) {
    EXPECT_FALSE(running(pid)) << "agent pid " << pid << " outlived the killed launcher";
    if (running(pid)) ::kill(pid, SIGKILL);
  }
  std::filesystem::remove_all(dir);
}

TEST(LauncherProcess, StopsAfterDurationAndWritesTheTrace) {
  const auto dir = scratch_dir("launch_duration");
  // A journal in a directory of the state directory: made before anything starts (before,
  // the topology agent failed at its start: "its directory does not exist").
  write_text(dir / "fleet.json", loop_launch(95, R"(
      {"kind": "topology", "db": "journals/loop.db"}, {"kind": "ran-sim", "vehicle": "V1", "at": "south-west"})"));
  // 100 simulated seconds at time factor 10: 10 s for both agents to start, discover each
  // other and trace a status, on a loaded host too.
  // The trace goes into a state directory the launch makes (made before the trace opens).
  const auto state = dir / "run1";
  auto launcher = start_launch(
      dir, {"--duration", "100", "--state-dir", state.string(), "--trace", (state / "trace.jsonl").string()});
  ASSERT_TRUE(launcher.has_value());
  const auto status = launcher->wait_exit(120s);
  ASSERT_TRUE(status.has_value()) << "the launcher did not stop after --duration";
  EXPECT_TRUE(status->exited);
  EXPECT_EQ(status->code, 0) << read_file((dir / "err.txt").string());
  const auto out = read_file((dir / "out.txt").string());
  EXPECT_NE(out.find("summary of loop test"), std::string::npos) << out;
  EXPECT_NE(out.find("stopped on --duration 100 s"), std::string::npos) << out;
  const auto trace = read_file((state / "trace.jsonl").string());
  EXPECT_EQ(trace.rfind("{\"t\":", 0), 0u) << trace.substr(0, 200);
  EXPECT_NE(trace.find("\"type\":\"launch\""), std::string::npos);
  EXPECT_NE(trace.find("\"type\":\"ran_status\""), std::string::npos) << trace.substr(0, 400);
  EXPECT_NE(trace.find("\"vehicle\":\"V1\""), std::string::npos);
  EXPECT_NE(trace.find("\"footprint\":[["), std::string::npos);
  EXPECT_TRUE(std::filesystem::is_regular_file(state / "journals" / "loop.db"));
  std::filesystem::remove_all(dir);
}

TEST(LauncherProcess, AgentFailingForGoodMakesExitOne) {
  const auto dir = scratch_dir("launch_failure");
  // The journal is a directory: the topology agent exits 1, and is not restarted.
  write_text(dir / "fleet.json", loop_launch(96, R"(
      {"kind": "topology", "db": ")" + dir.string() + R"("},
      {"kind": "ran-sim", "vehicle": "V1", "at": "south-west"})"));
  auto launcher = start_launch(dir, {"--duration", "30"});
  ASSERT_TRUE(launcher.has_value());
  const auto status = launcher->wait_exit(120s);
  ASSERT_TRUE(status.has_value());
  EXPECT_TRUE(status->exited);
  EXPECT_EQ(status->code, 1);
  const auto err = read_file((dir / "err.txt").string());
  EXPECT_NE(err.find("[topology] error: "), std::string::npos) << err;
  EXPECT_NE(err.find("[launcher] topology exited with code 1; not restarted"), std::string::npos) << err;
  EXPECT_NE(read_file((dir / "out.txt").string()).find("agent topology: 0 restart(s), FAILED; last failure: exited with code 1"), std::string::npos);
  std::filesystem::remove_all(dir);
}

TEST(LauncherProcess, BadLaunchFileStartsNothing) {
  const auto dir = scratch_dir("launch_bad");
  write_text(dir / "fleet.json", loop_launch(97, R"(
      {"kind": "topology"}, {"kind": "ran-sim", "vehicle": "V1", "at": "atlantis"})"));
  // A state directory that does not exist yet is not made for a launch that never starts.
  const auto state = dir / "state";
  auto launcher = start_launch(dir, {"--state-dir", state.string()});
  ASSERT_TRUE(launcher.has_value());
  const auto status = launcher->wait_exit(60s);
  ASSERT_TRUE(status.has_value());
  EXPECT_TRUE(status->exited);
  EXPECT_EQ(status->code, 2);
  const auto err = read_file((dir / "err.txt").string());
  EXPECT_NE(err.find("fleet.json:agents[1].at: 'atlantis' is not a vertex of"), std::string::npos) << err;
  EXPECT_EQ(err.find("started"), std::string::npos) << err;
  EXPECT_FALSE(std::filesystem::exists(state));

  // A journal directory that cannot be made (its parent is a file): refused before any
  // agent starts, not an agent failing at its start beside others that run.
  write_text(dir / "fleet.json", loop_launch(97, R"(
      {"kind": "routing"}, {"kind": "topology", "db": ")" + (dir / "fleet.json" / "j" / "loop.db").string() + R"("})"));
  auto second = start_launch(dir);
  ASSERT_TRUE(second.has_value());
  const auto refused = second->wait_exit(60s);
  ASSERT_TRUE(refused.has_value());
  EXPECT_TRUE(refused->exited);
  EXPECT_EQ(refused->code, 2);
  const auto why = read_file((dir / "err.txt").string());
  EXPECT_NE(why.find("error: agent 'topology': cannot create directory " + (dir / "fleet.json" / "j").string()),
            std::string::npos)
      << why;
  EXPECT_NE(why.find("(nothing started)"), std::string::npos) << why;
  EXPECT_EQ(why.find("started routing"), std::string::npos) << why;
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace drover::test
