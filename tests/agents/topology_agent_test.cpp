// The topology agent as a process (`drover topology-agent`): the test process is its
// client over DDS. Domains 39, 60, 66..68 and 70..78. Every agent is stopped with SIGTERM and must exit 0.

#include <signal.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <filesystem>
#include <fstream>
#include <future>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "agents/topology_agent/topology_agent.hpp"
#include "agents/logical_agent/src/topology_services.hpp"
#include "agents/topology_agent/wire.hpp"
#include "drover/dds/heartbeat_publisher.hpp"
#include "drover/dds/reader.hpp"
#include "drover/dds/service_client.hpp"
#include "drover/topology/topology_file.hpp"
#include "tests/agents/dds_test_support.hpp"

namespace drover::test {
namespace {

using namespace std::chrono_literals;

// A line a - b - c - d; a, b and their edges are partition west, c, d and c-d east. The
// edges' footprints are given and run from vertex to vertex, so they overlap the (generated)
// footprints of their end vertices: a reservation on a vertex shadows its edges and back
// (generated edge footprints would stop short of the vertices and conflict with nothing).
constexpr const char* kLineTopology = R"({
  "name": "line",
  "vertices": [
    {"id": "a", "x": 0, "y": 0, "partition": "west"},
    {"id": "b", "x": 3, "y": 0, "partition": "west"},
    {"id": "c", "x": 6, "y": 0, "partition": "east"},
    {"id": "d", "x": 9, "y": 0, "partition": "east"}
  ],
  "edges": [
    {"id": "a-b", "from": "a", "to": "b", "bidirectional": true, "max_speed": 1.0, "footprint": [[0, -0.7], [3, -0.7], [3, 0.7], [0, 0.7]],
     "partition": "west"},
    {"id": "b-c", "from": "b", "to": "c", "bidirectional": true, "max_speed": 1.0, "footprint": [[3, -0.7], [6, -0.7], [6, 0.7], [3, 0.7]],
     "partition": "west"},
    {"id": "c-d", "from": "c", "to": "d", "bidirectional": true, "max_speed": 1.0, "footprint": [[6, -0.7], [9, -0.7], [9, 0.7], [6, 0.7]],
     "partition": "east"}
  ]
})";

std::string write_topology_file() {
  const auto path = std::filesystem::temp_directory_path() /
                    ("drover-topology-agent-test-" + std::to_string(::getpid()) + ".json");
  std::ofstream(path) << kLineTopology;
  return path.string();
}

template <class Req, class Rep>
using Client = std::unique_ptr<dds::ServiceClient<Req, Rep>>;

template <class Req, class Rep>
Client<Req, Rep> make_client(dds::Participant& participant, const char* service) {
  auto client = dds::ServiceClient<Req, Rep>::create(participant, "topology", service);
  EXPECT_TRUE(client.has_value()) << (client ? "" : client.error().message);
  return client ? std::move(*client) : nullptr;
}

/// The test's side: a participant with a client of every service and readers of the
/// timelines, descriptions and notices the agents publish.
class TopologyAgentTest : public ::testing::Test {
 protected:
  void SetUp() override {
    topology_file_ = write_topology_file();
    auto loaded = topology::load_topology_file(topology_file_);
    ASSERT_TRUE(loaded.has_value());
    topology_.emplace(std::move(*loaded));
  }

  void TearDown() override {
    for (auto& agent : agents_) {
      agent.signal(SIGTERM);
      auto status = agent.wait_exit(kDiscoveryTimeout);
      ASSERT_TRUE(status.has_value()) << "the agent did not stop on SIGTERM";
      EXPECT_TRUE(status->exited) << "killed by signal " << status->code;
      EXPECT_EQ(status->code, 0);
    }
    readers_.clear();
    prepare_.reset();
    commit_.reset();
    abort_.reset();
    allocate_.reset();
    release_.reset();
    lock_.reset();
    unlock_.reset();
    delay_.reset();
    cancel_.reset();
    holdings_.reset();
    participant_.reset();
    agents_.clear();
    std::filesystem::remove(topology_file_);
  }

  void start_agent(std::uint32_t domain, const std::vector<std::string>& extra = {}) {
    std::vector<std::string> args{"topology-agent", "--topology", topology_file_, "--domain",
                                  std::to_string(domain)};
    args.insert(args.end(), extra.begin(), extra.end());
    auto agent = ChildProcess::spawn(binary_path("drover"), args);
    ASSERT_TRUE(agent.has_value());
    agents_.push_back(std::move(*agent));
  }

  void connect(std::uint32_t domain) {
    participant_ = make_participant(domain, "tester");
    ASSERT_NE(participant_, nullptr);
    prepare_ = make_client<msg::ReservePrepareRequest, msg::ReservePrepareReply>(*participant_, "reserve_prepare");
    commit_ = make_client<msg::ReserveCommitRequest, msg::StatusReply>(*participant_, "reserve_commit");
    abort_ = make_client<msg::ReserveAbortRequest, msg::StatusReply>(*participant_, "reserve_abort");
    allocate_ = make_client<msg::AllocateRequest, msg::AllocateReply>(*participant_, "allocate");
    release_ = make_client<msg::ReleaseRequest, msg::StatusReply>(*participant_, "release");
    lock_ = make_client<msg::LockRequest, msg::LockReply>(*participant_, "lock");
    unlock_ = make_client<msg::UnlockRequest, msg::StatusReply>(*participant_, "unlock");
    delay_ = make_client<msg::DelayRequest, msg::DelayReply>(*participant_, "delay");
    cancel_ = make_client<msg::CancelRouteRequest, msg::StatusReply>(*participant_, "cancel_route");
    holdings_ = make_client<msg::HoldingsRequest, msg::HoldingsReply>(*participant_, "holdings");
    auto timelines = dds::Reader<msg::TimelineState>::create(
        *participant_, topology_agent::kTimelineTopic, [this](const msg::TimelineState& state) {
          std::lock_guard lock(mutex_);
          timelines_[state.entity()] = state;
          changed_.notify_all();
        });
    ASSERT_TRUE(timelines.has_value());
    auto descriptions = dds::Reader<msg::EntityDescription>::create(
        *participant_, topology_agent::kEntityTopic, [this](const msg::EntityDescription& description) {
          std::lock_guard lock(mutex_);
          descriptions_[description.id()] = description;
          changed_.notify_all();
        });
    ASSERT_TRUE(descriptions.has_value());
    auto notices = dds::Reader<msg::ReservationNotice>::create(
        *participant_, topology_agent::kNoticeTopic,
        [this](const msg::ReservationNotice& notice) {
          std::lock_guard lock(mutex_);
          notices_.push_back(notice);
          changed_.notify_all();
        },
        dds::ReaderOptions{dds::TopicQos::events(), {}, {}});
    ASSERT_TRUE(notices.has_value());
    // Notices and events are VOLATILE: what is sent before a reader matched is not seen.
    ASSERT_TRUE((*notices)->wait_for_writers(agents_.size(), kDiscoveryTimeout));
    readers_.push_back(std::shared_ptr<void>(std::move(*timelines)));
    readers_.push_back(std::shared_ptr<void>(std::move(*descriptions)));
    readers_.push_back(std::shared_ptr<void>(std::move(*notices)));
    auto events = dds::Reader<msg::TopologyEvent>::create(
        *participant_, topology_agent::kEventTopic,
        [this](const msg::TopologyEvent& event) {
          std::lock_guard lock(mutex_);
          events_.push_back(event);
          changed_.notify_all();
        },
        dds::ReaderOptions{dds::TopicQos::events(), {}, {}});
    ASSERT_TRUE(events.has_value());
    ASSERT_TRUE((*events)->wait_for_writers(agents_.size(), kDiscoveryTimeout));
    readers_.push_back(std::shared_ptr<void>(std::move(*events)));
  }

