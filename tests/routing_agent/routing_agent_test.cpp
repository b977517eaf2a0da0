// The routing agent as a process (`drover routing-agent`), with topology agents serving two
// partitions: test and real routes through the route service and droverctl route, bad
// requests, many concurrent real routes through two routing agents (no double booking,
// judged on the timelines the topology agents publish), and a routing agent killed
// between prepare and commit. DDS domains 50..59. Nothing sleeps: every wait is on a
// condition with a generous timeout.

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <filesystem>
#include <fstream>
#include <future>
#include <map>
#include <mutex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "drover/common/clock.hpp"
#include "drover/dds/participant.hpp"
#include "drover/dds/reader.hpp"
#include "drover/dds/service_client.hpp"
#include "drover/topology/topology_file.hpp"
#include "routing.h"
#include "tests/agents/child_process.hpp"
#include "topology.h"

namespace drover::test {
namespace {

using namespace std::chrono_literals;
constexpr auto kTimeout = 30s;

// a - b - c - d, plus a spur b - e. West: a, b, e and their edges; east: c, d, b-c, c-d.
constexpr const char* kLineTopology = R"({
  "name": "line",
  "vertices": [
    {"id": "a", "x": 0, "y": 0, "partition": "west"},
    {"id": "b", "x": 3, "y": 0, "partition": "west"},
    {"id": "e", "x": 3, "y": 3, "partition": "west"},
    {"id": "c", "x": 6, "y": 0, "partition": "east"},
    {"id": "d", "x": 9, "y": 0, "partition": "east"}
  ],
  "edges": [
    {"id": "a-b", "from": "a", "to": "b", "bidirectional": true, "max_speed": 1.0, "partition": "west"},
    {"id": "b-e", "from": "b", "to": "e", "bidirectional": true, "max_speed": 1.0, "partition": "west"},
    {"id": "b-c", "from": "b", "to": "c", "bidirectional": true, "max_speed": 1.0, "partition": "east"},
    {"id": "c-d", "from": "c", "to": "d", "bidirectional": true, "max_speed": 1.0, "partition": "east"}
  ]
})";

// a - b - c straight (6 m) or a - d - c round (8.5 m); b alone is east.
constexpr const char* kDetourTopology = R"({
  "name": "detour",
  "vertices": [
    {"id": "a", "x": 0, "y": 0, "partition": "west"},
    {"id": "b", "x": 3, "y": 0, "partition": "east"},
    {"id": "c", "x": 6, "y": 0, "partition": "west"},
    {"id": "d", "x": 3, "y": 3, "partition": "west"}
  ],
  "edges": [
    {"id": "a-b", "from": "a", "to": "b", "bidirectional": true, "max_speed": 1.0, "partition": "east"},
    {"id": "b-c", "from": "b", "to": "c", "bidirectional": true, "max_speed": 1.0, "partition": "east"},
    {"id": "a-d", "from": "a", "to": "d", "bidirectional": true, "max_speed": 1.0, "partition": "west"},
    {"id": "d-c", "from": "d", "to": "c", "bidirectional": true, "max_speed": 1.0, "partition": "west"}
  ]
})";

using RouteClient = dds::ServiceClient<msg::RouteRequest, msg::RouteReply>;

std::string source_path(const std::string& relative) {
  const char* root = std::getenv("DROVER_SOURCE_DIR");
  return std::string(root ? root : ".") + "/" + relative;
}

msg::RouteRequest route_request(const std::string& agent, const std::string& from, const std::string& to,
                                bool real, TimeNs start_time = 0) {
  msg::RouteRequest request;
  request.agent(agent);
  request.real(real);
  request.vehicle().id(agent);
  request.vehicle().max_speed(1.0);
  request.vehicle().acceleration(1.0);
  request.vehicle().deceleration(1.0);
  request.vehicle().length(1.0);
  request.vehicle().width(1.0);
  request.start(from);
  request.start_time(start_time);
  msg::RouteStop stop;
  stop.vertex(to);
  request.stops().push_back(stop);
  return request;
}

