// droverctl lock / unlock / timeline run as processes against a real topology agent
// (`drover topology-agent`), domains 61..65. A lock that hits a committed reservation
// makes the agent send its owner NOTICE_LOCK_HIT over DDS, seen by this test's reader.

#include <signal.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "agents/topology_agent/topology_agent.hpp"
#include "agents/topology_agent/wire.hpp"
#include "drover/dds/reader.hpp"
#include "drover/dds/service_client.hpp"
#include "tests/agents/dds_test_support.hpp"

namespace drover::test {
namespace {

using namespace std::chrono_literals;

constexpr const char* kTopology = R"({
  "name": "pair",
  "vertices": [{"id": "a", "x": 0, "y": 0}, {"id": "b", "x": 3, "y": 0}],
  "edges": [{"id": "a-b", "from": "a", "to": "b", "bidirectional": true, "max_speed": 1.0,
             "footprint": [[0, -0.7], [3, -0.7], [3, 0.7], [0, 0.7]]}]
})";

class DroverctlTopologyTest : public ::testing::Test {
 protected:
  void SetUp() override {
    topology_file_ = ::testing::TempDir() + "droverctl-topology-" + std::to_string(::getpid()) + ".json";
    std::ofstream(topology_file_) << kTopology;
  }
  void TearDown() override {
    if (agent_) {
      agent_->signal(SIGTERM);
      auto status = agent_->wait_exit(kDiscoveryTimeout);
      ASSERT_TRUE(status.has_value());
      EXPECT_EQ(status->code, 0);
    }
    readers_.clear();
    participant_.reset();
    std::filesystem::remove(topology_file_);
  }

  void start_agent(std::uint32_t domain) {
    auto agent = ChildProcess::spawn(binary_path("drover"), {"topology-agent", "--topology", topology_file_,
                                                             "--domain", std::to_string(domain)});
    ASSERT_TRUE(agent.has_value());
    agent_.emplace(std::move(*agent));
  }

  /// Runs droverctl to its end. \return its exit code (-1 if it did not end); output in out/err.
  int droverctl(const std::vector<std::string>& args, std::string& out, std::string& err) {
    const std::string stem = ::testing::TempDir() + "droverctl_topology_" +
                             ::testing::UnitTest::GetInstance()->current_test_info()->name();
    auto child = ChildProcess::spawn(binary_path("droverctl"), args, stem + ".out", stem + ".err");
    if (!child) return -1;
    auto status = child->wait_exit(60s);
    out = read_file(stem + ".out");
    err = read_file(stem + ".err");
    return status && status->exited ? status->code : -1;
  }

  std::string topology_file_;
  std::optional<ChildProcess> agent_;
  std::unique_ptr<dds::Participant> participant_;
  std::vector<std::shared_ptr<void>> readers_;
};