  /// Waits until the agent's event writer delivers to this tester, then forgets what it
  /// delivered. Our reader matching the writer does not mean the writer matched our reader
  /// yet, and a VOLATILE sample written in between is lost to us: so lock `entity` (over
  /// [0, 1)) until an event arrives, and unlock it again.
  void wait_for_event_delivery(const std::string& entity) {
    std::vector<std::string> locks;
    bool delivered = false;
    for (int attempt = 0; attempt < 20 && !delivered; ++attempt) {
      locks.push_back(lock(entity, 0, 1).lock_id());
      std::unique_lock guard(mutex_);
      delivered = changed_.wait_for(guard, 1s, [&] { return !events_.empty(); });
    }
    ASSERT_TRUE(delivered) << "no topology event reached the tester";
    for (const auto& id : locks) EXPECT_EQ(unlock(id).error().code(), msg::ERROR_NONE);
    ASSERT_TRUE(wait_until([&] {
      return std::count_if(events_.begin(), events_.end(),
                           [](const msg::TopologyEvent& e) { return e.kind() == msg::EVENT_UNLOCKED; }) ==
             static_cast<std::ptrdiff_t>(locks.size());
    }));
    std::lock_guard guard(mutex_);
    events_.clear();
  }

  /// Waits until the agent's notice writer delivers to this tester, then forgets what it
  /// delivered: holds of agent "probe" on `entity`, far in the future, that expire at once
  /// (the agent expires holds every 100 ms), until a NOTICE_PREPARE_EXPIRED arrives. For
  /// tests that assert notices and no events (the probe's own events may still arrive).
  void wait_for_notice_delivery(const std::string& entity) {
    constexpr TimeNs kFar = seconds_to_ns(1e6);
    const auto expired = [&](topology::RouteId route) {
      return std::any_of(notices_.begin(), notices_.end(), [&](const msg::ReservationNotice& notice) {
        return notice.agent() == "probe" && notice.kind() == msg::NOTICE_PREPARE_EXPIRED && notice.route() == route;
      });
    };
    bool delivered = false;
    for (topology::RouteId route = 1; route <= 20 && !delivered; ++route) {
      // Each probe a window of its own: a hold whose notice was lost never refuses the next.
      const TimeNs start = kFar + static_cast<TimeNs>(route) * 10;
      auto prepared = prepare_->call(
          prepare_request("probe", route, items("probe", route, {{entity, {start, start + 1}}}), {},
                          SharedClock::wall().now()),
          kDiscoveryTimeout);
      ASSERT_TRUE(prepared.has_value()) << prepared.error().message;
      ASSERT_EQ(prepared->error().code(), msg::ERROR_NONE) << prepared->error().message();
      std::unique_lock guard(mutex_);
      delivered = changed_.wait_for(guard, 1s, [&] { return expired(route); });
    }
    ASSERT_TRUE(delivered) << "no reservation notice reached the tester";
    std::lock_guard guard(mutex_);
    notices_.clear();
  }

  /// Waits until `condition` (called with the mutex held) holds. \return whether it did.
  template <class Condition>
  bool wait_until(Condition condition) {
    std::unique_lock lock(mutex_);
    return changed_.wait_for(lock, kDiscoveryTimeout, [&] { return condition(); });
  }

  /// The last published timeline of `entity` (waits for one).
  msg::TimelineState timeline(const std::string& entity) {
    EXPECT_TRUE(wait_until([&] { return timelines_.count(entity) > 0; })) << "no timeline of " << entity;
    std::lock_guard lock(mutex_);
    return timelines_[entity];
  }

  /// Waits until the timeline of `entity` reaches `version` at least.
  msg::TimelineState timeline_at(const std::string& entity, std::uint64_t version) {
    EXPECT_TRUE(wait_until([&] { return timelines_.count(entity) > 0 && timelines_[entity].version() >= version; }))
        << "timeline of " << entity << " never reached version " << version;
    std::lock_guard lock(mutex_);
    return timelines_[entity];
  }

  /// The wire items a route of `agent` writes (real and shadow) on the entities of
  /// `partition` (empty: all), as a routing agent splits them by owner.
  std::vector<msg::Reservation> items(const std::string& agent, topology::RouteId route,
                                      const std::vector<std::pair<std::string, topology::Interval>>& steps,
                                      const std::string& partition = {}) {
    std::vector<topology::RouteStep> route_steps;
    for (const auto& [id, window] : steps) route_steps.push_back({*topology_->find(id), window});
    const topology::TimelineSet expander(topology_->conflict_sets());
    std::vector<msg::Reservation> out;
    for (const auto& item : expander.expand(agent, route, route_steps)) {
      if (partition.empty() || topology_->partition(item.entity) == partition) {
        out.push_back(topology_agent::to_wire(*topology_, item));
      }
    }
    return out;
  }

