// Heartbeats and the agent directory over real processes, and clean shutdown on signals.

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <iostream>
#include <mutex>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <signal.h>

#include "drover/dds/agent_directory.hpp"
#include "tests/agents/dds_test_support.hpp"

namespace drover::test {
namespace {

using namespace std::chrono_literals;

/// Bound on noticing a killed agent: the heartbeat deadline (2 s) or the participant lease
/// (3 s), whichever ends first, plus slack for a loaded machine.
constexpr std::chrono::milliseconds kDeathBound{8000};

class AgentDirectoryTest : public ::testing::Test {
 protected:
  void TearDown() override { peers_.clear(); }  // kill -9 and reap, whatever happened
  std::vector<ChildProcess> peers_;
};

TEST_F(AgentDirectoryTest, SeesAHeartbeatAndNoticesWhenItsAgentIsKilled) {
  constexpr std::uint32_t kDomain = 20;
  auto peer = spawn_peer(kDomain, "router-1", {"--heartbeat", "routing", "--owns", "zone-a", "--owns", "zone-b"});
  ASSERT_TRUE(peer.has_value());
  peers_.push_back(std::move(*peer));

  auto participant = make_participant(kDomain, "observer");
  ASSERT_NE(participant, nullptr);
  std::vector<dds::AgentRecord> changes;
  std::mutex changes_mutex;
  std::condition_variable changed;
  dds::AgentDirectoryOptions options;
  options.on_change = [&](const dds::AgentRecord& record) {
    std::lock_guard lock(changes_mutex);
    changes.push_back(record);
    changed.notify_all();
  };
  auto directory = dds::AgentDirectory::create(*participant, options);
  ASSERT_TRUE(directory.has_value()) << directory.error().message;

  ASSERT_TRUE((*directory)->wait_for_agent("router-1", true, kDiscoveryTimeout));
  const auto seen = (*directory)->find("router-1");
  ASSERT_TRUE(seen.has_value());
  EXPECT_EQ(seen->kind, "routing");
  EXPECT_EQ(seen->owns, (std::vector<std::string>{"zone-a", "zone-b"}));
  EXPECT_FALSE(seen->version.empty());
  EXPECT_GT(seen->sim_time, 0);
  ASSERT_EQ((*directory)->live_agents().size(), 1u);

  peers_.front().signal(SIGKILL);
  const auto killed_at = std::chrono::steady_clock::now();
  ASSERT_TRUE((*directory)->wait_for_agent("router-1", false, kDeathBound))
      << "still alive " << kDeathBound.count() << " ms after kill -9";
  const auto detection = std::chrono::duration_cast<std::chrono::milliseconds>(
      std::chrono::steady_clock::now() - killed_at);
  const auto dead = (*directory)->find("router-1");
  ASSERT_TRUE(dead.has_value());
  EXPECT_FALSE(dead->alive);
  EXPECT_TRUE(dead->lost_reason == "heartbeat deadline missed" || dead->lost_reason == "participant dropped")
      << dead->lost_reason;
  EXPECT_TRUE((*directory)->live_agents().empty());
  std::cout << "kill -9 noticed after " << detection.count() << " ms (" << dead->lost_reason << ")\n";

  // on_change runs on the directory's notifier thread, which may not have delivered the
  // death yet; resetting the directory would discard it. Waited for, then the notifier
  // is stopped so that `changes` no longer moves.
  {
    std::unique_lock lock(changes_mutex);
    changed.wait_for(lock, kDeathBound, [&] { return !changes.empty() && !changes.back().alive; });
  }
  directory->reset();
  ASSERT_GE(changes.size(), 2u);
  EXPECT_TRUE(changes.front().alive);
  EXPECT_FALSE(changes.back().alive);
}

TEST_F(AgentDirectoryTest, NoticesADroppedParticipantWithoutTheDeadline) {
  constexpr std::uint32_t kDomain = 21;
  auto peer = spawn_peer(kDomain, "logical-9", {"--heartbeat", "logical"});
  ASSERT_TRUE(peer.has_value());
  peers_.push_back(std::move(*peer));
  auto participant = make_participant(kDomain, "observer");
  ASSERT_NE(participant, nullptr);
  // A deadline far beyond the wait below: only the participant's lease (3 s) can tell.
  dds::AgentDirectoryOptions options;
  options.deadline = std::chrono::milliseconds(120000);
  auto directory = dds::AgentDirectory::create(*participant, options);
  ASSERT_TRUE(directory.has_value()) << directory.error().message;
  ASSERT_TRUE((*directory)->wait_for_agent("logical-9", true, kDiscoveryTimeout));

  peers_.front().signal(SIGKILL);
  ASSERT_TRUE((*directory)->wait_for_agent("logical-9", false, kDeathBound));
  EXPECT_EQ((*directory)->find("logical-9")->lost_reason, "participant dropped");
}

TEST_F(AgentDirectoryTest, SeesAnAgentKilledAndRestartedAgainAndAgain) {
  // A crashed agent comes back in a new process at once, while its old participant is
  // still announced (the launcher restarts it so): the new process's heartbeats must reach
  // the directory every time.
  constexpr std::uint32_t kDomain = 22;
  auto participant = make_participant(kDomain, "observer");
  ASSERT_NE(participant, nullptr);
  dds::AgentDirectoryOptions options;
  options.deadline = std::chrono::milliseconds(120000);  // only the participant's drop tells
  auto directory = dds::AgentDirectory::create(*participant, options);
  ASSERT_TRUE(directory.has_value()) << directory.error().message;
  for (int life = 0; life < 6; ++life) {
    // Each life says which it is in what it owns.
    const std::string mark = "life-" + std::to_string(life);
    auto peer = spawn_peer(kDomain, "phoenix", {"--heartbeat", "topology", "--owns", mark});
    ASSERT_TRUE(peer.has_value());
    peers_.push_back(std::move(*peer));
    const bool seen = (*directory)->wait_until(
        [&](const std::vector<dds::AgentRecord>& records) {
          return std::any_of(records.begin(), records.end(), [&](const dds::AgentRecord& r) {
            return r.id == "phoenix" && r.alive && r.owns == std::vector<std::string>{mark};
          });
        },
        kDiscoveryTimeout);
    ASSERT_TRUE(seen) << "life " << life << " of the agent was never seen";
    peers_.back().signal(SIGKILL);
    ASSERT_TRUE(peers_.back().wait_exit(kDiscoveryTimeout).has_value());
  }
}

/// A peer asked to stop by `signal_number` deletes its entities and exits 0; the
/// directory sees its participant leave (removed, not dropped: it said goodbye).
void expect_clean_exit_on(int signal_number, std::uint32_t domain, std::vector<ChildProcess>& peers) {
  auto peer = spawn_peer(domain, "stoppable", {"--echo", "--heartbeat", "topology"});
  ASSERT_TRUE(peer.has_value());
  peers.push_back(std::move(*peer));
  auto participant = make_participant(domain, "observer");
  ASSERT_NE(participant, nullptr);
  dds::AgentDirectoryOptions options;
  options.deadline = std::chrono::milliseconds(120000);  // only the removal can tell
  auto directory = dds::AgentDirectory::create(*participant, options);
  ASSERT_TRUE(directory.has_value()) << directory.error().message;
  // Fully up (handlers installed, entities created) once its heartbeat arrives.
  ASSERT_TRUE((*directory)->wait_for_agent("stoppable", true, kDiscoveryTimeout));

  peers.front().signal(signal_number);
  const auto status = peers.front().wait_exit(kDiscoveryTimeout);
  ASSERT_TRUE(status.has_value()) << "the peer did not exit after signal " << signal_number;
  EXPECT_TRUE(status->exited) << "killed by signal " << status->code;
  EXPECT_EQ(status->code, 0);
  ASSERT_TRUE((*directory)->wait_for_agent("stoppable", false, kDeathBound));
  EXPECT_EQ((*directory)->find("stoppable")->lost_reason, "participant removed");
}

TEST_F(AgentDirectoryTest, SigtermStopsAnAgentCleanlyWithExitCodeZero) {
  expect_clean_exit_on(SIGTERM, 120, peers_);
}

TEST_F(AgentDirectoryTest, SigintStopsAnAgentCleanlyWithExitCodeZero) {
  expect_clean_exit_on(SIGINT, 121, peers_);
}

}  // namespace
}  // namespace drover::test