TEST_F(DroverctlTopologyTest, LockHitsAReservationAndNotifiesItsOwnerTimelineShowsItUnlockRemovesIt) {
  constexpr std::uint32_t kDomain = 61;
  start_agent(kDomain);
  participant_ = make_participant(kDomain, "v1");
  ASSERT_NE(participant_, nullptr);
  std::mutex mutex;
  std::condition_variable changed;
  std::vector<msg::ReservationNotice> notices;
  auto reader = dds::Reader<msg::ReservationNotice>::create(
      *participant_, topology_agent::kNoticeTopic,
      [&](const msg::ReservationNotice& notice) {
        std::lock_guard lock(mutex);
        notices.push_back(notice);
        changed.notify_all();
      },
      dds::ReaderOptions{dds::TopicQos::events(), "agent = %0", {"'v1'"}});
  ASSERT_TRUE(reader.has_value());
  ASSERT_TRUE((*reader)->wait_for_writers(1, kDiscoveryTimeout));
  auto prepare = dds::ServiceClient<msg::ReservePrepareRequest, msg::ReservePrepareReply>::create(
      *participant_, "topology", "reserve_prepare");
  auto commit = dds::ServiceClient<msg::ReserveCommitRequest, msg::StatusReply>::create(*participant_, "topology",
                                                                                      "reserve_commit");
  ASSERT_TRUE(prepare && commit);

  // Our reader matching the agent's notice writer does not mean the writer matched our
  // reader, and a notice written in between is lost: holds of v1 on b, far in the future and
  // expiring at once (each a window and route of its own), until a NOTICE_PREPARE_EXPIRED
  // reaches v1.
  const auto probe_expired = [&] {
    return std::any_of(notices.begin(), notices.end(),
                       [](const msg::ReservationNotice& n) { return n.kind() == msg::NOTICE_PREPARE_EXPIRED; });
  };
  bool delivered = false;
  for (std::uint64_t probe = 100; probe < 120 && !delivered; ++probe) {
    msg::ReservePrepareRequest hold;
    hold.agent("v1");
    hold.route(probe);
    for (const char* entity : {"b", "a-b"}) {  // b and its shadow on a-b, as for a below
      msg::Reservation item;
      item.agent("v1");
      item.route(probe);
      item.step(0);
      item.entity(entity);
      item.origin("b");
      item.window().start(seconds_to_ns(1e6) + static_cast<TimeNs>(probe) * 10);
      item.window().end(item.window().start() + 1);
      hold.items().push_back(item);
    }
    hold.expires_at(SharedClock::wall().now());
    auto held = (*prepare)->call(hold, kDiscoveryTimeout);
    ASSERT_TRUE(held.has_value()) << held.error().message;
    ASSERT_EQ(held->error().code(), msg::ERROR_NONE) << held->error().message();
    std::unique_lock lock(mutex);
    delivered = changed.wait_for(lock, 1s, probe_expired);
  }
  ASSERT_TRUE(delivered) << "no reservation notice reached v1";
  {
    std::lock_guard lock(mutex);
    notices.clear();
  }

  // v1 reserves a during [1000, 5000) (with its shadow on a-b).
  msg::ReservePrepareRequest request;
  request.agent("v1");
  request.route(3);
  for (const char* entity : {"a", "a-b"}) {
    msg::Reservation item;
    item.agent("v1");
    item.route(3);
    item.step(0);
    item.entity(entity);
    item.origin("a");
    item.window().start(1000);
    item.window().end(5000);
    request.items().push_back(item);
  }
  request.expires_at(SharedClock::wall().now() + seconds_to_ns(600));
  auto prepared = (*prepare)->call(request, kDiscoveryTimeout);
  ASSERT_TRUE(prepared.has_value());
  ASSERT_EQ(prepared->error().code(), msg::ERROR_NONE) << prepared->error().message();
  msg::ReserveCommitRequest commit_request;
  commit_request.prepare_id(prepared->prepare_id());
  auto committed = (*commit)->call(commit_request, kDiscoveryTimeout);
  ASSERT_TRUE(committed.has_value());
  ASSERT_EQ(committed->error().code(), msg::ERROR_NONE) << committed->error().message();

  std::string out, err;
  const std::string domain = std::to_string(kDomain);
  ASSERT_EQ(droverctl({"lock", "a", "--from", "4000", "--until", "forever", "--reason", "broken floor plate",
                       "--operator", "op-7", "--domain", domain, "--timeout", "20"},
                      out, err),
            0)
      << err;
  EXPECT_EQ(out.substr(0, out.find('\n')), "topology/1");
  EXPECT_NE(out.find("hit: v1 route 3 step 0 on a [1000, 5000)"), std::string::npos) << out;

  {
    std::unique_lock lock(mutex);
    EXPECT_TRUE(changed.wait_for(lock, kDiscoveryTimeout, [&] {
      for (const auto& notice : notices) {
        if (notice.kind() == msg::NOTICE_LOCK_HIT && notice.lock_id() == "topology/1" && notice.route() == 3 &&
            notice.entity() == "a" && notice.window().start() == 1000) {
          return true;
        }
      }
      return false;
    })) << "v1 is told that the lock hit its reservation on a";
  }

  ASSERT_EQ(droverctl({"timeline", "a", "--json", "--domain", domain, "--timeout", "20"}, out, err), 0) << err;
  const auto timeline = nlohmann::json::parse(out);
  EXPECT_EQ(timeline["entity"], "a");
  ASSERT_EQ(timeline["reservations"].size(), 1u);
  EXPECT_EQ(timeline["reservations"][0]["agent"], "v1");
  EXPECT_EQ(timeline["reservations"][0]["start_ns"], 1000);
  ASSERT_EQ(timeline["locks"].size(), 1u);
  EXPECT_EQ(timeline["locks"][0]["id"], "topology/1");
  EXPECT_EQ(timeline["locks"][0]["operator"], "op-7");
  EXPECT_EQ(timeline["locks"][0]["reason"], "broken floor plate");
  EXPECT_EQ(timeline["locks"][0]["end_ns"], kForever);
  EXPECT_TRUE(timeline["holder"].is_null());

  ASSERT_EQ(droverctl({"timeline", "a", "--domain", domain, "--timeout", "20"}, out, err), 0) << err;
  EXPECT_NE(out.find("topology/1  [4000, forever)  by op-7: broken floor plate"), std::string::npos) << out;

  ASSERT_EQ(droverctl({"unlock", "topology/1", "--domain", domain, "--timeout", "20"}, out, err), 0) << err;
  // Unlocking it again: the agent refuses (exit 1) and says why.
  EXPECT_EQ(droverctl({"unlock", "topology/1", "--domain", domain, "--timeout", "20"}, out, err), 1);
  EXPECT_NE(err.find("unknown lock 'topology/1'"), std::string::npos) << err;
  ASSERT_EQ(droverctl({"timeline", "a", "--json", "--domain", domain, "--timeout", "20"}, out, err), 0) << err;
  EXPECT_TRUE(nlohmann::json::parse(out)["locks"].empty()) << out;
}