std::vector<std::string> step_ids(const msg::RouteReply& reply) {
  std::vector<std::string> ids;
  for (const auto& step : reply.steps()) ids.push_back(step.entity());
  return ids;
}

class RoutingAgentTest : public ::testing::Test {
 protected:
  void TearDown() override {
    // Clients and readers before the participant; agents stopped with SIGTERM, exit 0.
    client_.reset();
    readers_.clear();
    participant_.reset();
    for (auto& [name, agent] : agents_) {
      agent.signal(SIGTERM);
      auto status = agent.wait_exit(kTimeout);
      ASSERT_TRUE(status.has_value()) << name << " did not stop on SIGTERM";
      EXPECT_TRUE(status->exited) << name << " killed by signal " << status->code;
      EXPECT_EQ(status->code, 0) << name;
    }
    agents_.clear();
    if (!topology_file_.empty()) std::filesystem::remove(topology_file_);
  }

  std::string temp_path(const std::string& name) const {
    return ::testing::TempDir() + "routing_agent_test_" + std::to_string(::getpid()) + "_" + name;
  }

  void use_topology(const char* text) {
    topology_file_ = temp_path("topology.json");
    std::ofstream(topology_file_) << text;
  }
  void use_line_topology() { use_topology(kLineTopology); }

  void start(const std::string& name, std::vector<std::string> args) {
    auto child = ChildProcess::spawn(binary_path("drover"), args, temp_path(name + ".out"), temp_path(name + ".err"));
    ASSERT_TRUE(child.has_value());
    agents_.emplace(name, std::move(*child));
  }

  void start_topology_agents(std::uint32_t domain, const std::string& file) {
    for (const char* partition : {"west", "east"}) {
      start(std::string("topology-") + partition, {"topology-agent", "--topology", file, "--partition", partition,
                                                    "--domain", std::to_string(domain)});
    }
  }

  void start_routing_agent(std::uint32_t domain, const std::string& id, std::vector<std::string> extra = {}) {
    std::vector<std::string> args{"routing-agent", "--id", id, "--domain", std::to_string(domain)};
    args.insert(args.end(), extra.begin(), extra.end());
    start(id, args);
  }

  /// The test's participant, a route client and a reader of every published timeline;
  /// waits until that reader has matched `timeline_writers` topology agents.
  void connect(std::uint32_t domain, std::size_t timeline_writers = 0) {
    dds::ParticipantOptions options;
    options.domain_id = domain;
    options.agent_id = "tester";
    auto participant = dds::Participant::create(options);
    ASSERT_TRUE(participant.has_value()) << participant.error().message;
    participant_ = std::move(*participant);
    auto client = RouteClient::create(*participant_, "routing", "route");
    ASSERT_TRUE(client.has_value());
    client_ = std::move(*client);
    auto timelines = dds::Reader<msg::TimelineState>::create(
        *participant_, "drover/topology/timeline", [this](const msg::TimelineState& state) {
          std::lock_guard lock(mutex_);
          timelines_[state.entity()] = state;
          changed_.notify_all();
        });
    ASSERT_TRUE(timelines.has_value());
    ASSERT_TRUE((*timelines)->wait_for_writers(timeline_writers, kTimeout)) << "the topology agents never matched";
    readers_.push_back(std::shared_ptr<void>(std::move(*timelines)));
  }

  template <class Condition>
  bool wait_until(Condition condition, std::chrono::milliseconds timeout = kTimeout) {
    std::unique_lock lock(mutex_);
    return changed_.wait_for(lock, timeout, [&] { return condition(); });
  }

  /// Every reservation (real and shadow) of `agent` on the published timelines.
  std::vector<msg::Reservation> reservations_of(const std::string& agent) {
    std::vector<msg::Reservation> out;
    for (const auto& [entity, state] : timelines_) {
      for (const auto& item : state.reservations()) {
        if (item.agent() == agent) out.push_back(item);
      }
    }
    return out;
  }