  msg::ReservePrepareRequest prepare_request(const std::string& agent, topology::RouteId route,
                                             std::vector<msg::Reservation> route_items,
                                             std::vector<std::pair<std::string, std::uint64_t>> expected = {},
                                             TimeNs expires_at = SharedClock::wall().now() + seconds_to_ns(600)) {
    msg::ReservePrepareRequest request;
    request.agent(agent);
    request.route(route);
    request.items(std::move(route_items));
    for (const auto& [entity, version] : expected) {
      msg::EntityVersion entry;
      entry.entity(entity);
      entry.version(version);
      request.expected().push_back(entry);
    }
    request.expires_at(expires_at);
    return request;
  }

  /// Prepares and commits a route; fails the test when either is refused.
  void reserve(const std::string& agent, topology::RouteId route,
               const std::vector<std::pair<std::string, topology::Interval>>& steps,
               const std::string& responder = {}, const std::string& partition = {}) {
    auto prepared = prepare_->call(prepare_request(agent, route, items(agent, route, steps, partition)),
                                   kDiscoveryTimeout, responder);
    ASSERT_TRUE(prepared.has_value()) << prepared.error().message;
    ASSERT_EQ(prepared->error().code(), msg::ERROR_NONE) << prepared->error().message();
    msg::ReserveCommitRequest commit;
    commit.prepare_id(prepared->prepare_id());
    auto committed = commit_->call(commit, kDiscoveryTimeout, responder);
    ASSERT_TRUE(committed.has_value()) << committed.error().message;
    ASSERT_EQ(committed->error().code(), msg::ERROR_NONE) << committed->error().message();
  }

  msg::AllocateReply allocate(const std::string& agent, const std::string& entity, bool wait) {
    msg::AllocateRequest request;
    request.agent(agent);
    request.entity(entity);
    request.wait(wait);
    auto reply = allocate_->call(request, kDiscoveryTimeout);
    EXPECT_TRUE(reply.has_value()) << reply.error().message;
    return reply ? *reply : msg::AllocateReply{};
  }

  msg::LockReply lock(const std::string& entity, TimeNs start, TimeNs end, const std::string& responder = {}) {
    msg::LockRequest request;
    request.entity(entity);
    request.window().start(start);
    request.window().end(end);
    request.operator_id("operator-1");
    request.reason("spilled oil");
    auto reply = lock_->call(request, kDiscoveryTimeout, responder);
    EXPECT_TRUE(reply.has_value()) << reply.error().message;
    return reply ? *reply : msg::LockReply{};
  }

  msg::StatusReply unlock(const std::string& lock_id) {
    msg::UnlockRequest request;
    request.lock_id(lock_id);
    auto reply = unlock_->call(request, kDiscoveryTimeout);
    EXPECT_TRUE(reply.has_value()) << reply.error().message;
    return reply ? *reply : msg::StatusReply{};
  }

  msg::StatusReply release(const std::string& agent, const std::string& entity) {
    msg::ReleaseRequest request;
    request.agent(agent);
    request.entity(entity);
    auto reply = release_->call(request, kDiscoveryTimeout);
    EXPECT_TRUE(reply.has_value()) << reply.error().message;
    return reply ? *reply : msg::StatusReply{};
  }

  std::string topology_file_;
  std::optional<topology::Topology> topology_;
  std::vector<ChildProcess> agents_;
  std::unique_ptr<dds::Participant> participant_;
  Client<msg::ReservePrepareRequest, msg::ReservePrepareReply> prepare_;
  Client<msg::ReserveCommitRequest, msg::StatusReply> commit_;
  Client<msg::ReserveAbortRequest, msg::StatusReply> abort_;
  Client<msg::AllocateRequest, msg::AllocateReply> allocate_;
  Client<msg::ReleaseRequest, msg::StatusReply> release_;
  Client<msg::LockRequest, msg::LockReply> lock_;
  Client<msg::UnlockRequest, msg::StatusReply> unlock_;
  Client<msg::DelayRequest, msg::DelayReply> delay_;
  Client<msg::CancelRouteRequest, msg::StatusReply> cancel_;
  Client<msg::HoldingsRequest, msg::HoldingsReply> holdings_;
  std::vector<std::shared_ptr<void>> readers_;

  std::mutex mutex_;
  std::condition_variable changed_;
  std::map<std::string, msg::TimelineState> timelines_;
  std::map<std::string, msg::EntityDescription> descriptions_;
  std::vector<msg::ReservationNotice> notices_;
  std::vector<msg::TopologyEvent> events_;
};

TEST_F(TopologyAgentTest, CommittedReservationShowsOnTheTimelineAndAConflictingPrepareChangesNothing) {
  start_agent(70);
  connect(70);
  ASSERT_EQ(timeline("a").version(), 0u);

  reserve("v1", 1, {{"a", {1000, 2000}}});
  const auto after_commit = timeline_at("a", 2);  // prepare and commit each change it
  ASSERT_EQ(after_commit.reservations().size(), 1u);
  EXPECT_EQ(after_commit.reservations()[0].agent(), "v1");
  EXPECT_EQ(after_commit.reservations()[0].window().start(), 1000);
  EXPECT_FALSE(after_commit.reservations()[0].prepared());
  // The footprint of edge a-b overlaps vertex a: the reservation shadows it.
  const auto shadowed = timeline_at("a-b", 2);
  ASSERT_EQ(shadowed.reservations().size(), 1u);
  EXPECT_EQ(shadowed.reservations()[0].agent(), "v1");
  EXPECT_EQ(shadowed.reservations()[0].origin(), "a");
  EXPECT_EQ(shadowed.reservations()[0].entity(), "a-b");
  EXPECT_EQ(shadowed.reservations()[0].window().start(), 1000);
  EXPECT_EQ(shadowed.reservations()[0].window().end(), 2000);
  EXPECT_FALSE(shadowed.reservations()[0].prepared());

  // Another agent overlapping v1: conflict. A plan made on an old version: conflict.
  auto rejected = prepare_->call(prepare_request("v2", 7, items("v2", 7, {{"a", {1500, 2500}}})), kDiscoveryTimeout);
  ASSERT_TRUE(rejected.has_value());
  EXPECT_EQ(rejected->error().code(), msg::ERROR_CONFLICT) << rejected->error().message();
  auto stale = prepare_->call(prepare_request("v2", 7, items("v2", 7, {{"a", {5000, 6000}}}), {{"a", 1}}),
                              kDiscoveryTimeout);
  ASSERT_TRUE(stale.has_value());
  EXPECT_EQ(stale->error().code(), msg::ERROR_CONFLICT) << stale->error().message();

  // A later change on d is published after anything the rejected calls could have sent.
  reserve("v3", 1, {{"d", {0, 10}}});
  timeline_at("d", 2);
  EXPECT_EQ(timeline("a").version(), after_commit.version());
  EXPECT_EQ(timeline("a").reservations().size(), 1u);
}

