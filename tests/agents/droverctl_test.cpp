// `droverctl agents` as an operator runs it: a separate process against live agents.

#include <chrono>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "drover/dds/agent_directory.hpp"
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
}

}  // namespace
}  // namespace drover::test