  msg::RouteReply call(const msg::RouteRequest& request, const std::string& responder = {}) {
    auto reply = client_->call(request, kTimeout, responder);
    EXPECT_TRUE(reply.has_value()) << reply.error().message;
    return reply ? *reply : msg::RouteReply{};
  }

  /// Asks for `request` until the route has `steps` (the routing agent's replica follows
  /// the topology agents' timelines a moment later) or kTimeout passes; between tries it
  /// waits for the next timeline update, at most 100 ms.
  bool eventually_routes(const msg::RouteRequest& request, const std::vector<std::string>& steps) {
    const auto deadline = std::chrono::steady_clock::now() + kTimeout;
    while (std::chrono::steady_clock::now() < deadline) {
      if (step_ids(call(request)) == steps) return true;
      std::unique_lock lock(mutex_);
      changed_.wait_for(lock, 100ms);
    }
    return false;
  }

  /// Runs droverctl to its end with `args`; its output in `out` and `err`.
  std::optional<ExitStatus> droverctl(const std::vector<std::string>& args, std::string& out, std::string& err) {
    const std::string stem = temp_path("droverctl_" + std::to_string(droverctl_runs_++));
    auto child = ChildProcess::spawn(binary_path("droverctl"), args, stem + ".out", stem + ".err");
    if (!child) return std::nullopt;
    auto status = child->wait_exit(kTimeout * 2);
    out = read_file(stem + ".out");
    err = read_file(stem + ".err");
    return status;
  }

  std::string topology_file_;
  std::map<std::string, ChildProcess> agents_;
  std::unique_ptr<dds::Participant> participant_;
  std::unique_ptr<RouteClient> client_;
  std::vector<std::shared_ptr<void>> readers_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::map<std::string, msg::TimelineState> timelines_;
  int droverctl_runs_ = 0;
};