TEST_F(TopologyAgentTest, AllocationIsGrantedInReservationOrderHoldingsShowItAndAQueuedRequesterIsAnsweredOnRelease) {
  start_agent(71);
  connect(71);
  ASSERT_NO_FATAL_FAILURE(wait_for_notice_delivery("d"));
  reserve("v1", 1, {{"b", {1000, 2000}}});
  reserve("v2", 1, {{"b", {3000, 4000}}});

  const auto early = allocate("v2", "b", false);
  EXPECT_EQ(early.error().code(), msg::ERROR_NONE) << early.error().message();
  EXPECT_FALSE(early.granted());
  EXPECT_EQ(early.queue_position(), 1u);

  const auto first = allocate("v1", "b", false);
  EXPECT_EQ(first.error().code(), msg::ERROR_NONE) << first.error().message();
  EXPECT_TRUE(first.granted());
  // What each agent has here (what a restarted logical agent asks for).
  msg::HoldingsRequest of_v1;
  of_v1.agent("v1");
  const auto v1 = holdings_->call(of_v1, kDiscoveryTimeout);
  ASSERT_TRUE(v1.has_value()) << v1.error().message;
  EXPECT_EQ(v1->error().code(), msg::ERROR_NONE) << v1->error().message();
  ASSERT_EQ(v1->held().size(), 1u);
  EXPECT_EQ(v1->held()[0].entity(), "b");
  EXPECT_EQ(v1->held()[0].route(), 1u);
  EXPECT_EQ(v1->held()[0].step(), 0u);
  EXPECT_EQ(v1->routes(), std::vector<std::uint64_t>{1});
  msg::HoldingsRequest of_v2;
  of_v2.agent("v2");
  const auto v2 = holdings_->call(of_v2, kDiscoveryTimeout);
  ASSERT_TRUE(v2.has_value()) << v2.error().message;
  EXPECT_TRUE(v2->held().empty());
  EXPECT_EQ(v2->routes(), std::vector<std::uint64_t>{1});
  const auto nobody = holdings_->call(msg::HoldingsRequest{}, kDiscoveryTimeout);
  ASSERT_TRUE(nobody.has_value()) << nobody.error().message;
  EXPECT_EQ(nobody->error().code(), msg::ERROR_INVALID_ARGUMENT);

  auto waiting = std::async(std::launch::async, [this] { return allocate("v2", "b", true); });
  EXPECT_TRUE(wait_until([&] {
    const auto& state = timelines_["b"];
    return state.holder() == "v1" && state.waiting() == std::vector<std::string>{"v2"};
  })) << "the timeline shows v1 holding b and v2 in the queue";
  EXPECT_EQ(waiting.wait_for(0s), std::future_status::timeout) << "v2 must not be granted before v1 releases";
  // v2 asks again (as a logical agent does once its call timed out): the earlier request is
  // answered "not yet" at once, and one reply waits, not one per try.
  auto again = std::async(std::launch::async, [this] { return allocate("v2", "b", true); });
  const auto superseded = waiting.get();
  EXPECT_EQ(superseded.error().code(), msg::ERROR_NONE) << superseded.error().message();
  EXPECT_FALSE(superseded.granted());
  EXPECT_EQ(superseded.queue_position(), 1u);
  EXPECT_EQ(again.wait_for(0s), std::future_status::timeout) << "v2 must not be granted before v1 releases";

  EXPECT_EQ(release("v1", "b").error().code(), msg::ERROR_NONE);
  const auto granted = again.get();
  EXPECT_EQ(granted.error().code(), msg::ERROR_NONE) << granted.error().message();
  EXPECT_TRUE(granted.granted());
  EXPECT_TRUE(wait_until([&] { return timelines_["b"].holder() == "v2" && timelines_["b"].waiting().empty(); }));
  EXPECT_TRUE(wait_until([&] {
    for (const auto& notice : notices_) {
      // The notice names the step granted (route 1, step 0, its window).
      if (notice.agent() == "v2" && notice.kind() == msg::NOTICE_ALLOCATION_GRANTED && notice.entity() == "b" &&
          notice.route() == 1 && notice.from_step() == 0 && notice.window().start() == 3000) {
        return true;
      }
    }
    return false;
  }));
}

// Only a logical agent that is gone loses an allocation to someone else's release (an
// operator's droverctl release): one whose heartbeat the topology agent hears releases what
// it holds itself, whatever the operator's tool believes.
TEST_F(TopologyAgentTest, WhatALiveLogicalAgentHoldsIsReleasedOnlyByItself) {
  constexpr std::uint32_t kDomain = 39;
  start_agent(kDomain, {"--departed-after", "0"});  // no sweep: only the heartbeats count
  connect(kDomain);
  reserve("v1", 1, {{"b", {1000, 2000}}});
  ASSERT_TRUE(allocate("v1", "b", false).granted());
  auto v1 = make_participant(kDomain, "v1");
  ASSERT_NE(v1, nullptr);
  dds::HeartbeatOptions beat;
  beat.kind = "logical";
  beat.owns = {"v1"};
  auto heartbeat = dds::HeartbeatPublisher::create(*v1, SharedClock::wall(), beat);
  ASSERT_TRUE(heartbeat.has_value()) << heartbeat.error().message;

  // Once the topology agent hears v1, nobody else's release of v1's allocations is taken:
  // a (harmless) release of an entity v1 does not hold says when that is.
  const auto refused_as_alive = [](const msg::StatusReply& reply) {
    return reply.error().code() == msg::ERROR_CONFLICT &&
           reply.error().message().find("'v1' is alive") != std::string::npos;
  };
  const auto give_up = std::chrono::steady_clock::now() + kDiscoveryTimeout;
  while (!refused_as_alive(release("v1", "a")) && std::chrono::steady_clock::now() < give_up) {
    std::this_thread::sleep_for(50ms);
  }
  ASSERT_TRUE(refused_as_alive(release("v1", "a"))) << "the topology agent never heard v1";
  const auto refused = release("v1", "b");
  EXPECT_TRUE(refused_as_alive(refused)) << refused.error().message();
  EXPECT_EQ(timeline("b").holder(), "v1");

  // v1 goes away: then an operator may clear what it left.
  heartbeat->reset();
  v1.reset();
  const auto released = [&] { return release("v1", "b").error().code() == msg::ERROR_NONE; };
  const auto later = std::chrono::steady_clock::now() + kDiscoveryTimeout;
  bool done = released();
  while (!done && std::chrono::steady_clock::now() < later) {
    std::this_thread::sleep_for(100ms);
    done = released();
  }
  EXPECT_TRUE(done) << "v1 gone, its allocation is still refused to others";
  EXPECT_TRUE(wait_until([&] { return timelines_["b"].holder().empty(); }));
}