TEST_F(DroverctlTopologyTest, BadInputIsExit2AndNoAgentIsExit3) {
  constexpr std::uint32_t kDomain = 62;
  start_agent(kDomain);
  const std::string domain = std::to_string(kDomain);
  std::string out, err;
  EXPECT_EQ(droverctl({"lock", "a", "--from", "+x", "--until", "+30s", "--reason", "r", "--domain", domain}, out, err),
            2);
  EXPECT_NE(err.find("--from: '+x' is not a time"), std::string::npos) << err;
  // Checked once the agent told what `a` is: a generous timeout for it to come up.
  EXPECT_EQ(droverctl({"lock", "a", "--from", "10", "--until", "2", "--reason", "r", "--domain", domain, "--timeout",
                       "20"},
                      out, err),
            2);
  // Times in the wrong order are refused before any agent is asked (domain 63 has none)
  // where the order does not depend on the owner's clock.
  EXPECT_EQ(droverctl({"lock", "a", "--from", "10", "--until", "2", "--reason", "r", "--domain", "63", "--timeout",
                       "1"},
                      out, err),
            2);
  EXPECT_NE(err.find("--from 10 is not before --until 2"), std::string::npos) << err;
  EXPECT_EQ(droverctl({"lock", "a", "--from", "+1m", "--until", "+30s", "--reason", "r", "--domain", "63",
                       "--timeout", "1"},
                      out, err),
            2);
  EXPECT_NE(err.find("--from +1m is not before --until +30s"), std::string::npos) << err;
  EXPECT_EQ(droverctl({"lock", "a", "--from", "1", "--until", "2", "--domain", domain}, out, err), 2)
      << "--reason is required";
  EXPECT_EQ(droverctl({"lock", "nowhere", "--from", "1", "--until", "2", "--reason", "r", "--domain", domain,
                       "--timeout", "20"},
                      out, err),
            2);
  EXPECT_NE(err.find("unknown entity 'nowhere'"), std::string::npos) << err;
  EXPECT_EQ(droverctl({"unlock", "garbage", "--domain", domain}, out, err), 2);
  EXPECT_EQ(droverctl({"timeline", "a", "--domain", "63", "--timeout", "1"}, out, err), 3);
  EXPECT_NE(err.find("no topology agent answered on domain 63"), std::string::npos) << err;
  EXPECT_EQ(droverctl({"unlock", "topology/1", "--domain", "63", "--timeout", "1"}, out, err), 3);
  EXPECT_EQ(droverctl({"lock", "a", "--from", "now", "--until", "+1m", "--reason", "r", "--domain", "63",
                       "--timeout", "1"},
                      out, err),
            3);
  EXPECT_EQ(droverctl({"release", "a", "--domain", domain}, out, err), 2) << "--from is required";
  EXPECT_EQ(droverctl({"release", "nowhere", "--from", "v1", "--domain", domain, "--timeout", "20"}, out, err), 2);
  EXPECT_NE(err.find("unknown entity 'nowhere'"), std::string::npos) << err;
  EXPECT_EQ(droverctl({"release", "a", "--from", "v1", "--domain", domain, "--timeout", "20"}, out, err), 1);
  EXPECT_NE(err.find("'v1' does not hold 'a'"), std::string::npos) << err;
  EXPECT_EQ(droverctl({"release", "a", "--from", "v1", "--domain", "63", "--timeout", "1"}, out, err), 3);
  EXPECT_EQ(droverctl({"timeline", "--help"}, out, err), 0);
  EXPECT_NE(out.find("--domain"), std::string::npos);
}

}  // namespace
}  // namespace drover::test