TEST_F(RoutingAgentTest, TestRouteReservesNothingRealRouteIsReservedOnBothPartitions) {
  constexpr std::uint32_t kDomain = 50;
  use_line_topology();
  start_topology_agents(kDomain, topology_file_);
  start_routing_agent(kDomain, "routing-1");
  connect(kDomain);

  const TimeNs start = SharedClock::wall().now() + seconds_to_ns(60);
  auto test = call(route_request("v1", "a", "d", false, start));
  ASSERT_EQ(test.error().code(), msg::ERROR_NONE) << test.error().message();
  EXPECT_EQ(test.header().responder(), "routing-1");
  EXPECT_EQ(step_ids(test), (std::vector<std::string>{"a", "a-b", "b", "b-c", "c", "c-d", "d"}));
  EXPECT_EQ(test.steps().front().window().start(), start);
  EXPECT_EQ(test.steps().back().window().end(), kForever);
  EXPECT_DOUBLE_EQ(test.distance(), 9.0);
  EXPECT_EQ(test.attempts(), 1u);
  {
    std::lock_guard lock(mutex_);
    EXPECT_TRUE(reservations_of("v1").empty()) << "a test route reserved something";
  }

  auto real = call(route_request("v1", "a", "d", true, start));
  ASSERT_EQ(real.error().code(), msg::ERROR_NONE) << real.error().message();
  EXPECT_EQ(step_ids(real), step_ids(test));
  EXPECT_NE(real.route(), 0u) << "the routing agent picks a route id";
  // Committed on both partitions: a real reservation per step (none prepared any more).
  ASSERT_TRUE(wait_until([&] {
    std::set<std::string> reserved;
    for (const auto& item : reservations_of("v1")) {
      if (item.prepared()) return false;
      if (item.entity() == item.origin()) reserved.insert(item.entity());
    }
    return reserved == std::set<std::string>{"a", "a-b", "b", "b-c", "c", "c-d", "d"};
  })) << "the real route's reservations never showed committed on the timelines";

  // d is held open-ended by v1: another agent can reach c but not d.
  auto blocked = call(route_request("v2", "e", "d", true, start));
  EXPECT_EQ(blocked.error().code(), msg::ERROR_UNAVAILABLE) << blocked.error().message();
  EXPECT_EQ(blocked.failure(), "no_window");
  // A test route for v2 to c is planned around v1 (it waits for v1 to pass).
  auto around = call(route_request("v2", "e", "c", false, start));
  ASSERT_EQ(around.error().code(), msg::ERROR_NONE) << around.error().message();
  for (const auto& step : around.steps()) {
    for (const auto& mine : real.steps()) {
      if (mine.entity() == step.entity()) {
        EXPECT_TRUE(step.window().end() <= mine.window().start() || mine.window().end() <= step.window().start())
            << "v2's window on " << step.entity() << " overlaps v1's";
      }
    }
  }

  // droverctl route: a test route as JSON, exit 0.
  std::string out, err;
  auto status = droverctl({"route", "e", "a", "--test", "--domain", std::to_string(kDomain), "--timeout", "30",
                           "--start-time", std::to_string(start)},
                          out, err);
  ASSERT_TRUE(status.has_value());
  EXPECT_EQ(status->code, 0) << err;
  auto json = nlohmann::json::parse(out, nullptr, false);
  ASSERT_FALSE(json.is_discarded()) << out;
  EXPECT_EQ(json["routing_agent"], "routing-1");
  EXPECT_EQ(json["real"], false);
  ASSERT_EQ(json["steps"].size(), 5u);
  EXPECT_EQ(json["steps"][0]["entity"], "e");
  EXPECT_TRUE(json["steps"][4]["end_ns"].is_null()) << "an open end prints as null";
  // A planning failure: exit 1, the reason printed.
  status = droverctl({"route", "e", "d", "--domain", std::to_string(kDomain), "--timeout", "30", "--start-time",
                      std::to_string(start)},
                     out, err);
  ASSERT_TRUE(status.has_value());
  EXPECT_EQ(status->code, 1) << err;
  EXPECT_NE(err.find("failure: no_window"), std::string::npos) << err;
}