// A lock in force keeps a vehicle off the entity however its request came: a request queued
// before the lock is not granted by the release that would have let it on.
TEST_F(TopologyAgentTest, AQueuedRequestIsNotGrantedWhileALockIsInForce) {
  start_agent(66);
  connect(66);
  reserve("v1", 1, {{"b", {1000, 2000}}});
  reserve("v2", 1, {{"d", {2000, 3000}}, {"b", {3000, 4000}}});  // b is v2's step 1, not where it stands
  ASSERT_TRUE(allocate("v1", "b", false).granted());
  auto waiting = std::async(std::launch::async, [this] { return allocate("v2", "b", true); });
  ASSERT_TRUE(wait_until([&] { return timelines_["b"].waiting() == std::vector<std::string>{"v2"}; }));
  const auto locked = lock("b", 0, kForever / 2);
  ASSERT_EQ(locked.error().code(), msg::ERROR_NONE) << locked.error().message();
  EXPECT_FALSE(allocate("v2", "b", false).granted()) << "a new request under the lock";

  EXPECT_EQ(release("v1", "b").error().code(), msg::ERROR_NONE);
  EXPECT_TRUE(wait_until([&] { return timelines_["b"].holder().empty(); })) << "v1's release never showed";
  EXPECT_EQ(waiting.wait_for(0s), std::future_status::timeout) << "v2 was answered: granted under the lock";
  EXPECT_TRUE(wait_until([&] { return timelines_["b"].waiting() == std::vector<std::string>{"v2"}; }))
      << "v2 stays queued";
  // The agent asks again once the lock is gone (no grant comes when a lock ends).
  ASSERT_EQ(unlock(locked.lock_id()).error().code(), msg::ERROR_NONE);
  const auto granted = allocate("v2", "b", false);
  EXPECT_EQ(granted.error().code(), msg::ERROR_NONE) << granted.error().message();
  EXPECT_TRUE(granted.granted());
  EXPECT_TRUE(waiting.get().granted()) << "the queued request is answered by the grant";
}

TEST_F(TopologyAgentTest, ALockNotifiesTheOwnersOfHitReservationsAndUnlockRemovesIt) {
  start_agent(72);
  connect(72);
  // Notices are VOLATILE: the agent's notice writer must have matched this tester before the
  // lock, or its notice is lost (seen once in a full run). Its event writer delivering says
  // so (the tester's readers were announced in one go); the locks this takes count on.
  ASSERT_NO_FATAL_FAILURE(wait_for_event_delivery("d"));
  reserve("v1", 4, {{"c", {100, 200}}});
  const auto locked = lock("c", 150, 300);
  ASSERT_EQ(locked.error().code(), msg::ERROR_NONE) << locked.error().message();
  const std::string id = locked.lock_id();
  EXPECT_EQ(id.rfind("topology/", 0), 0u) << id;
  ASSERT_EQ(locked.hit().size(), 1u);
  EXPECT_EQ(locked.hit()[0].agent(), "v1");
  EXPECT_TRUE(wait_until([&] {
    for (const auto& notice : notices_) {
      if (notice.agent() == "v1" && notice.kind() == msg::NOTICE_LOCK_HIT && notice.lock_id() == id &&
          notice.route() == 4) {
        return true;
      }
    }
    return false;
  }));
  EXPECT_TRUE(wait_until([&] {
    const auto& locks = timelines_["c"].locks();
    return locks.size() == 1 && locks[0].id() == id && locks[0].operator_id() == "operator-1" &&
           locks[0].reason() == "spilled oil" && locks[0].window().end() == 300;
  }));
  // A new reservation into the lock is refused.
  auto blocked = prepare_->call(prepare_request("v2", 1, items("v2", 1, {{"c", {250, 260}}})), kDiscoveryTimeout);
  ASSERT_TRUE(blocked.has_value());
  EXPECT_EQ(blocked->error().code(), msg::ERROR_CONFLICT);

  EXPECT_EQ(unlock(id).error().code(), msg::ERROR_NONE);
  EXPECT_TRUE(wait_until([&] { return timelines_["c"].locks().empty(); }));
  reserve("v2", 1, {{"c", {250, 260}}});
}

TEST_F(TopologyAgentTest, BadRequestsGetAnErrorReplyAndChangeNothing) {
  start_agent(73);
  connect(73);
  reserve("v1", 1, {{"a", {1000, 2000}}});
  const auto before = timeline_at("a", 2);

  const auto unknown = allocate("v1", "nowhere", false);
  EXPECT_EQ(unknown.error().code(), msg::ERROR_NOT_FOUND);
  EXPECT_NE(unknown.error().message().find("nowhere"), std::string::npos) << unknown.error().message();

  const auto malformed = lock("a", 500, 500);
  EXPECT_EQ(malformed.error().code(), msg::ERROR_INVALID_ARGUMENT) << malformed.error().message();

  const auto not_held = release("v1", "a");
  EXPECT_EQ(not_held.error().code(), msg::ERROR_NOT_PERMITTED) << not_held.error().message();

  EXPECT_EQ(unlock("topology/99").error().code(), msg::ERROR_NOT_FOUND);
  EXPECT_EQ(unlock("garbage").error().code(), msg::ERROR_NOT_FOUND);
  EXPECT_EQ(unlock("topology/").error().code(), msg::ERROR_NOT_FOUND);

  msg::DelayRequest backwards;
  backwards.agent("v1");
  backwards.route(1);
  backwards.entity("a");
  backwards.by(-5);
  auto delayed = delay_->call(backwards, kDiscoveryTimeout);
  ASSERT_TRUE(delayed.has_value());
  EXPECT_EQ(delayed->error().code(), msg::ERROR_INVALID_ARGUMENT);

  msg::CancelRouteRequest no_route;
  no_route.agent("v9");
  no_route.route(3);
  auto cancelled = cancel_->call(no_route, kDiscoveryTimeout);
  ASSERT_TRUE(cancelled.has_value());
  EXPECT_EQ(cancelled->error().code(), msg::ERROR_NOT_FOUND);

  auto no_items = prepare_->call(prepare_request("v1", 2, {}), kDiscoveryTimeout);
  ASSERT_TRUE(no_items.has_value());
  EXPECT_EQ(no_items->error().code(), msg::ERROR_INVALID_ARGUMENT);

  // A delay in seconds sent as ns would push routes for years; a hold expiring in two hours
  // is one of another clock, and would block others for good if its routing agent died.
  msg::DelayRequest years = backwards;
  years.by(25 * 3600 * kNsPerSecond);
  delayed = delay_->call(years, kDiscoveryTimeout);
  ASSERT_TRUE(delayed.has_value());
  EXPECT_EQ(delayed->error().code(), msg::ERROR_INVALID_ARGUMENT);
  EXPECT_NE(delayed->error().message().find("at most 86400000000000 ns"), std::string::npos)
      << delayed->error().message();
  auto far_hold = prepare_->call(
      prepare_request("v1", 2, items("v1", 2, {{"b", {5000, 6000}}}), {}, SharedClock::wall().now() + seconds_to_ns(7200)),
      kDiscoveryTimeout);
  ASSERT_TRUE(far_hold.has_value());
  EXPECT_EQ(far_hold->error().code(), msg::ERROR_INVALID_ARGUMENT);
  EXPECT_NE(far_hold->error().message().find("more than 3600 s after now on topology agent"), std::string::npos)
      << far_hold->error().message();

  reserve("v3", 1, {{"d", {0, 10}}});
  timeline_at("d", 2);
  EXPECT_EQ(timeline("a"), before);
}

TEST_F(TopologyAgentTest, DelayShiftsThePushedRouteAndNotifiesEveryAffectedAgent) {
  start_agent(74);
  connect(74);
  ASSERT_NO_FATAL_FAILURE(wait_for_notice_delivery("d"));
  reserve("v1", 1, {{"a", {1000, 2000}}});
  reserve("v2", 1, {{"a", {2000, 3000}}});
  msg::DelayRequest request;
  request.agent("v1");
  request.route(1);
  request.entity("a");
  request.by(500);
  auto delayed = delay_->call(request, kDiscoveryTimeout);
  ASSERT_TRUE(delayed.has_value());
  ASSERT_EQ(delayed->error().code(), msg::ERROR_NONE) << delayed->error().message();
  ASSERT_EQ(delayed->shifts().size(), 2u);
  EXPECT_EQ(delayed->shifts()[0].agent(), "v1");
  EXPECT_EQ(delayed->shifts()[1].agent(), "v2");
  // Each agent is told about its own route: its first moved step, entity and new window.
  EXPECT_TRUE(wait_until([&] {
    bool v1 = false, v2 = false;
    for (const auto& notice : notices_) {
      if (notice.kind() != msg::NOTICE_SHIFTED || notice.route() != 1 || notice.from_step() != 0 ||
          notice.entity() != "a" || notice.shift() != 500) {
        continue;
      }
      v1 = v1 || (notice.agent() == "v1" && notice.window().start() == 1000 && notice.window().end() == 2500);
      v2 = v2 || (notice.agent() == "v2" && notice.window().start() == 2500 && notice.window().end() == 3500);
    }
    return v1 && v2;
  })) << "NOTICE_SHIFTED to v1 on a [1000, 2500) and to v2 on a [2500, 3500)";
  EXPECT_TRUE(wait_until([&] {
    const auto& reservations = timelines_["a"].reservations();
    return reservations.size() == 2 && reservations[1].agent() == "v2" && reservations[1].window().start() == 2500;
  }));
}

TEST_F(TopologyAgentTest, EveryReservationAllocationAndReleaseIsPublishedAsAnEvent) {
  start_agent(60);
  connect(60);
  ASSERT_NO_FATAL_FAILURE(wait_for_event_delivery("d"));
  reserve("v1", 1, {{"a", {1000, 2000}}});
  reserve("v2", 5, {{"a", {3000, 4000}}});
  EXPECT_TRUE(allocate("v1", "a", false).granted());
  auto waiting = std::async(std::launch::async, [this] { return allocate("v2", "a", true); });
  ASSERT_TRUE(wait_until([&] { return timelines_["a"].waiting() == std::vector<std::string>{"v2"}; }));
  EXPECT_EQ(release("v1", "a").error().code(), msg::ERROR_NONE);
  EXPECT_TRUE(waiting.get().granted());
  const auto locked = lock("d", 0, 500);

  struct Expected {
    msg::TopologyEventKind kind;
    std::string agent;
    topology::RouteId route;
    std::string entity;
    TimeNs start, end;
  };
  const std::vector<Expected> expected{{msg::EVENT_RESERVED, "v1", 1, "a", 1000, 2000},
                                       {msg::EVENT_RESERVED, "v2", 5, "a", 3000, 4000},
                                       {msg::EVENT_ALLOCATED, "v1", 1, "a", 1000, 2000},
                                       {msg::EVENT_RELEASED, "v1", 1, "a", 1000, 2000},
                                       {msg::EVENT_ALLOCATED, "v2", 5, "a", 3000, 4000},
                                       {msg::EVENT_LOCKED, "operator-1", 0, "d", 0, 500}};
  ASSERT_TRUE(wait_until([&] { return events_.size() >= expected.size(); }));
  std::lock_guard guard(mutex_);
  ASSERT_EQ(events_.size(), expected.size()) << "the shadows on a-b make no events of their own";
  for (std::size_t i = 0; i < expected.size(); ++i) {
    const auto& event = events_[i];
    SCOPED_TRACE("event " + std::to_string(i));
    EXPECT_EQ(event.kind(), expected[i].kind);
    EXPECT_EQ(event.agent(), expected[i].agent);
    EXPECT_EQ(event.route(), expected[i].route);
    EXPECT_EQ(event.entity(), expected[i].entity);
    EXPECT_EQ(event.window().start(), expected[i].start);
    EXPECT_EQ(event.window().end(), expected[i].end);
    EXPECT_EQ(event.source(), "topology");
    EXPECT_EQ(event.serial(), events_.front().serial() + i) << "events are numbered without gaps";
    if (i > 0) {
      EXPECT_GE(event.time(), events_[i - 1].time());
    }
  }
  EXPECT_EQ(events_.back().lock_id(), locked.lock_id());
  EXPECT_EQ(events_.back().reason(), "spilled oil");
}