TEST_F(RoutingAgentTest, BadRequestsGetClearErrors) {
  constexpr std::uint32_t kDomain = 51;
  use_line_topology();
  start_topology_agents(kDomain, topology_file_);
  start_routing_agent(kDomain, "routing-1", {"--learn-timeout", "1"});
  connect(kDomain, 2);
  // Learnt the topology: a good test route comes back (asked again while the topology
  // agents' descriptions have not reached the routing agent within its 1 s learn timeout).
  ASSERT_TRUE(eventually_routes(route_request("v1", "a", "c", false), {"a", "a-b", "b", "b-c", "c"}));

  auto unknown = call(route_request("v1", "a", "nowhere", false));
  EXPECT_EQ(unknown.error().code(), msg::ERROR_NOT_FOUND);
  EXPECT_NE(unknown.error().message().find("unknown vertex 'nowhere'"), std::string::npos) << unknown.error().message();

  auto edge = call(route_request("v1", "a-b", "c", false));
  EXPECT_EQ(edge.error().code(), msg::ERROR_INVALID_ARGUMENT);
  EXPECT_NE(edge.error().message().find("'a-b' is an edge"), std::string::npos) << edge.error().message();

  auto no_stops = route_request("v1", "a", "c", false);
  no_stops.stops().clear();
  EXPECT_EQ(call(no_stops).error().code(), msg::ERROR_INVALID_ARGUMENT);

  auto anonymous = route_request("", "a", "c", true);
  auto reply = call(anonymous);
  EXPECT_EQ(reply.error().code(), msg::ERROR_INVALID_ARGUMENT);
  EXPECT_NE(reply.error().message().find("agent"), std::string::npos);

  auto slow = route_request("v1", "a", "c", true);
  slow.vehicle().max_speed(0);
  reply = call(slow);
  EXPECT_EQ(reply.error().code(), msg::ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(reply.failure(), "invalid_request");
  EXPECT_NE(reply.error().message().find("max_speed"), std::string::npos) << reply.error().message();
  {
    std::lock_guard lock(mutex_);
    EXPECT_TRUE(reservations_of("v1").empty()) << "a rejected request reserved something";
  }

  // droverctl: a bad vehicle file names the file and the field (exit 2), an unknown vertex
  // is bad input (exit 2), and nobody on another domain is exit 3.
  const std::string vehicle = temp_path("vehicle.json");
  std::ofstream(vehicle) << R"({"max_speed": "fast"})";
  std::string out, err;
  auto status = droverctl({"route", "a", "c", "--vehicle", vehicle, "--domain", std::to_string(kDomain)}, out, err);
  ASSERT_TRUE(status.has_value());
  EXPECT_EQ(status->code, 2);
  EXPECT_NE(err.find(vehicle + ": max_speed: must be a number"), std::string::npos) << err;
  std::ofstream(vehicle) << R"({"length": -1})";
  status = droverctl({"route", "a", "c", "--vehicle", vehicle, "--domain", std::to_string(kDomain)}, out, err);
  EXPECT_EQ(status->code, 2);
  EXPECT_NE(err.find("length"), std::string::npos) << err;
  status = droverctl({"route", "a", "nowhere", "--test", "--domain", std::to_string(kDomain), "--timeout", "30"},
                     out, err);
  EXPECT_EQ(status->code, 2) << err;
  EXPECT_NE(err.find("unknown vertex 'nowhere'"), std::string::npos) << err;
  status = droverctl({"route", "a", "c", "--test", "--domain", "59", "--timeout", "0.5"}, out, err);
  EXPECT_EQ(status->code, 3) << err;
  EXPECT_NE(err.find("no routing agent answered"), std::string::npos) << err;
  status = droverctl({"route", "a"}, out, err);
  EXPECT_EQ(status->code, 2);
  std::filesystem::remove(vehicle);
}

// Two topology agents (the warehouse's west and east), two routing agents, four client
// processes sending 50 real routes each from 4 threads: 200 concurrent requests.
TEST_F(RoutingAgentTest, ConcurrentRealRoutesThroughTwoRoutingAgentsNeverDoubleBook) {
  constexpr std::uint32_t kDomain = 52;
  const std::string warehouse = source_path("launch/topologies/warehouse.json");
  auto topology = topology::load_topology_file(warehouse);
  ASSERT_TRUE(topology.has_value());
  const std::string stations_file = temp_path("stations.txt");
  {
    std::ofstream stations(stations_file);
    for (const auto& vertex : topology->vertices()) {
      if (vertex.kind == topology::VertexKind::station) stations << vertex.id << "\n";
    }
  }
  start_topology_agents(kDomain, warehouse);
  start_routing_agent(kDomain, "routing-1");
  start_routing_agent(kDomain, "routing-2");
  connect(kDomain);
  // Both routing agents serve before the clients start, so both take requests.
  ASSERT_TRUE(client_->wait_for_server(kTimeout, "routing-1").has_value());
  ASSERT_TRUE(client_->wait_for_server(kTimeout, "routing-2").has_value());

  const TimeNs start = SharedClock::wall().now() + seconds_to_ns(30);
  std::vector<ChildProcess> clients;
  for (int c = 0; c < 4; ++c) {
    auto client = ChildProcess::spawn(
        binary_path("route_test_client"),
        {"--domain", std::to_string(kDomain), "--id", "client" + std::to_string(c), "--stations", stations_file,
         "--count", "50", "--threads", "4", "--seed", std::to_string(100 + c), "--start-ns", std::to_string(start),
         "--spread-s", "120", "--dwell-s", "5"},
        temp_path("client" + std::to_string(c) + ".out"), temp_path("client" + std::to_string(c) + ".err"));
    ASSERT_TRUE(client.has_value());
    clients.push_back(std::move(*client));
  }
  std::map<std::pair<std::string, std::uint64_t>, std::size_t> committed;  // (agent, route) -> steps
  std::set<std::string> responders;
  int answered = 0;
  for (int c = 0; c < 4; ++c) {
    auto status = clients[c].wait_exit(180s);
    ASSERT_TRUE(status.has_value()) << "client " << c << " did not finish";
    EXPECT_EQ(status->code, 0) << read_file(temp_path("client" + std::to_string(c) + ".err"));
    std::istringstream lines(read_file(temp_path("client" + std::to_string(c) + ".out")));
    for (std::string line; std::getline(lines, line);) {
      auto json = nlohmann::json::parse(line);
      ASSERT_TRUE(json["answered"].get<bool>()) << line;
      ++answered;
      responders.insert(json["routing_agent"].get<std::string>());
      const int code = json["code"];
      if (code == msg::ERROR_NONE) {
        committed[{json["agent"], json["route"]}] = json["steps"];
      } else {
        // Only planning outcomes are acceptable: no timeouts, no internal errors.
        EXPECT_FALSE(json["failure"].get<std::string>().empty()) << line;
      }
    }
  }
  EXPECT_EQ(answered, 200);
  EXPECT_EQ(responders, (std::set<std::string>{"routing-1", "routing-2"}));
  EXPECT_GE(committed.size(), 100u) << "most routes should be reservable";

  // Every committed route shows on the timelines with one real reservation per step and as
  // many shadows as its steps' conflict sets have members (the two partitions publish
  // independently, so one may show a route a moment before the other).
  EXPECT_TRUE(wait_until([&] {
    std::map<std::pair<std::string, std::uint64_t>, std::size_t> real_steps, shadows, expected_shadows;
    for (const auto& [entity, state] : timelines_) {
      for (const auto& item : state.reservations()) {
        if (item.prepared()) return false;
        if (item.entity() == item.origin()) {
          ++real_steps[{item.agent(), item.route()}];
          expected_shadows[{item.agent(), item.route()}] += topology->conflicts(*topology->find(entity)).size();
        } else {
          ++shadows[{item.agent(), item.route()}];
        }
      }
    }
    std::erase_if(expected_shadows, [](const auto& entry) { return entry.second == 0; });
    return real_steps == committed && shadows == expected_shadows;
  })) << "the published timelines never showed exactly the committed routes with their shadows (details below)";

  // I1 on every timeline (shadows carry conflict sets), and every real reservation has its
  // shadows on its whole conflict set.
  std::lock_guard lock(mutex_);
  std::size_t checked = 0;
  for (const auto& [entity, state] : timelines_) {
    const auto& items = state.reservations();
    for (std::size_t i = 0; i < items.size(); ++i) {
      EXPECT_FALSE(items[i].prepared()) << "a prepared hold left on " << entity;
      for (std::size_t j = i + 1; j < items.size(); ++j) {
        if (items[i].agent() == items[j].agent()) continue;
        // I1 (docs/timelines.md): reservations of different agents exclude each other when
        // their origins are the same entity or conflict; shadows of two non-conflicting
        // entities may share a timeline.
        const auto origin_i = *topology->find(items[i].origin());
        const auto origin_j = *topology->find(items[j].origin());
        const auto conflicts_i = topology->conflicts(origin_i);
        if (origin_i != origin_j && std::find(conflicts_i.begin(), conflicts_i.end(), origin_j) == conflicts_i.end()) {
          continue;
        }
        const bool overlap = items[i].window().start() < items[j].window().end() &&
                             items[j].window().start() < items[i].window().end();
        EXPECT_FALSE(overlap) << "on " << entity << ": " << items[i].agent() << " (origin " << items[i].origin()
                              << ") and " << items[j].agent() << " (origin " << items[j].origin() << ") overlap";
        ++checked;
      }
      if (items[i].entity() != items[i].origin()) continue;
      for (auto other : topology->conflicts(*topology->find(entity))) {
        const auto& shadows = timelines_[topology->id(other)].reservations();
        const bool found = std::any_of(shadows.begin(), shadows.end(), [&](const msg::Reservation& s) {
          return s.agent() == items[i].agent() && s.route() == items[i].route() && s.origin() == entity &&
                 s.window() == items[i].window();
        });
        EXPECT_TRUE(found) << "no shadow of " << items[i].agent() << "'s step on " << entity << " on "
                           << topology->id(other);
      }
    }
  }
  EXPECT_GT(checked, 0u);
  std::filesystem::remove(stations_file);
}

TEST_F(RoutingAgentTest, HoldsOfARoutingAgentKilledBetweenPrepareAndCommitExpire) {
  constexpr std::uint32_t kDomain = 53;
  use_line_topology();
  start_topology_agents(kDomain, topology_file_);
  start_routing_agent(kDomain, "routing-held", {"--hold-after-prepare", "--prepare-ttl", "4"});
  start_routing_agent(kDomain, "routing-2");
  // The holds live 4 s: the test must see the timelines live by then, so it waits for the
  // topology agents' writers (transient-local alone would only show the state after expiry).
  connect(kDomain, 2);
  ASSERT_TRUE(client_->wait_for_server(kTimeout, "routing-held").has_value());

  const TimeNs start = SharedClock::wall().now() + seconds_to_ns(60);
  // The call never gets an answer: the agent holds, then dies.
  auto pending = std::async(std::launch::async, [&] {
    return client_->call(route_request("v1", "a", "d", true, start), kTimeout, "routing-held");
  });
  ASSERT_TRUE(wait_until([&] {
    std::set<std::string> held;
    for (const auto& item : reservations_of("v1")) {
      if (item.prepared() && item.entity() == item.origin()) held.insert(item.entity());
    }
    return held == std::set<std::string>{"a", "a-b", "b", "b-c", "c", "c-d", "d"};
  })) << "the prepared holds never showed on both partitions";
  auto held = agents_.extract("routing-held");
  held.mapped().signal(SIGKILL);
  ASSERT_TRUE(held.mapped().wait_exit(kTimeout).has_value());
  EXPECT_FALSE(pending.get().has_value()) << "a killed agent cannot have answered";

  // Presumed abort: the holds expire on both partitions and nothing of v1 is left.
  ASSERT_TRUE(wait_until([&] { return reservations_of("v1").empty(); }))
      << "the held reservations of the killed routing agent never expired";

  // The same windows are free again: another routing agent reserves them for v2.
  ASSERT_TRUE(client_->wait_for_server(kTimeout, "routing-2").has_value());
  // Its replica follows the topology agents' timelines a moment later: ask until it has
  // taken in the expiry.
  msg::RouteReply reply;
  const auto deadline = std::chrono::steady_clock::now() + kTimeout;
  do {
    reply = call(route_request("v2", "a", "d", true, start), "routing-2");
    if (reply.error().code() == msg::ERROR_NONE) break;
    std::unique_lock lock(mutex_);
    changed_.wait_for(lock, 100ms);
  } while (std::chrono::steady_clock::now() < deadline);
  ASSERT_EQ(reply.error().code(), msg::ERROR_NONE) << reply.error().message();
  EXPECT_EQ(reply.steps().front().window().start(), start);
  EXPECT_EQ(reply.arrival(), start + seconds_to_ns(9)) << "v2 drove straight through, nothing in its way";
}

// A commit whose reply is lost may have been applied: the routing agent undoes it there too,
// so no partition keeps a route nobody knows of (here east applies it, its destination held
// for ever, and the client hears a failure).
TEST_F(RoutingAgentTest, ACommitOfUnknownOutcomeIsUndoneOnItsPartitionToo) {
  constexpr std::uint32_t kDomain = 55;
  use_line_topology();
  start("topology-west", {"topology-agent", "--topology", topology_file_, "--partition", "west", "--domain",
                          std::to_string(kDomain)});
  start("topology-east", {"topology-agent", "--topology", topology_file_, "--partition", "east", "--domain",
                          std::to_string(kDomain), "--drop-commit-replies"});
  start_routing_agent(kDomain, "routing-1");
  connect(kDomain, 2);

  const auto reply = call(route_request("v1", "a", "d", true, SharedClock::wall().now() + seconds_to_ns(60)));
  EXPECT_NE(reply.error().code(), msg::ERROR_NONE) << "the route was reported reserved";
  EXPECT_NE(reply.error().message().find("commit on topology agent 'topology-east'"), std::string::npos)
      << reply.error().message();
  ASSERT_TRUE(wait_until([&] { return reservations_of("v1").empty(); }))
      << "a partition keeps the route: " << reservations_of("v1").size() << " item(s) of v1 left";
}

// An operator's lock (droverctl lock, as a process) makes new routes go round the entity;
// unlocking it (droverctl unlock) makes it usable again.
TEST_F(RoutingAgentTest, LockMakesNewRoutesAvoidTheEntityAndUnlockRestoresIt) {
  constexpr std::uint32_t kDomain = 54;
  use_topology(kDetourTopology);
  start_topology_agents(kDomain, topology_file_);
  start_routing_agent(kDomain, "routing-1");
  connect(kDomain);
  const std::vector<std::string> straight{"a", "a-b", "b", "b-c", "c"};
  const std::vector<std::string> round{"a", "a-d", "d", "d-c", "c"};
  const TimeNs start = SharedClock::wall().now() + seconds_to_ns(60);

  auto before = call(route_request("v1", "a", "c", false, start));
  ASSERT_EQ(before.error().code(), msg::ERROR_NONE) << before.error().message();
  EXPECT_EQ(step_ids(before), straight);

  std::string out, err;
  const std::string domain = std::to_string(kDomain);
  auto status = droverctl({"lock", "b", "--from", "now", "--until", "forever", "--reason", "spill on the floor",
                           "--domain", domain, "--timeout", "30"},
                          out, err);
  ASSERT_TRUE(status.has_value());
  ASSERT_EQ(status->code, 0) << err;
  const std::string lock_id = out.substr(0, out.find('\n'));
  EXPECT_NE(lock_id.find('/'), std::string::npos) << "not a lock id: " << out;
  // The routing agent's replica learns the lock from the published timeline of b.
  EXPECT_TRUE(eventually_routes(route_request("v1", "a", "c", false, start), round))
      << "routes never went round the locked vertex b";
  // A real route too (later, out of the way of v2's routes below).
  auto real = call(route_request("v1", "a", "c", true, start + seconds_to_ns(1000)));
  ASSERT_EQ(real.error().code(), msg::ERROR_NONE) << real.error().message();
  EXPECT_EQ(step_ids(real), round);
  // A route that must end on b cannot be planned while it is locked.
  auto onto = call(route_request("v2", "c", "b", false, start));
  EXPECT_NE(onto.error().code(), msg::ERROR_NONE);
  EXPECT_EQ(onto.failure(), "locked") << onto.error().message();

  status = droverctl({"unlock", lock_id, "--domain", domain, "--timeout", "30"}, out, err);
  ASSERT_TRUE(status.has_value());
  ASSERT_EQ(status->code, 0) << err;
  EXPECT_TRUE(eventually_routes(route_request("v2", "c", "b", false, start), {"c", "b-c", "b"}))
      << "b stayed unusable after the unlock";
}

}  // namespace
}  // namespace drover::test