TEST_F(TopologyAgentTest, TwoPartitionsAreServedByTwoAgents) {
  start_agent(75, {"--partition", "west"});
  start_agent(75, {"--partition", "east"});
  connect(75);
  EXPECT_TRUE(wait_until([&] { return descriptions_.size() == topology_->entity_count(); }));
  {
    std::lock_guard guard(mutex_);
    EXPECT_EQ(descriptions_["a"].partition(), "west");
    EXPECT_EQ(descriptions_["c-d"].partition(), "east");
    EXPECT_EQ(descriptions_["c-d"].kind(), msg::ENTITY_EDGE);
    EXPECT_EQ(descriptions_["c-d"].from(), "c");
  }
  // Each agent takes only its own entities.
  const auto wrong = lock("c", 0, 100, "topology-west");
  EXPECT_EQ(wrong.error().code(), msg::ERROR_NOT_FOUND);
  EXPECT_NE(wrong.error().message().find("east"), std::string::npos) << wrong.error().message();
  const auto right = lock("c", 0, 100, "topology-east");
  EXPECT_EQ(right.error().code(), msg::ERROR_NONE) << right.error().message();
  EXPECT_EQ(right.lock_id(), "topology-east/1");

  // A route over b-c then c: the part on each partition goes to its owner.
  const std::vector<std::pair<std::string, topology::Interval>> route{{"b-c", {200, 210}}, {"c", {210, 400}}};
  reserve("v1", 1, route, "topology-west", "west");
  reserve("v1", 1, route, "topology-east", "east");
  // Every item of the route, real and shadow, is on its owner's timeline and nothing else
  // is: each partition's agent stored exactly its share, committed.
  std::map<std::string, std::vector<msg::Reservation>> expected;
  std::size_t shadows = 0;
  for (auto item : items("v1", 1, route)) {
    shadows += item.origin() != item.entity() ? 1 : 0;
    expected[item.entity()].push_back(std::move(item));
  }
  ASSERT_GE(shadows, 2u) << "b-c and c conflict: each step shadows the other";
  for (const auto& [entity, entity_items] : expected) {
    EXPECT_TRUE(wait_until([&, &entity = entity, &entity_items = entity_items] {
      const auto& reservations = timelines_[entity].reservations();
      if (reservations.size() != entity_items.size()) return false;
      for (const auto& wanted : entity_items) {
        if (std::find(reservations.begin(), reservations.end(), wanted) == reservations.end()) return false;
      }
      return true;
    })) << "timeline of " << entity << " holds exactly the route's " << entity_items.size() << " item(s)";
  }
  {
    std::lock_guard guard(mutex_);
    EXPECT_TRUE(timelines_["a"].reservations().empty());
    EXPECT_TRUE(timelines_["d"].reservations().empty());
    ASSERT_EQ(timelines_["c"].locks().size(), 1u);
    EXPECT_EQ(timelines_["c"].locks()[0].id(), "topology-east/1");
  }
}

// A route its own agent cancelled (it gave it up, or crashed and its next life did) is never
// reserved again: a routing agent still retrying it would leave a route nobody cancels. One
// a routing agent cancelled (it undoes a partial commit and re-plans) may be.
TEST_F(TopologyAgentTest, ARouteItsOwnAgentCancelledIsNotReservedAgain) {
  start_agent(67);
  connect(67);
  auto v1 = make_participant(67, "v1");
  ASSERT_NE(v1, nullptr);
  auto own_cancel = make_client<msg::CancelRouteRequest, msg::StatusReply>(*v1, "cancel_route");
  msg::CancelRouteRequest give_up;
  give_up.agent("v1");
  give_up.route(5);  // nothing of it here yet: its prepare is still on its way
  auto given_up = own_cancel->call(give_up, kDiscoveryTimeout);
  ASSERT_TRUE(given_up.has_value()) << given_up.error().message;
  EXPECT_EQ(given_up->error().code(), msg::ERROR_NOT_FOUND);
  auto late = prepare_->call(prepare_request("v1", 5, items("v1", 5, {{"a", {1000, 2000}}})), kDiscoveryTimeout);
  ASSERT_TRUE(late.has_value()) << late.error().message;
  EXPECT_EQ(late->error().code(), msg::ERROR_NOT_PERMITTED) << late->error().message();

  reserve("v1", 6, {{"a", {1000, 2000}}});
  msg::CancelRouteRequest undo;  // from "tester", as a routing agent undoing a commit
  undo.agent("v1");
  undo.route(6);
  auto undone = cancel_->call(undo, kDiscoveryTimeout);
  ASSERT_TRUE(undone.has_value()) << undone.error().message;
  EXPECT_EQ(undone->error().code(), msg::ERROR_NONE) << undone->error().message();
  reserve("v1", 6, {{"a", {1000, 2000}}});
  own_cancel.reset();
  v1.reset();
}

TEST_F(TopologyAgentTest, APreparedHoldThatIsNeverCommittedExpires) {
  start_agent(76);
  connect(76);
  ASSERT_NO_FATAL_FAILURE(wait_for_notice_delivery("d"));
  auto prepared = prepare_->call(
      prepare_request("v1", 1, items("v1", 1, {{"b", {1000, 2000}}}), {}, SharedClock::wall().now() + seconds_to_ns(1)),
      kDiscoveryTimeout);
  ASSERT_TRUE(prepared.has_value());
  ASSERT_EQ(prepared->error().code(), msg::ERROR_NONE) << prepared->error().message();
  EXPECT_TRUE(wait_until([&] {
    for (const auto& notice : notices_) {
      if (notice.agent() == "v1" && notice.kind() == msg::NOTICE_PREPARE_EXPIRED && notice.route() == 1) return true;
    }
    return false;
  }));
  EXPECT_TRUE(wait_until([&] { return timelines_["b"].version() >= 2 && timelines_["b"].reservations().empty(); }));
  msg::ReserveCommitRequest late;
  late.prepare_id(prepared->prepare_id());
  auto committed = commit_->call(late, kDiscoveryTimeout);
  ASSERT_TRUE(committed.has_value());
  EXPECT_EQ(committed->error().code(), msg::ERROR_NOT_FOUND);
  reserve("v2", 1, {{"b", {1000, 2000}}});
}

TEST_F(TopologyAgentTest, AfterKill9TheRestartedAgentHasItsCommittedStateBack) {
  const auto journal = std::filesystem::path(topology_file_).replace_extension(".db");
  std::filesystem::remove(journal);
  // No sweeps of v1 and v2 (which send no heartbeats) after the restart.
  start_agent(77, {"--db", journal.string(), "--departed-after", "0"});
  connect(77);
  std::atomic<bool> gone{false};
  const auto token = participant_->subscribe_events([&](const dds::ParticipantEvent& event) {
    if (event.name == "topology" && event.change != dds::ParticipantChange::discovered) gone = true;
  });
  reserve("v1", 1, {{"a", {1000, 2000}}});
  reserve("v2", 1, {{"a", {3000, 4000}}});
  EXPECT_TRUE(allocate("v1", "a", false).granted());
  EXPECT_EQ(lock("c", 0, 500).lock_id(), "topology/1");
  ASSERT_TRUE(wait_until([&] { return timelines_["a"].holder() == "v1"; }));
  const auto before = timeline("a");

  agents_.back().signal(SIGKILL);
  ASSERT_TRUE(agents_.back().wait_exit(kDiscoveryTimeout).has_value());
  agents_.pop_back();
  EXPECT_TRUE(wait_until([&] { return gone.load(); })) << "the killed agent is seen gone";
  participant_->unsubscribe_events(token);
  {
    std::lock_guard guard(mutex_);
    timelines_.clear();
  }
  start_agent(77, {"--db", journal.string(), "--departed-after", "0"});
  EXPECT_TRUE(wait_until([&] { return timelines_.count("a") > 0 && timelines_.count("c") > 0; }));
  {
    std::lock_guard guard(mutex_);
    EXPECT_EQ(timelines_["a"].reservations(), before.reservations());
    EXPECT_EQ(timelines_["a"].holder(), "v1");
    ASSERT_EQ(timelines_["c"].locks().size(), 1u);
    EXPECT_EQ(timelines_["c"].locks()[0].id(), "topology/1");
  }
  // Ids go on where they stopped; the restored holder releases and the next is granted.
  EXPECT_EQ(lock("d", 0, 500).lock_id(), "topology/2");
  EXPECT_EQ(release("v1", "a").error().code(), msg::ERROR_NONE);
  EXPECT_TRUE(allocate("v2", "a", false).granted());
  std::filesystem::remove(journal);
  std::filesystem::remove(journal.string() + "-wal");
  std::filesystem::remove(journal.string() + "-shm");
}

// The logical agent's side of a cancel (TopologyServices, as its executor uses it): a
// partition's owner that is down is not waited for, and the cancel reaches its next life.
TEST_F(TopologyAgentTest, ACancelSentWhileTheOwnerWasDownReachesItsNextLife) {
  const auto journal = std::filesystem::path(topology_file_).replace_extension(".cancel.db");
  std::filesystem::remove(journal);
  // No sweep of v1 (which sends no heartbeat) after the restart: only its cancel may free "a".
  start_agent(68, {"--db", journal.string(), "--departed-after", "0"});
  connect(68);
  reserve("v1", 1, {{"a", {1000, 2000}}});
  ASSERT_FALSE(timeline("a").reservations().empty());
  agents_.back().signal(SIGKILL);
  ASSERT_TRUE(agents_.back().wait_exit(kDiscoveryTimeout).has_value());
  agents_.pop_back();

  auto v1 = make_participant(68, "v1");
  ASSERT_NE(v1, nullptr);
  const std::atomic<bool> stopping{false};
  auto services = logical_agent::TopologyServices::create(*v1, std::make_shared<topology::Topology>(*topology_),
                                                          std::chrono::milliseconds(1000), stopping);
  ASSERT_TRUE(services.has_value()) << services.error().message;
  const std::vector<topology::RouteStep> steps{{*topology_->find("a"), {1000, 2000}}};
  const auto touched = (*services)->partitions_touched(steps);
  EXPECT_EQ(touched, std::vector<std::string>{"west"});  // "a" and its shadows on a-b
  // Returns at once, the cancel left due: nobody owns "west" now.
  EXPECT_TRUE((*services)->cancel_route("v1", 1, {}, touched).has_value());
  EXPECT_EQ((*services)->cancels_due(), 1u);

  {
    std::lock_guard guard(mutex_);
    timelines_.clear();
  }
  start_agent(68, {"--db", journal.string(), "--departed-after", "0"});
  EXPECT_TRUE(wait_until([&] { return timelines_.count("a") > 0 && timelines_["a"].reservations().empty(); }))
      << "the restarted agent kept route 1";
  EXPECT_TRUE(wait_until([&] { return (*services)->cancels_due() == 0; }));
  services->reset();
  v1.reset();
  for (const auto* suffix : {"", "-wal", "-shm"}) std::filesystem::remove(journal.string() + suffix);
}

TEST(TopologyAgentCommand, APartitionThatOwnsNothingIsBadInput) {
  const auto file = write_topology_file();
  auto agent = ChildProcess::spawn(binary_path("drover"),
                                   {"topology-agent", "--topology", file, "--partition", "north", "--domain", "78"});
  ASSERT_TRUE(agent.has_value());
  auto status = agent->wait_exit(kDiscoveryTimeout);
  ASSERT_TRUE(status.has_value());
  EXPECT_TRUE(status->exited);
  EXPECT_EQ(status->code, 2);
  std::filesystem::remove(file);
}

}  // namespace
}  // namespace drover::test
