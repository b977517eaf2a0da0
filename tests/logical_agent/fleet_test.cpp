// Logical agents as processes with a topology agent, a routing agent and simulated RANs on
// the bundled H-shaped crossing (launch/topologies/h_crossing.json). The test process
// watches what a user could watch: RAN statuses, timelines, notices, order progress,
// alarms. Domains 35..37, 45..49, 69, 83..93 and 99..101. Every agent is stopped with SIGTERM and must exit 0.

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <list>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <boost/geometry.hpp>
#include <nlohmann/json.hpp>
#include <gtest/gtest.h>

#include "drover/dds/heartbeat_publisher.hpp"
#include "drover/dds/participant.hpp"
#include "drover/dds/reader.hpp"
#include "drover/dds/service_client.hpp"
#include "drover/logical_agent/messages.hpp"
#include "drover/logical_agent/names.hpp"
#include "drover/ran/sim_driver.hpp"
#include "drover/ran_runner/client.hpp"
#include "drover/ran_runner/runner.hpp"
#include "agents/topology_agent/topology_agent.hpp"
#include "drover/topology/conflicts.hpp"
#include "drover/topology/topology_file.hpp"
#include "tests/agents/child_process.hpp"

namespace drover::test {
namespace {

namespace bg = boost::geometry;
using namespace std::chrono_literals;

/// Generous bound for a whole run on a loaded 2-core machine.
constexpr auto kRunTimeout = 240s;
constexpr double kTimeFactor = 2.0;
/// Two vehicle statuses this close on the shared clock show the vehicles at the same moment
/// (a simulated RAN reports every 0.1 s of real time, 0.2 s at kTimeFactor).
constexpr DurationNs kSameMoment = seconds_to_ns(0.3);

std::string source_dir() {
  const char* dir = std::getenv("DROVER_SOURCE_DIR");
  return dir ? dir : ".";
}

/// One process per agent; logs under the test's temporary directory.
class Fleet {
 public:
  Fleet(std::uint32_t domain, std::string name) : domain_(domain) {
    dir_ = std::filesystem::temp_directory_path() / ("drover-fleet-" + name + "-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
    topology_file_ = source_dir() + "/launch/topologies/h_crossing.json";
    vehicle_file_ = (dir_ / "vehicle.json").string();
    std::ofstream(vehicle_file_) << R"({"max_speed": 1.0, "acceleration": 0.5, "deceleration": 0.5,
                                       "length": 0.6, "width": 0.4})";
    origin_ = SharedClock::unix_now();
  }
  /// Stops every agent; removes the logs when the test passed (a failed test printed them,
  /// and keeps them under dir() for a closer look).
  ~Fleet() {
    stop();
    std::error_code ignored;
    if (::testing::Test::HasFailure()) {
      std::cerr << "logs kept in " << dir_.string() << "\n";
    } else {
      std::filesystem::remove_all(dir_, ignored);
    }
  }

  SharedClock clock() const { return *SharedClock::create_at_origin(origin_, kTimeFactor, origin_); }
  const std::string& topology_file() const { return topology_file_; }

  /// Uses `file` instead of the bundled H crossing (call before starting anything).
  void use_topology(std::string file) { topology_file_ = std::move(file); }
  const std::filesystem::path& dir() const { return dir_; }

  /// Starts `drover ARGS` on the fleet's domain and clock, logging to NAME.log.
  void start(const std::string& name, const std::vector<std::string>& args) {
    auto full = args;
    full.insert(full.end(), {"--domain", std::to_string(domain_), "--time-factor", std::to_string(kTimeFactor),
                             "--epoch", std::to_string(origin_), "--clock-origin", std::to_string(origin_)});
    // A restarted agent logs to NAME.restarted.log, so that its first life's log stays.
    auto log = (dir_ / (name + ".log")).string();
    if (std::filesystem::exists(log)) log = (dir_ / (name + ".restarted.log")).string();
    auto child = ChildProcess::spawn(binary_path("drover"), full, log, log);
    ASSERT_TRUE(child.has_value()) << name;
    children_.push_back(Child{name, args, std::move(*child)});
  }
  void start_infrastructure(const std::string& journal = {}) {
    std::vector<std::string> topology{"topology-agent", "--topology", topology_file_};
    if (!journal.empty()) topology.insert(topology.end(), {"--db", (dir_ / journal).string()});
    start("topology", topology);
    start("routing", {"routing-agent"});
  }
  /// A simulated RAN (extra options `ran`) and the logical agent (options `logical`, which
  /// default to neither parking nor charging).
  void start_vehicle(const std::string& id, const std::string& at, std::vector<std::string> ran = {},
                     std::vector<std::string> logical = {"--park-after", "-1", "--charge-below", "0"}) {
    start_ran(id, at, std::move(ran));
    start_logical(id, std::move(logical));
  }
  void start_ran(const std::string& id, const std::string& at, std::vector<std::string> options = {}) {
    std::vector<std::string> args{"ran-sim", "--id", id, "--topology", topology_file_, "--at", at, "--max-speed", "1",
                                  "--acceleration", "0.5", "--deceleration", "0.5"};
    args.insert(args.end(), options.begin(), options.end());
    start("ran-" + id, args);
  }
  void start_logical(const std::string& id, std::vector<std::string> options) {
    std::vector<std::string> args{"logical-agent", "--id", id, "--topology", topology_file_, "--vehicle", vehicle_file_};
    args.insert(args.end(), options.begin(), options.end());
    start(id, args);
  }
  /// SIGKILL to the agent started as `name` (a crash), then the same agent again.
  void crash_and_restart(const std::string& name) {
    std::vector<std::string> args;
    ASSERT_NO_FATAL_FAILURE(crash(name, &args));
    start(name, args);
  }
  /// SIGKILL to the agent started as `name` (a crash); its arguments go to `args` if given.
  void crash(const std::string& name, std::vector<std::string>* args = nullptr) {
    auto found = std::find_if(children_.begin(), children_.end(), [&](const Child& c) { return c.name == name; });
    ASSERT_NE(found, children_.end()) << name;
    found->process.signal(SIGKILL);
    ASSERT_TRUE(found->process.wait_exit(30s).has_value()) << name << " survived SIGKILL";
    if (args != nullptr) *args = found->args;
    children_.erase(found);
  }
  /// SIGTERM to everyone, newest first; each must exit 0.
  void stop() {
    while (!children_.empty()) stop(std::prev(children_.end()));
  }
  /// SIGTERM to the agent started as `name`; it must exit 0.
  void stop(const std::string& name) {
    auto found = std::find_if(children_.begin(), children_.end(), [&](const Child& c) { return c.name == name; });
    ASSERT_NE(found, children_.end()) << name;
    stop(found);
  }

 private:
  struct Child {
    std::string name;
    std::vector<std::string> args;
    ChildProcess process;
  };
  void stop(std::list<Child>::iterator child) {
    child->process.signal(SIGTERM);
    const auto status = child->process.wait_exit(30s);
    EXPECT_TRUE(status.has_value()) << child->name << " did not stop on SIGTERM";
    if (status) {
      EXPECT_TRUE(status->exited && status->code == 0) << child->name << " ended with " << status->code;
    }
    if (::testing::Test::HasFailure()) {
      std::cerr << "---- " << child->name << " ----\n" << read_file((dir_ / (child->name + ".log")).string());
      const auto restarted = dir_ / (child->name + ".restarted.log");
      if (std::filesystem::exists(restarted)) std::cerr << "---- " << child->name << " restarted ----\n" << read_file(restarted.string());
    }
    children_.erase(child);
  }
  std::uint32_t domain_;
  std::filesystem::path dir_;
  std::string topology_file_;
  std::string vehicle_file_;
  TimeNs origin_ = 0;
  std::list<Child> children_;  // a list: ChildProcess cannot be move-assigned
};

/// A RAN with faults the test injects: the simulated vehicle, whose reports can be made to
/// drift sideways (a slipping wheel, a localisation error: what footprint monitoring must
/// catch) or to leave out commands the driver dropped (a driver bug: what the command watch
/// must catch).
class FaultyDriver final : public ran::VehicleDriver {
 public:
  explicit FaultyDriver(ran::SimVehicle vehicle) : sim_(std::move(vehicle)) {}

  void start(ran::StatusSink& sink, TimeNs now) override {
    faulty_.target = &sink;
    sim_.start(faulty_, now);
  }
  void stop(TimeNs now) override { sim_.stop(now); }
  void on_move(const ran::MoveCommand& command, TimeNs now) override { sim_.on_move(command, now); }
  void on_action(const ran::ActionCommand& command, TimeNs now) override { sim_.on_action(command, now); }
  void on_cancel(const ran::CommandId& command, TimeNs now) override { sim_.on_cancel(command, now); }
  void on_pause(TimeNs now) override { sim_.on_pause(now); }
  void on_resume(TimeNs now) override { sim_.on_resume(now); }
  void on_tick(TimeNs now) override { sim_.on_tick(now); }
  // Call the faults through RanRunner::with_driver (never concurrently with the calls above).
  /// From now on, every report is `dx` metres further along x.
  void drift(double dx) { faulty_.dx = dx; }
  /// While `left_out`, every report carries an empty footprint (no valid polygon).
  void leave_out_footprint(bool left_out) { faulty_.no_footprint = left_out; }
  /// Drops every command not yet ended: the vehicle stops, and no report lists them again,
  /// as if they had never been given. \return how many were dropped.
  std::size_t drop_unended(TimeNs now) {
    std::vector<ran::CommandId> unended;
    for (const auto& command : faulty_.last.commands) {
      if (!ran::is_terminal(command.state)) unended.push_back(command.id);
    }
    if (unended.empty()) return 0;
    faulty_.hidden.insert(unended.begin(), unended.end());
    sim_.on_cancel(unended.front(), now);  // cancels the rest too
    return unended.size();
  }

 private:
  struct FaultySink final : ran::StatusSink {
    ran::StatusSink* target = nullptr;
    double dx = 0;
    bool no_footprint = false;
    std::set<ran::CommandId> hidden;
    ran::VehicleStatus last;  ///< as the vehicle reported it
    void deliver(const ran::VehicleStatus& status) override {
      last = status;
      ran::VehicleStatus faulty = status;
      std::erase_if(faulty.commands, [&](const ran::CommandProgress& command) { return hidden.contains(command.id); });
      faulty.pose.x += dx;
      faulty.footprint.clear();
      if (!no_footprint) {
        bg::transform(status.footprint, faulty.footprint,
                      bg::strategy::transform::translate_transformer<double, 2, 2>(dx, 0));
      }
      target->report(std::move(faulty));
    }
  };
  ran::SimDriver sim_;
  FaultySink faulty_;
};

/// Everything the test observes, in arrival order, with the shared-clock time of arrival.
struct Observations {
  std::mutex mutex;
  std::condition_variable changed;
  std::map<std::string, msg::OrderProgress> orders;
  std::vector<msg::ReservationNotice> notices;
  std::vector<msg::OperatorAlarm> alarms;
  std::map<std::string, std::string> holders;                       ///< entity -> agent, now
  std::vector<std::string> hold_violations;                         ///< conflicting holders seen
  std::map<std::string, ran::VehicleStatus> latest;                 ///< vehicle -> status
  std::map<std::string, msg::VehicleState> vehicles;                ///< vehicle -> logical agent's state
  std::vector<std::string> overlaps;                                ///< footprints overlapping
  std::map<std::string, std::vector<std::pair<TimeNs, TimeNs>>> on_bar;  ///< vehicle -> times on bar-2
  std::map<std::string, std::vector<std::pair<TimeNs, std::string>>> holder_log;  ///< entity -> (time, allocated to)
  std::map<std::string, std::uint64_t> last_serial;                ///< of each topology agent's last event
  std::vector<std::string> cancelled;                               ///< agents whose route was cancelled
  std::vector<std::pair<TimeNs, std::string>> releases;             ///< (time, agent) of each release
  std::map<std::string, std::vector<TimeNs>> status_times;          ///< vehicle -> times of its statuses

  bool wait(const std::function<bool()>& condition, std::chrono::seconds timeout) {
    std::unique_lock lock(mutex);
    return changed.wait_for(lock, timeout, condition);
  }
};

class FleetTest : public ::testing::Test {
 protected:
  /// Follows what `fleet` on `domain` does: orders, vehicle states, notices, alarms, the
  /// events of its `topology_agents` topology agents (waited for: none may be missed) and
  /// the statuses of `vehicles`.
  void watch(std::uint32_t domain, const Fleet& fleet, const std::vector<std::string>& vehicles,
             std::size_t topology_agents = 1) {
    auto loaded = topology::load_topology_file(fleet.topology_file());
    ASSERT_TRUE(loaded.has_value());
    world_ = std::make_shared<topology::Topology>(std::move(*loaded));
    clock_ = fleet.clock();
    dds::ParticipantOptions options;
    options.domain_id = domain;
    options.agent_id = "tester";
    auto participant = dds::Participant::create(options);
    ASSERT_TRUE(participant.has_value()) << participant.error().message;
    participant_ = std::move(*participant);
    // The tester beats like an agent: droverctl's discovery (vehicles, orders, pause --all)
    // then ends once every participant present has shown its heartbeat, instead of always
    // at its timeout with what it heard by then.
    dds::HeartbeatOptions beat;
    beat.kind = "tester";
    auto heartbeat = dds::HeartbeatPublisher::create(*participant_, *clock_, std::move(beat));
    ASSERT_TRUE(heartbeat.has_value()) << heartbeat.error().message;
    heartbeat_ = std::move(*heartbeat);

    auto progress = dds::Reader<msg::OrderProgress>::create(*participant_, logical_agent::kOrderProgressTopic,
                                                            [this](const msg::OrderProgress& sample) {
                                                              std::lock_guard lock(seen_.mutex);
                                                              seen_.orders[sample.order()] = sample;
                                                              seen_.changed.notify_all();
                                                            });
    ASSERT_TRUE(progress.has_value());
    progress_ = std::move(*progress);
    auto states = dds::Reader<msg::VehicleState>::create(*participant_, logical_agent::kVehicleStateTopic,
                                                           [this](const msg::VehicleState& sample) {
                                                             std::lock_guard lock(seen_.mutex);
                                                             seen_.vehicles[sample.vehicle()] = sample;
                                                             seen_.changed.notify_all();
                                                           });
    ASSERT_TRUE(states.has_value());
    vehicle_states_ = std::move(*states);
    dds::ReaderOptions events;
    events.qos = dds::TopicQos::events();
    auto notices = dds::Reader<msg::ReservationNotice>::create(
        *participant_, "drover/topology/notices",
        [this](const msg::ReservationNotice& notice) {
          std::lock_guard lock(seen_.mutex);
          seen_.notices.push_back(notice);
          seen_.changed.notify_all();
        },
        events);
    ASSERT_TRUE(notices.has_value());
    notices_ = std::move(*notices);
    auto alarms = dds::Reader<msg::OperatorAlarm>::create(
        *participant_, logical_agent::kAlarmTopic,
        [this](const msg::OperatorAlarm& alarm) {
          std::lock_guard lock(seen_.mutex);
          seen_.alarms.push_back(alarm);
          seen_.changed.notify_all();
        },
        // An agent's alarm may be raised before this reader matched it (a restored order
        // failing at start-up): its writer keeps it for us.
        dds::ReaderOptions{logical_agent::alarm_reader_qos(), {}, {}});
    ASSERT_TRUE(alarms.has_value());
    alarms_ = std::move(*alarms);
    // Holds are followed from the topology agent's events, which carry one serial order: the
    // timelines are keyed per entity, and a reader may deliver two entities' updates in
    // another order than they were made in.
    auto topology_events = dds::Reader<msg::TopologyEvent>::create(
        *participant_, topology_agent::kEventTopic, [this](const msg::TopologyEvent& event) { on_event(event); },
        events);
    ASSERT_TRUE(topology_events.has_value());
    topology_events_ = std::move(*topology_events);
    for (const auto& vehicle : vehicles) {
      auto client = ran::RanClient::create(*participant_, vehicle, {}, 16,
                                           [this](const ran::VehicleStatus& status) { on_status(status); });
      ASSERT_TRUE(client.has_value()) << client.error().message;
      rans_[vehicle] = std::move(*client);
    }
    auto orders = dds::ServiceClient<msg::OrderRequest, msg::OrderReply>::create(
        *participant_, logical_agent::kServiceArea, logical_agent::kOrderService);
    ASSERT_TRUE(orders.has_value());
    order_client_ = std::move(*orders);
    // Nothing the topology agent does may be missed.
    ASSERT_TRUE(topology_events_->wait_for_writers(topology_agents, 60s))
        << "the topology agents' events never matched";
  }

  /// How many routes of `vehicle` the topology agents reported cancelled so far.
  std::size_t cancels_of(const std::string& vehicle) {
    std::lock_guard lock(seen_.mutex);
    return static_cast<std::size_t>(std::count(seen_.cancelled.begin(), seen_.cancelled.end(), vehicle));
  }

  /// Waits until the topology agent cancelled a route of `vehicle` beyond the first
  /// `cancels_before` (cancels_of) and released every one of `ahead` it held: the agent
  /// cancels first and releases its allocations one by one after.
  ::testing::AssertionResult gives_up_route(const std::string& vehicle, std::size_t cancels_before,
                                            std::initializer_list<const char*> ahead) {
    const auto cancelled = [&] {
      return static_cast<std::size_t>(std::count(seen_.cancelled.begin(), seen_.cancelled.end(), vehicle)) >
             cancels_before;
    };
    const auto still_held = [&] {
      for (const auto* entity : ahead) {
        if (seen_.holders[entity] == vehicle) return std::string(entity);
      }
      return std::string();
    };
    if (seen_.wait([&] { return cancelled() && still_held().empty(); }, 60s)) return ::testing::AssertionSuccess();
    std::lock_guard lock(seen_.mutex);
    if (!cancelled()) return ::testing::AssertionFailure() << vehicle << "'s route was not cancelled";
    return ::testing::AssertionFailure() << vehicle << " still holds " << still_held();
  }

  /// Whether `vehicle` raised an alarm of `severity` whose text contains `part`.
  /// \pre seen_.mutex is held
  bool alarm_seen(msg::AlarmSeverity severity, const std::string& vehicle, const std::string& part) const {
    return std::any_of(seen_.alarms.begin(), seen_.alarms.end(), [&](const msg::OperatorAlarm& alarm) {
      return alarm.severity() == severity && alarm.vehicle() == vehicle && alarm.text().find(part) != std::string::npos;
    });
  }

  void TearDown() override {
    order_client_.reset();
    rans_.clear();
    topology_events_.reset();
    alarms_.reset();
    notices_.reset();
    vehicle_states_.reset();
    progress_.reset();
    heartbeat_.reset();
    participant_.reset();
  }

  void on_event(const msg::TopologyEvent& event) {
    std::lock_guard lock(seen_.mutex);
    // Each topology agent numbers its events 1, 2, 3, ...; a restarted one anew from 1, and
    // its first ones may be written before its writer matched this reader (VOLATILE), so
    // its next life starts at whatever serial arrives first.
    auto& last = seen_.last_serial[event.source()];
    const bool first = last == 0 || event.serial() <= last;
    if (!first && event.serial() != last + 1) {
      seen_.hold_violations.push_back("topology event " + std::to_string(event.serial()) + " of " + event.source() +
                                      " after " + std::to_string(last) + ": events lost or out of order");
    }
    last = event.serial();
    if (event.kind() == msg::EVENT_CANCELLED) seen_.cancelled.push_back(event.agent());
    if (event.kind() == msg::EVENT_RELEASED) {
      seen_.releases.emplace_back(event.time(), event.agent());
      if (seen_.holders[event.entity()] == event.agent()) seen_.holders[event.entity()].clear();
    } else if (event.kind() == msg::EVENT_ALLOCATED) {
      seen_.holders[event.entity()] = event.agent();
      seen_.holder_log[event.entity()].emplace_back(event.time(), event.agent());
      const auto entity = world_->find(event.entity());
      if (!entity) return;
      for (const auto other : world_->conflicts(*entity)) {
        const auto& holder = seen_.holders[world_->id(other)];
        if (!holder.empty() && holder != event.agent()) {
          seen_.hold_violations.push_back(event.agent() + " holds " + event.entity() + " while " + holder +
                                          " holds " + world_->id(other));
        }
      }
    }
    seen_.changed.notify_all();
  }

  void on_status(const ran::VehicleStatus& status) {
    std::lock_guard lock(seen_.mutex);
    seen_.latest[status.vehicle_id] = status;
    seen_.status_times[status.vehicle_id].push_back(status.time);
    for (const auto& [other, other_status] : seen_.latest) {
      if (other == status.vehicle_id) continue;
      // Only footprints of about the same moment: each vehicle's statuses arrive on a reader
      // thread of their own, and one that lags would show a vehicle where it no longer is.
      // Both report every 0.2 s (shared clock), so an overlap that lasts is still compared
      // (not with a vehicle whose RAN went silent: no test here drives into one).
      if (std::abs(status.time - other_status.time) > kSameMoment) continue;
      const double area = topology::footprint_overlap_area(status.footprint, other_status.footprint);
      if (area > 1e-6) {
        seen_.overlaps.push_back(status.vehicle_id + " and " + other + " overlap by " + std::to_string(area) + " m^2");
      }
    }
    const bool on = bg::intersects(status.footprint, world_->footprint(*world_->find("bar-2")));
    auto& spans = seen_.on_bar[status.vehicle_id];
    if (on) {
      if (spans.empty() || spans.back().second != 0) spans.emplace_back(status.time, 0);
    } else if (!spans.empty() && spans.back().second == 0) {
      spans.back().second = status.time;
    }
    seen_.changed.notify_all();
  }

  /// Sends an order; \return the reply's error message ("" when queued).
  std::string send_order(const std::string& vehicle, const std::string& name,
                         const std::vector<std::pair<std::string, std::string>>& destinations) {
    msg::OrderRequest request;
    request.order(name);
    for (const auto& [location, operation] : destinations) {
      msg::OrderDestination destination;
      destination.location(location);
      destination.operation(operation);
      request.destinations().push_back(destination);
    }
    auto reply = order_client_->call(request, 60s, vehicle);
    if (!reply) return reply.error().message;
    return reply->error().code() == msg::ERROR_NONE ? "" : reply->error().message();
  }

  /// Waits until the order ended. \return its last progress.
  std::optional<msg::OrderProgress> wait_order(const std::string& name) {
    std::optional<msg::OrderProgress> out;
    seen_.wait(
        [&] {
          auto found = seen_.orders.find(name);
          if (found == seen_.orders.end()) return false;
          const auto state = found->second.state();
          if (state != msg::ORDER_FINISHED && state != msg::ORDER_FAILED && state != msg::ORDER_WITHDRAWN) {
            return false;
          }
          out = found->second;
          return true;
        },
        std::chrono::duration_cast<std::chrono::seconds>(kRunTimeout));
    return out;
  }

  /// Waits until a status of `vehicle` satisfies `condition`.
  bool wait_status(const std::string& vehicle, const std::function<bool(const ran::VehicleStatus&)>& condition,
                   std::chrono::seconds timeout = 120s) {
    return seen_.wait(
        [&] {
          auto found = seen_.latest.find(vehicle);
          return found != seen_.latest.end() && condition(found->second);
        },
        timeout);
  }

  /// Waits until the state `vehicle`'s logical agent publishes satisfies `condition`.
  bool wait_vehicle_state(const std::string& vehicle, const std::function<bool(const msg::VehicleState&)>& condition,
                          std::chrono::seconds timeout = 60s) {
    return seen_.wait(
        [&] {
          auto found = seen_.vehicles.find(vehicle);
          return found != seen_.vehicles.end() && condition(found->second);
        },
        timeout);
  }

  /// Starts vehicle V1 on left-0, sends it order `name` to right-4 and waits until it drives.
  void send_v1_across(Fleet& fleet, const std::string& name) {
    fleet.start_vehicle("V1", "left-0");
    ASSERT_TRUE(wait_ready("V1", "left-0"));
    ASSERT_EQ(send_order("V1", name, {{"right-4", "NOP"}}), "");
    ASSERT_TRUE(wait_status("V1", [](const ran::VehicleStatus& s) { return s.pose.y > 1.0; })) << "V1 never started";
  }

  /// The crossing's usual start: infrastructure (the topology agent journaling to `journal`
  /// when given), V1 on left-0 and V2 on right-0, both ready. Call through
  /// ASSERT_NO_FATAL_FAILURE.
  void start_two_vehicles(Fleet& fleet, std::uint32_t domain, const std::string& journal = {}) {
    fleet.start_infrastructure(journal);
    watch(domain, fleet, {"V1", "V2"});
    fleet.start_vehicle("V1", "left-0");
    fleet.start_vehicle("V2", "right-0");
    ASSERT_TRUE(wait_ready("V1", "left-0"));
    ASSERT_TRUE(wait_ready("V2", "right-0"));
  }

  /// The crossing's usual start (the topology agent journaling to `journal` when given),
  /// then V1 sent to the station right-4 (order v1-lost), until it drives. Call through
  /// ASSERT_NO_FATAL_FAILURE.
  void start_v1_towards_the_station(Fleet& fleet, std::uint32_t domain, const std::string& journal = {}) {
    ASSERT_NO_FATAL_FAILURE(start_two_vehicles(fleet, domain, journal));
    ASSERT_EQ(send_order("V1", "v1-lost", {{"right-4", "NOP"}}), "");
    ASSERT_TRUE(wait_status("V1", [](const ran::VehicleStatus& s) { return s.pose.y > 1.0; })) << "V1 never started";
  }

  /// After an agent's crash: the crossing orders v1-there and v2-there finish, then a new
  /// order v1-back to left-0 (which needs the restarted agent), with no two footprints
  /// overlapping and no alarm. Call through ASSERT_NO_FATAL_FAILURE.
  void expect_crossing_orders_and_one_more_finish() {
    const auto first = wait_order("v1-there");
    const auto second = wait_order("v2-there");
    ASSERT_TRUE(first && second) << "an order did not end";
    EXPECT_EQ(first->state(), msg::ORDER_FINISHED) << first->failure();
    EXPECT_EQ(second->state(), msg::ORDER_FINISHED) << second->failure();
    ASSERT_EQ(send_order("V1", "v1-back", {{"left-0", "NOP"}}), "");
    const auto back = wait_order("v1-back");
    ASSERT_TRUE(back.has_value());
    EXPECT_EQ(back->state(), msg::ORDER_FINISHED) << back->failure();

    std::lock_guard lock(seen_.mutex);
    EXPECT_TRUE(seen_.overlaps.empty()) << seen_.overlaps.front();
    for (const auto& alarm : seen_.alarms) ADD_FAILURE() << "alarm: " << alarm.text();
  }

  /// The infrastructure, and V1 on left-0 (a load takes it 20 s) whose logical agent keeps an
  /// order journal (its options go to `logical`); sends V1 order "pallet" (load at left-4,
  /// unload at right-4) and order "home" (to left-0) behind it, and waits until V1 loads at
  /// left-4. Call through ASSERT_NO_FATAL_FAILURE.
  void start_v1_loading_with_an_order_journal(Fleet& fleet, std::uint32_t domain, std::vector<std::string>& logical) {
    fleet.start_infrastructure();
    watch(domain, fleet, {"V1"});
    fleet.start_ran("V1", "left-0", {"--load-duration", "20"});
    logical = {"--park-after", "-1", "--charge-below", "0", "--db", (fleet.dir() / "V1.db").string()};
    fleet.start_logical("V1", logical);
    ASSERT_TRUE(wait_ready("V1", "left-0"));
    ASSERT_EQ(send_order("V1", "pallet", {{"left-4", "load"}, {"right-4", "unload"}}), "");
    ASSERT_EQ(send_order("V1", "home", {{"left-0", "NOP"}}), "");
    const auto left4 = world_->vertex(*world_->find("left-4")).position;
    // One command running for a second at rest on left-4: the load (20 s). The move there
    // may still be listed running for a report after the vehicle came to rest, and a crash
    // then would hit the load's command on its way instead of the load.
    std::optional<std::pair<ran::CommandId, TimeNs>> resting;  // that command, since
    ASSERT_TRUE(wait_status("V1", [&](const ran::VehicleStatus& s) {
      const auto running = std::find_if(s.commands.begin(), s.commands.end(), [](const ran::CommandProgress& c) {
        return c.state == ran::CommandState::running;
      });
      if (std::hypot(s.pose.x - left4.x(), s.pose.y - left4.y()) >= 0.05 || s.linear_speed != 0 ||
          running == s.commands.end()) {
        resting.reset();
        return false;
      }
      if (!resting || resting->first != running->id) resting.emplace(running->id, s.time);
      return s.time - resting->second >= seconds_to_ns(1);
    })) << "V1 never loaded at left-4";
  }

  /// Waits until the vehicle's logical agent holds its start vertex (it is ready).
  bool wait_ready(const std::string& vehicle, const std::string& vertex) {
    return seen_.wait([&] { return seen_.holders[vertex] == vehicle; }, 60s);
  }

  /// V1's RAN run in this process, so that the test can inject faults through `driver`.
  struct InProcessRan {
    std::unique_ptr<FaultyDriver> driver;
    std::unique_ptr<ran::RanNode> node;
  };
  /// Starts V1's in-process RAN on `domain`, its vehicle standing on `vertex`. \pre watch()
  /// called. \return nullopt (with a test failure) if it did not start.
  std::optional<InProcessRan> start_faulty_ran(std::uint32_t domain, const std::string& vertex) {
    ran::SimVehicleConfig config;
    config.vehicle_id = "V1";
    config.max_speed = 1;
    config.acceleration = 0.5;
    config.deceleration = 0.5;
    const auto& start = world_->vertex(*world_->find(vertex)).position;
    auto vehicle = ran::SimVehicle::create(config, ran::Pose{start.x(), start.y(), 0}, clock_->now(), world_);
    if (!vehicle) {
      ADD_FAILURE() << vehicle.error().message;
      return std::nullopt;
    }
    InProcessRan ran{std::make_unique<FaultyDriver>(std::move(*vehicle)), nullptr};
    ran::RanNodeOptions options;
    options.vehicle_id = "V1";
    options.domain_id = domain;
    auto node = ran::RanNode::create(*ran.driver, options, *clock_);
    if (!node) {
      ADD_FAILURE() << node.error().message;
      return std::nullopt;
    }
    ran.node = std::move(*node);
    return ran;
  }

  /// The infrastructure, V1 on left-0 with its RAN in this process (`ran`), and V1 sent to
  /// right-4 by order `order`: returns once it drives. Call through ASSERT_NO_FATAL_FAILURE.
  void send_v1_off_on_a_faulty_ran(Fleet& fleet, std::uint32_t domain, const std::string& order,
                                   std::optional<InProcessRan>& ran) {
    fleet.start_infrastructure();
    watch(domain, fleet, {"V1"});
    ran = start_faulty_ran(domain, "left-0");
    ASSERT_TRUE(ran.has_value());
    fleet.start_logical("V1", {"--park-after", "-1", "--charge-below", "0"});
    ASSERT_TRUE(wait_ready("V1", "left-0"));
    ASSERT_EQ(send_order("V1", order, {{"right-4", "NOP"}}), "");
    ASSERT_TRUE(wait_status("V1", [](const ran::VehicleStatus& s) { return s.pose.y > 1.0; })) << "V1 never started";
  }

  std::shared_ptr<topology::Topology> world_;
  std::optional<SharedClock> clock_;
  Observations seen_;
  std::unique_ptr<dds::Participant> participant_;
  std::unique_ptr<dds::HeartbeatPublisher> heartbeat_;
  std::unique_ptr<dds::Reader<msg::OrderProgress>> progress_;
  std::unique_ptr<dds::Reader<msg::VehicleState>> vehicle_states_;
  std::unique_ptr<dds::Reader<msg::ReservationNotice>> notices_;
  std::unique_ptr<dds::Reader<msg::OperatorAlarm>> alarms_;
  std::unique_ptr<dds::Reader<msg::TopologyEvent>> topology_events_;
  std::map<std::string, std::unique_ptr<ran::RanClient>> rans_;
  std::unique_ptr<dds::ServiceClient<msg::OrderRequest, msg::OrderReply>> order_client_;
};

/// Polls `condition`, state that no callback reports (a RAN client's refusals), until it
/// holds or `timeout` passes. \return whether it holds.
bool poll_until(const std::function<bool()>& condition, std::chrono::seconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (!condition()) {
    if (std::chrono::steady_clock::now() >= deadline) return false;
    std::this_thread::sleep_for(10ms);
  }
  return true;
}

/// Runs droverctl to its end. \return its exit code (-1 if it did not end); output in out/err.
/// Without a --timeout in `args` it gets a generous one: its defaults (2 s, 5 s) are for an
/// operator's terminal, not for discovering a fleet on a loaded 2-core host. Commands end
/// once discovery is complete; `orders` alone listens for its whole timeout.
int droverctl(const Fleet& fleet, const std::string& name, std::vector<std::string> args, std::string& out,
              std::string& err) {
  if (std::find(args.begin(), args.end(), "--timeout") == args.end()) {
    args.insert(args.end(), {"--timeout", args.front() == "orders" ? "10" : "30"});
  }
  const std::string stem = (fleet.dir() / ("droverctl-" + name)).string();
  auto child = ChildProcess::spawn(binary_path("droverctl"), args, stem + ".out", stem + ".err");
  if (!child) return -1;
  auto status = child->wait_exit(kRunTimeout);
  out = read_file(stem + ".out");
  err = read_file(stem + ".err");
  return status && status->exited ? status->code : -1;
}

TEST_F(FleetTest, CrossingVehiclesBothFinishAndTheLaterWaitsForTheEarlier) {
  constexpr std::uint32_t kDomain = 86;
  Fleet fleet(kDomain, "crossing");
  ASSERT_NO_FATAL_FAILURE(start_two_vehicles(fleet, kDomain));

  // V1 through droverctl, as an operator would; V2 directly.
  auto sender = ChildProcess::spawn(binary_path("droverctl"),
                                    {"order", "send", "V1", "right-4:NOP", "--name", "v1-cross", "--domain",
                                     std::to_string(kDomain), "--timeout", "60"});
  ASSERT_TRUE(sender.has_value());
  const auto sent = sender->wait_exit(90s);
  ASSERT_TRUE(sent.has_value());
  ASSERT_EQ(sent->code, 0);
  ASSERT_EQ(send_order("V2", "v2-cross", {{"left-4", "NOP"}}), "");

  const auto first = wait_order("v1-cross");
  const auto second = wait_order("v2-cross");
  ASSERT_TRUE(first && second) << "an order did not end: deadlock?";
  EXPECT_EQ(first->state(), msg::ORDER_FINISHED) << first->failure();
  EXPECT_EQ(second->state(), msg::ORDER_FINISHED) << second->failure();
  EXPECT_EQ(first->destination(), 1u);

  {
    // Names are unique per vehicle: V2 takes one V1's finished order has. droverctl's wait
    // is for V2's (before, V1's kept progress ended it at once, V2 still on left-4).
    std::string out, err;
    ASSERT_EQ(droverctl(fleet, "same-name", {"order", "send", "V2", "left-0:NOP", "--name", "v1-cross", "--wait", "120",
                                             "--domain", std::to_string(kDomain)},
                        out, err),
              0)
        << out << err;
    const TimeNs returned = clock_->now();
    EXPECT_NE(out.find("order 'v1-cross' finished"), std::string::npos) << out;
    const auto finished_by_v2 = [&] {
      const auto found = seen_.orders.find("v1-cross");
      return found != seen_.orders.end() && found->second.vehicle() == "V2" &&
             found->second.state() == msg::ORDER_FINISHED;
    };
    ASSERT_TRUE(seen_.wait(finished_by_v2, 120s)) << "V2's order did not finish";
    std::lock_guard lock(seen_.mutex);
    EXPECT_LE(seen_.orders["v1-cross"].finished().ns(), returned) << "droverctl said finished before V2's order was";
  }

  std::lock_guard lock(seen_.mutex);
  EXPECT_TRUE(seen_.hold_violations.empty()) << seen_.hold_violations.front();
  EXPECT_TRUE(seen_.overlaps.empty()) << seen_.overlaps.front();
  EXPECT_TRUE(seen_.alarms.empty()) << seen_.alarms.front().text();
  // Both crossed the bar's middle, one after the other.
  const auto& v1 = seen_.on_bar["V1"];
  const auto& v2 = seen_.on_bar["V2"];
  ASSERT_EQ(v1.size(), 1u);
  ASSERT_EQ(v2.size(), 1u);
  const auto& earlier = v1.front().first < v2.front().first ? v1.front() : v2.front();
  const auto& later = v1.front().first < v2.front().first ? v2.front() : v1.front();
  EXPECT_NE(earlier.second, 0) << "the earlier vehicle never left bar-2";
  EXPECT_GE(later.first, earlier.second) << "the later vehicle entered bar-2 before the earlier left it";
  // V1 ends where it was sent, holding its destination.
  EXPECT_EQ(seen_.holders["right-4"], "V1");
}

TEST_F(FleetTest, StalledVehiclePropagatesADelayTheOtherFollowsAndBothFinish) {
  constexpr std::uint32_t kDomain = 87;
  Fleet fleet(kDomain, "stall");
  fleet.start_infrastructure();
  watch(kDomain, fleet, {"V1", "V2"});
  fleet.start_vehicle("V1", "left-0");
  // V2 tells the operator once it has waited 4 s for one allocation.
  fleet.start_vehicle("V2", "right-0", {}, {"--park-after", "-1", "--charge-below", "0", "--wait-alarm", "4"});
  ASSERT_TRUE(wait_ready("V1", "left-0"));
  ASSERT_TRUE(wait_ready("V2", "right-0"));
  ASSERT_EQ(send_order("V1", "v1-stall", {{"right-4", "NOP"}}), "");
  // V2's order only once V1 drives (its route is reserved): V1 is then first on the bar.
  ASSERT_TRUE(seen_.wait(
      [&] {
        auto found = seen_.latest.find("V1");
        return found != seen_.latest.end() && found->second.pose.y > 0.1;
      },
      120s))
      << "V1 never started";
  ASSERT_EQ(send_order("V2", "v2-stall", {{"left-4", "NOP"}}), "");

  // Stall V1 as soon as it drives on the bar (ahead of V2, which waits for it).
  ASSERT_TRUE(seen_.wait(
      [&] {
        auto found = seen_.latest.find("V1");
        return found != seen_.latest.end() && found->second.pose.x > 1.5 && found->second.pose.x < 8;
      },
      120s))
      << "V1 never reached the bar";
  std::size_t notices_before = 0;
  {
    std::lock_guard lock(seen_.mutex);
    notices_before = seen_.notices.size();
  }
  ASSERT_TRUE(rans_["V1"]->inject_fault(ran::SimFault::stall, seconds_to_ns(10), 10s));

  // V1 propagates a delay; V2's reservations are pushed (it is told and follows).
  EXPECT_TRUE(seen_.wait(
      [&] {
        bool v1 = false;
        bool v2 = false;
        for (std::size_t i = notices_before; i < seen_.notices.size(); ++i) {
          const auto& notice = seen_.notices[i];
          if (notice.kind() != msg::NOTICE_SHIFTED) continue;
          v1 = v1 || notice.agent() == "V1";
          v2 = v2 || notice.agent() == "V2";
        }
        return v1 && v2;
      },
      120s))
      << "no delay of V1 pushing V2 was seen";

  const auto first = wait_order("v1-stall");
  const auto second = wait_order("v2-stall");
  ASSERT_TRUE(first && second) << "an order did not end: deadlock?";
  EXPECT_EQ(first->state(), msg::ORDER_FINISHED) << first->failure();
  EXPECT_EQ(second->state(), msg::ORDER_FINISHED) << second->failure();
  std::lock_guard lock(seen_.mutex);
  EXPECT_TRUE(seen_.hold_violations.empty()) << seen_.hold_violations.front();
  EXPECT_TRUE(seen_.overlaps.empty()) << seen_.overlaps.front();
  const auto& v1 = seen_.on_bar["V1"];
  const auto& v2 = seen_.on_bar["V2"];
  ASSERT_EQ(v1.size(), 1u);
  ASSERT_EQ(v2.size(), 1u);
  EXPECT_GE(v2.front().first, v1.front().second) << "V2 overtook the stalled V1 on bar-2";
  // Held up for the 10 s of the stall, V2 warned the operator, once per entity it waited
  // for; V1 had nothing to say.
  std::set<std::string> waited_for;
  for (const auto& alarm : seen_.alarms) {
    if (alarm.vehicle() != "V2" || alarm.text().find("has waited") == std::string::npos) continue;
    EXPECT_EQ(alarm.severity(), msg::ALARM_WARNING) << alarm.text();
    EXPECT_TRUE(waited_for.insert(alarm.text().substr(alarm.text().find(" for "))).second)
        << "warned twice: " << alarm.text();
  }
  EXPECT_FALSE(waited_for.empty()) << "V2 did not warn of its wait";
  for (const auto& alarm : seen_.alarms) EXPECT_NE(alarm.vehicle(), "V1") << alarm.text();
}

TEST_F(FleetTest, LockOnThePlannedRouteMakesTheVehicleReplanAroundIt) {
  constexpr std::uint32_t kDomain = 88;
  Fleet fleet(kDomain, "lock");
  fleet.start_infrastructure();
  watch(kDomain, fleet, {"V1"});
  // Once V1 has its route (it moves), lock bar-3 ahead of it for 30 s.
  ASSERT_NO_FATAL_FAILURE(send_v1_across(fleet, "v1-lock"));
  auto lock_client = dds::ServiceClient<msg::LockRequest, msg::LockReply>::create(*participant_, "topology", "lock");
  ASSERT_TRUE(lock_client.has_value());
  msg::LockRequest lock;
  lock.entity("bar-3");
  const TimeNs lock_start = clock_->now();
  const TimeNs lock_end = lock_start + seconds_to_ns(30);
  lock.window().start(lock_start);
  lock.window().end(lock_end);
  lock.operator_id("tester");
  lock.reason("broken floor plate");
  auto locked = (*lock_client)->call(lock, 10s);
  ASSERT_TRUE(locked.has_value());
  ASSERT_EQ(locked->error().code(), msg::ERROR_NONE) << locked->error().message();
  bool hit_v1 = false;
  for (const auto& reservation : locked->hit()) hit_v1 = hit_v1 || reservation.agent() == "V1";
  ASSERT_TRUE(hit_v1) << "the lock did not hit V1's planned route";

  const auto done = wait_order("v1-lock");
  ASSERT_TRUE(done.has_value());
  EXPECT_EQ(done->state(), msg::ORDER_FINISHED) << done->failure();
  std::lock_guard guard(seen_.mutex);
  bool notified = false;
  for (const auto& notice : seen_.notices) notified = notified || (notice.kind() == msg::NOTICE_LOCK_HIT && notice.agent() == "V1");
  EXPECT_TRUE(notified);
  // V1 was never allocated bar-3 while it was locked, but drove over it afterwards.
  bool held_after = false;
  for (const auto& [time, holder] : seen_.holder_log["bar-3"]) {
    if (holder != "V1") continue;
    EXPECT_GE(time, lock_end) << "V1 held bar-3 during the lock";
    held_after = true;
  }
  EXPECT_TRUE(held_after);
  EXPECT_EQ(seen_.holders["right-4"], "V1");
}

TEST_F(FleetTest, OrdersSurviveACrashOfTheRoutingAgent) {
  constexpr std::uint32_t kDomain = 89;
  Fleet fleet(kDomain, "restart");
  ASSERT_NO_FATAL_FAILURE(start_two_vehicles(fleet, kDomain));
  ASSERT_EQ(send_order("V1", "v1-there", {{"right-4", "NOP"}}), "");
  ASSERT_EQ(send_order("V2", "v2-there", {{"left-4", "NOP"}}), "");
  // Both drive (their routes are reserved and allocated in part): the routing agent crashes
  // and comes back.
  ASSERT_TRUE(wait_status("V1", [](const ran::VehicleStatus& s) { return s.pose.y > 1.0; })) << "V1 never started";
  ASSERT_TRUE(wait_status("V2", [](const ran::VehicleStatus& s) { return s.pose.y > 1.0; })) << "V2 never started";
  fleet.crash_and_restart("routing");

  // A new order needs a new route from the restarted routing agent.
  ASSERT_NO_FATAL_FAILURE(expect_crossing_orders_and_one_more_finish());
}

TEST_F(FleetTest, OrdersSurviveACrashOfTheTopologyAgent) {
  constexpr std::uint32_t kDomain = 83;
  Fleet fleet(kDomain, "topology-restart");
  // The topology agent keeps its reservations in a journal, so its next life goes on
  // with the routes the vehicles are driving.
  ASSERT_NO_FATAL_FAILURE(start_two_vehicles(fleet, kDomain, "topology.db"));
  ASSERT_EQ(send_order("V1", "v1-there", {{"right-4", "NOP"}}), "");
  ASSERT_EQ(send_order("V2", "v2-there", {{"left-4", "NOP"}}), "");
  ASSERT_TRUE(wait_status("V1", [](const ran::VehicleStatus& s) { return s.pose.y > 1.0; })) << "V1 never started";
  fleet.crash_and_restart("topology");

  // A new route is reserved and allocated at the restarted topology agent.
  ASSERT_NO_FATAL_FAILURE(expect_crossing_orders_and_one_more_finish());
}

TEST_F(FleetTest, ALogicalAgentRestartedAfterACrashTakesOverItsVehicleAndFreesTheRouteItLeft) {
  constexpr std::uint32_t kDomain = 45;
  Fleet fleet(kDomain, "logical-restart");
  // V1 drives towards right-4, its route reserved over the bar to the station (held there
  // open-ended); its logical agent crashes on the way and is started again.
  ASSERT_NO_FATAL_FAILURE(start_v1_towards_the_station(fleet, kDomain));
  fleet.crash_and_restart("V1");

  // The new life takes over the vehicle where it stands and gives up the route the old one
  // left reserved: V2 gets the station, and V1 drives again.
  ASSERT_EQ(send_order("V2", "v2-station", {{"right-4", "NOP"}}), "");
  const auto station = wait_order("v2-station");
  ASSERT_TRUE(station.has_value()) << "V2's order did not end";
  EXPECT_EQ(station->state(), msg::ORDER_FINISHED) << station->failure();
  // What the earlier life held behind the vehicle is released (it stopped on left-2, where
  // its last move took it).
  EXPECT_TRUE(seen_.wait([&] { return seen_.holders["left-0"].empty() && seen_.holders["left-0<->left-1"].empty(); },
                         30s))
      << "V1 still holds what it left behind";
  ASSERT_EQ(send_order("V1", "v1-home", {{"left-0", "NOP"}}), "");
  const auto home = wait_order("v1-home");
  ASSERT_TRUE(home.has_value()) << "V1's order did not end";
  EXPECT_EQ(home->state(), msg::ORDER_FINISHED) << home->failure();

  std::lock_guard lock(seen_.mutex);
  EXPECT_EQ(seen_.holders["left-0"], "V1");
  EXPECT_TRUE(seen_.hold_violations.empty()) << seen_.hold_violations.front();
  EXPECT_TRUE(seen_.overlaps.empty()) << seen_.overlaps.front();
  for (const auto& alarm : seen_.alarms) ADD_FAILURE() << "alarm: " << alarm.text();
}

TEST_F(FleetTest, ALogicalAgentRestartedFromItsOrderJournalAwaitsTheLoadItCommandedAndFinishesItsOrders) {
  constexpr std::uint32_t kDomain = 49;
  Fleet fleet(kDomain, "order-journal");
  std::vector<std::string> logical;
  ASSERT_NO_FATAL_FAILURE(start_v1_loading_with_an_order_journal(fleet, kDomain, logical));

  // The agent crashes while the RAN loads; its next life reads the journal.
  ASSERT_NO_FATAL_FAILURE(fleet.crash_and_restart("V1"));
  // The load it commanded is awaited, not commanded again (the simulated vehicle fails a
  // second load, "already_loaded"), and the orders run on.
  const auto pallet = wait_order("pallet");
  ASSERT_TRUE(pallet.has_value()) << "the order running at the crash did not end";
  EXPECT_EQ(pallet->state(), msg::ORDER_FINISHED) << pallet->failure();
  EXPECT_EQ(pallet->destination(), 2u);
  // It knows its orders again: a name in use is refused.
  const std::string again = send_order("V1", "home", {{"left-0", "NOP"}});
  EXPECT_NE(again.find("known already"), std::string::npos) << again;
  const auto home = wait_order("home");
  ASSERT_TRUE(home.has_value()) << "the order queued at the crash did not end";
  EXPECT_EQ(home->state(), msg::ORDER_FINISHED) << home->failure();
  // What an operator lists: both orders, ended, from the agent's next life.
  std::string out, err;
  ASSERT_EQ(droverctl(fleet, "orders", {"orders", "--vehicle", "V1", "--json", "--domain", std::to_string(kDomain)},
                      out, err),
            0)
      << err;
  const auto listed = nlohmann::json::parse(out);
  ASSERT_EQ(listed.size(), 2u) << out;
  EXPECT_EQ(listed[1]["order"], "pallet") << out;
  EXPECT_EQ(listed[1]["state"], "finished") << out;
  EXPECT_EQ(listed[1]["destination"], 2) << out;
  EXPECT_EQ(listed[0]["order"], "home") << out;
  EXPECT_EQ(listed[0]["state"], "finished") << out;

  std::lock_guard lock(seen_.mutex);
  EXPECT_EQ(seen_.latest["V1"].load, ran::LoadState::empty) << "unloaded at right-4";
  EXPECT_EQ(seen_.holders["left-0"], "V1");
  EXPECT_TRUE(seen_.hold_violations.empty()) << seen_.hold_violations.front();
  for (const auto& alarm : seen_.alarms) ADD_FAILURE() << "alarm: " << alarm.text();
}

TEST_F(FleetTest, AnActionTheRanNoLongerKnowsFailsTheRestoredOrderWithAnAlarmAndTheQueueRunsOn) {
  constexpr std::uint32_t kDomain = 69;
  Fleet fleet(kDomain, "order-journal-ran-lost");
  std::vector<std::string> logical;
  ASSERT_NO_FATAL_FAILURE(start_v1_loading_with_an_order_journal(fleet, kDomain, logical));

  // The agent and the vehicle's RAN both go down mid-load; the RAN comes back knowing no
  // command, so whether the pallet is on board is unknown.
  ASSERT_NO_FATAL_FAILURE(fleet.crash("V1"));
  ASSERT_NO_FATAL_FAILURE(fleet.crash("ran-V1"));
  fleet.start_ran("V1", "left-4", {"--load-duration", "20"});
  fleet.start_logical("V1", logical);
  const auto pallet = wait_order("pallet");
  ASSERT_TRUE(pallet.has_value()) << "the order running at the crash did not end";
  EXPECT_EQ(pallet->state(), msg::ORDER_FAILED);
  EXPECT_NE(pallet->failure().find("whether it was done is unknown"), std::string::npos) << pallet->failure();
  const auto home = wait_order("home");
  ASSERT_TRUE(home.has_value()) << "the order queued at the crash did not end";
  EXPECT_EQ(home->state(), msg::ORDER_FINISHED) << home->failure();
  std::lock_guard lock(seen_.mutex);
  EXPECT_TRUE(alarm_seen(msg::ALARM_ERROR, "V1", "order 'pallet' of vehicle 'V1' failed"));
}

TEST_F(FleetTest, ARanRestartedMidLoadFailsTheOrderInsteadOfLeavingItWaitingForEver) {
  constexpr std::uint32_t kDomain = 35;
  Fleet fleet(kDomain, "ran-restart-mid-load");
  std::vector<std::string> logical;
  ASSERT_NO_FATAL_FAILURE(start_v1_loading_with_an_order_journal(fleet, kDomain, logical));
  // Only the RAN goes down, and comes back at once knowing no command: the load the agent
  // waits for will never end (before, the order waited for it for ever).
  ASSERT_NO_FATAL_FAILURE(fleet.crash("ran-V1"));
  fleet.start_ran("V1", "left-4", {"--load-duration", "20"});
  const auto pallet = wait_order("pallet");
  ASSERT_TRUE(pallet.has_value()) << "the order loading when the RAN restarted did not end";
  EXPECT_EQ(pallet->state(), msg::ORDER_FAILED);
  EXPECT_NE(pallet->failure().find("is no longer reported by the RAN, which restarted"), std::string::npos) << pallet->failure();
  const auto home = wait_order("home");
  ASSERT_TRUE(home.has_value()) << "the order queued behind it did not end";
  EXPECT_EQ(home->state(), msg::ORDER_FINISHED) << home->failure();
}

TEST_F(FleetTest, ARanRestartedMidMoveFailsTheOrderInsteadOfLeavingItDrivingForEver) {
  constexpr std::uint32_t kDomain = 23;
  Fleet fleet(kDomain, "ran-restart-mid-move");
  fleet.start_infrastructure();
  watch(kDomain, fleet, {"V1"});
  ASSERT_NO_FATAL_FAILURE(send_v1_across(fleet, "v1-across"));
  // The RAN goes down on the way to left-1 and comes back there at once, knowing no move:
  // the move the agent waits for will never end (before, the order stayed running, the
  // vehicle "driving" and standing, for ever).
  ASSERT_NO_FATAL_FAILURE(fleet.crash("ran-V1"));
  fleet.start_ran("V1", "left-1");
  const auto across = wait_order("v1-across");
  ASSERT_TRUE(across.has_value()) << "the order driving when the RAN restarted did not end";
  EXPECT_EQ(across->state(), msg::ORDER_FAILED);
  EXPECT_NE(across->failure().find("the move to 'left-1' is no longer reported by the RAN, which restarted"),
            std::string::npos)
      << across->failure();
  // The alarm comes on its own topic, which the order's progress may overtake.
  EXPECT_TRUE(seen_.wait([&] { return alarm_seen(msg::ALARM_ERROR, "V1", "no longer reported by the RAN"); }, 30s));
  // The vehicle works on from where its RAN came back.
  ASSERT_EQ(send_order("V1", "v1-on", {{"left-4", "NOP"}}), "");
  const auto on = wait_order("v1-on");
  ASSERT_TRUE(on.has_value()) << "the next order did not end";
  EXPECT_EQ(on->state(), msg::ORDER_FINISHED) << on->failure();
}

TEST_F(FleetTest, AVehicleHoldsItsVertexAndWorksThoughAPartitionItNeverUsesHasNoLiveOwner) {
  constexpr std::uint32_t kDomain = 47;
  Fleet fleet(kDomain, "silent-partition");
  // The H crossing in partition "west", and an island of its own in partition "east", which
  // no topology agent serves (one that is down, or that this host never discovers).
  auto json = nlohmann::json::parse(std::ifstream(source_dir() + "/launch/topologies/h_crossing.json"));
  for (auto& vertex : json["vertices"]) vertex["partition"] = "west";
  for (auto& edge : json["edges"]) edge["partition"] = "west";
  auto island = json["vertices"][0];
  island["id"] = "island";
  island["partition"] = "east";
  island["x"] = 40;
  island["y"] = 40;
  island.erase("kind");
  json["vertices"].push_back(island);
  const auto file = (fleet.dir() / "h_island.json").string();
  std::ofstream(file) << json.dump(2);
  fleet.use_topology(file);
  fleet.start("topology", {"topology-agent", "--topology", file, "--partition", "west"});
  fleet.start("routing", {"routing-agent"});
  watch(kDomain, fleet, {"V1"});
  fleet.start_vehicle("V1", "left-0");
  // Asking every partition what an earlier life left gives up on "east" after a few seconds:
  // the vehicle's vertex must not stay unprotected for as long as a partition is silent.
  ASSERT_TRUE(wait_ready("V1", "left-0")) << "V1 never held its vertex";
  // Each new route cancels the one before (its remnant) where that one was reserved: in
  // "west" only, so a partition nobody serves holds up no order.
  for (const auto& [order, to] : {std::pair{"there", "right-4"}, std::pair{"back", "left-0"}}) {
    ASSERT_EQ(send_order("V1", order, {{to, "NOP"}}), "");
    const auto ended = wait_order(order);
    ASSERT_TRUE(ended.has_value()) << "order " << order << " did not end";
    EXPECT_EQ(ended->state(), msg::ORDER_FINISHED) << order << ": " << ended->failure();
  }
}

/// Waits until the file at `path` contains `text` (an agent's log line). \return whether it did.
bool wait_for_log(const std::filesystem::path& path, const std::string& text, std::chrono::seconds timeout) {
  const auto give_up = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < give_up) {
    if (std::filesystem::exists(path) && read_file(path.string()).find(text) != std::string::npos) return true;
    std::this_thread::sleep_for(100ms);
  }
  return false;
}

TEST_F(FleetTest, ALogicalAgentRestartedWhileAPartitionIsDownTakesOverWhatItLeftThereOnceItIsBack) {
  constexpr std::uint32_t kDomain = 36;
  Fleet fleet(kDomain, "late-take-over");
  // The H crossing with its right leg in partition "east", the rest in "west", each served
  // by a journaling topology agent. V1 stands on the station right-4, in "east".
  auto json = nlohmann::json::parse(std::ifstream(source_dir() + "/launch/topologies/h_crossing.json"));
  for (auto* items : {&json["vertices"], &json["edges"]}) {
    for (auto& item : *items) item["partition"] = item["id"].get<std::string>().rfind("right", 0) == 0 ? "east" : "west";
  }
  const auto file = (fleet.dir() / "h_two_partitions.json").string();
  std::ofstream(file) << json.dump(2);
  fleet.use_topology(file);
  for (const char* partition : {"west", "east"}) {
    fleet.start(std::string("topology-") + partition,
                {"topology-agent", "--topology", file, "--partition", partition, "--id",
                 std::string("topology-") + partition, "--db", (fleet.dir() / (std::string(partition) + ".db")).string()});
  }
  fleet.start("routing", {"routing-agent"});
  watch(kDomain, fleet, {"V1", "V2"}, 2);
  fleet.start_vehicle("V1", "right-4");
  fleet.start_vehicle("V2", "left-0");
  ASSERT_TRUE(wait_ready("V1", "right-4"));
  ASSERT_TRUE(wait_ready("V2", "left-0"));

  // "east" goes down, then V1's logical agent crashes and comes back while "east" is down:
  // its start cannot learn that its earlier life holds the station there open-ended.
  std::vector<std::string> east;
  ASSERT_NO_FATAL_FAILURE(fleet.crash("topology-east", &east));
  ASSERT_NO_FATAL_FAILURE(fleet.crash_and_restart("V1"));
  ASSERT_TRUE(wait_for_log(fleet.dir() / "V1.restarted.log", "did not say within", 60s))
      << "V1's next life never gave up asking partition east";
  // "east" comes back from its journal, the earlier life's hold of the station with it; V1's
  // heartbeat keeps "east" from sweeping it as departed. V1's next life must take over what
  // its earlier life left there, or that hold would block the station for ever.
  fleet.start("topology-east", east);
  ASSERT_EQ(send_order("V1", "v1-away", {{"left-4", "NOP"}}), "");
  const auto away = wait_order("v1-away");
  ASSERT_TRUE(away.has_value()) << "V1's order did not end";
  EXPECT_EQ(away->state(), msg::ORDER_FINISHED) << away->failure();
  ASSERT_EQ(send_order("V2", "v2-station", {{"right-4", "NOP"}}), "");
  const auto station = wait_order("v2-station");
  ASSERT_TRUE(station.has_value()) << "V2's order did not end";
  EXPECT_EQ(station->state(), msg::ORDER_FINISHED) << station->failure();

  std::lock_guard lock(seen_.mutex);
  // "east" restarted: the first events of its next life may be written before its writer
  // matched the tester (and number past its earlier life's last); only conflicting holds
  // count here.
  for (const auto& violation : seen_.hold_violations) {
    if (violation.find(" while ") != std::string::npos) ADD_FAILURE() << violation;
  }
  EXPECT_TRUE(seen_.overlaps.empty()) << seen_.overlaps.front();
}

TEST_F(FleetTest, APausedVehicleStopsOnAVertexStaysPausedThroughARestartAndGoesOnWhenResumed) {
  constexpr std::uint32_t kDomain = 37;
  Fleet fleet(kDomain, "pause");
  fleet.start_infrastructure();
  watch(kDomain, fleet, {"V1", "V2"});
  const auto wait_state = [&](const std::function<bool(const msg::VehicleState&)>& condition) {
    return wait_vehicle_state("V1", condition);
  };
  fleet.start_vehicle("V1", "left-0", {},
                      {"--park-after", "-1", "--charge-below", "0", "--db", (fleet.dir() / "V1.db").string()});
  ASSERT_TRUE(wait_ready("V1", "left-0"));
  // V2 stands idle off V1's way: a pause of V1 leaves it alone, a pause of all takes it too.
  fleet.start_vehicle("V2", "right-0", {}, {"--park-after", "-1", "--charge-below", "0"});
  ASSERT_TRUE(wait_ready("V2", "right-0"));
  ASSERT_EQ(send_order("V1", "trip", {{"right-4", "NOP"}}), "");
  ASSERT_EQ(send_order("V1", "back", {{"left-0", "NOP"}}), "");
  ASSERT_TRUE(wait_status("V1", [](const ran::VehicleStatus& s) { return s.linear_speed > 0; }, 60s))
      << "V1 never drove";

  // Paused while driving: it drives the moves it was given and stands on a vertex.
  const std::string domain = std::to_string(kDomain);
  std::string out, err;
  ASSERT_EQ(droverctl(fleet, "pause", {"pause", "V1", "--reason", "aisle blocked", "--wait", "60", "--domain", domain},
                      out, err),
            0)
      << out << err;
  EXPECT_NE(out.find("vehicle 'V1' stands paused"), std::string::npos) << out;
  ASSERT_TRUE(wait_status("V1", [](const ran::VehicleStatus& s) { return s.linear_speed == 0.0; }, 60s));
  std::string paused_at;
  ran::Pose pose;
  {
    std::lock_guard lock(seen_.mutex);
    pose = seen_.latest["V1"].pose;
    for (topology::EntityIndex v = 0; v < world_->vertex_count(); ++v) {
      const auto& position = world_->vertex(v).position;
      if (std::hypot(pose.x - position.x(), pose.y - position.y()) < 0.05) paused_at = world_->id(v);
    }
    ASSERT_FALSE(paused_at.empty()) << "V1 stopped off its vertices, at (" << pose.x << ", " << pose.y << ")";
    EXPECT_NE(paused_at, "right-4") << "V1 drove on to its destination";
    EXPECT_EQ(seen_.orders["trip"].state(), msg::ORDER_RUNNING) << "a pause is no failure";
    EXPECT_EQ(seen_.orders["back"].state(), msg::ORDER_QUEUED);
  }
  EXPECT_TRUE(seen_.wait([&] { return seen_.holders[paused_at] == "V1"; }, 60s))
      << "V1 does not hold the vertex it stands on";

  // Its logical agent restarts (the journal keeps the pause): it holds its vertex again and
  // stays paused, its orders where they were.
  const TimeNs restarted = clock_->now();
  ASSERT_NO_FATAL_FAILURE(fleet.crash_and_restart("V1"));
  ASSERT_TRUE(wait_state([&](const msg::VehicleState& s) { return s.time().ns() > restarted && s.state() == msg::VEHICLE_PAUSED; }))
      << "V1's next life is not paused";
  ASSERT_EQ(droverctl(fleet, "vehicles", {"vehicles", "--json", "--domain", domain}, out, err), 0) << err;
  const auto listed = nlohmann::json::parse(out);
  ASSERT_EQ(listed.size(), 2u) << out;
  EXPECT_EQ(listed[0]["state"], "paused") << out;
  EXPECT_EQ(listed[0]["paused"], true) << out;
  EXPECT_EQ(listed[0]["pause_reason"], "aisle blocked") << out;
  EXPECT_EQ(listed[1]["vehicle"], "V2") << out;
  EXPECT_EQ(listed[1]["paused"], false) << out;
  EXPECT_TRUE(seen_.wait([&] { return seen_.holders[paused_at] == "V1"; }, 60s)) << "V1's next life holds nothing";
  {
    std::lock_guard lock(seen_.mutex);
    const auto& now = seen_.latest["V1"].pose;
    EXPECT_LT(std::hypot(now.x - pose.x, now.y - pose.y), 0.05) << "V1 moved while paused";
    EXPECT_EQ(seen_.orders["trip"].state(), msg::ORDER_RUNNING);
    EXPECT_EQ(seen_.orders["back"].state(), msg::ORDER_QUEUED);
  }

  // The running order withdrawn while the vehicle is paused: it ends at once (the vehicle
  // stands).
  ASSERT_EQ(droverctl(fleet, "withdraw", {"order", "withdraw", "V1", "trip", "--wait", "60", "--domain", domain}, out,
                      err),
            0)
      << out << err;
  // Resumed: the queued order runs.
  ASSERT_EQ(droverctl(fleet, "resume", {"resume", "V1", "--domain", domain}, out, err), 0) << out << err;
  EXPECT_NE(out.find("vehicle 'V1' resumed"), std::string::npos) << out;
  const auto back = wait_order("back");
  ASSERT_TRUE(back.has_value()) << "order back did not end";
  EXPECT_EQ(back->state(), msg::ORDER_FINISHED) << back->failure();
  EXPECT_TRUE(wait_state([](const msg::VehicleState& s) { return !s.paused() && s.state() == msg::VEHICLE_IDLE; }));
  // V2 paused on its own, then all: V1 pauses, V2 keeps its own reason. The fleet-wide pause
  // lifted, V1 goes on and V2 stays paused; resumed all, both are idle again (ready for the
  // next order), not paused.
  ASSERT_EQ(droverctl(fleet, "pause-v2", {"pause", "V2", "--reason", "bumper check", "--domain", domain}, out, err),
            0)
      << out << err;
  ASSERT_TRUE(wait_vehicle_state("V2", [](const msg::VehicleState& s) { return s.pause_reason() == "bumper check"; }));
  ASSERT_EQ(droverctl(fleet, "pause-all", {"pause", "--all", "--reason", "shift change", "--wait", "60", "--domain",
                                           domain},
                      out, err),
            0)
      << out << err;
  EXPECT_NE(out.find("vehicle 'V1' stands paused"), std::string::npos) << out;
  EXPECT_NE(out.find("vehicle 'V2' already paused ('bumper check'): left as it is"), std::string::npos) << out;
  EXPECT_NE(out.find("vehicle 'V2' stands paused"), std::string::npos) << out;
  EXPECT_TRUE(wait_vehicle_state("V1", [](const msg::VehicleState& s) {
    return s.paused() && s.pause_reason() == "shift change" && s.state() == msg::VEHICLE_PAUSED;
  })) << "V1 not paused by pause --all";
  EXPECT_TRUE(wait_vehicle_state("V2", [](const msg::VehicleState& s) {
    return s.paused() && s.pause_reason() == "bumper check" && s.state() == msg::VEHICLE_PAUSED;
  })) << "V2's own pause changed by pause --all";
  ASSERT_EQ(droverctl(fleet, "resume-shift", {"resume", "--all", "--reason", "shift change", "--domain", domain}, out,
                      err),
            0)
      << out << err;
  EXPECT_NE(out.find("vehicle 'V1' resumed"), std::string::npos) << out;
  EXPECT_NE(out.find("vehicle 'V2' left paused ('bumper check')"), std::string::npos) << out;
  EXPECT_TRUE(wait_vehicle_state(
      "V1", [](const msg::VehicleState& s) { return !s.paused() && s.state() == msg::VEHICLE_IDLE; }))
      << "V1 resumed with nothing to do is not idle";
  ASSERT_EQ(droverctl(fleet, "resume-all", {"resume", "--all", "--domain", domain}, out, err), 0) << out << err;
  EXPECT_NE(out.find("vehicle 'V2' resumed"), std::string::npos) << out;
  EXPECT_NE(out.find("vehicle 'V1' not paused"), std::string::npos) << out;
  EXPECT_TRUE(wait_vehicle_state(
      "V2", [](const msg::VehicleState& s) { return !s.paused() && s.state() == msg::VEHICLE_IDLE; }))
      << "V2 resumed with nothing to do is not idle";
  // A vehicle no logical agent serves: nobody answers.
  EXPECT_EQ(droverctl(fleet, "pause-nobody", {"pause", "V9", "--timeout", "1", "--domain", domain}, out, err), 3)
      << out << err;
  std::lock_guard lock(seen_.mutex);
  EXPECT_TRUE(seen_.hold_violations.empty()) << seen_.hold_violations.front();
  for (const auto& alarm : seen_.alarms) {
    if (alarm.severity() >= msg::ALARM_WARNING) ADD_FAILURE() << "alarm: " << alarm.text();
  }
}

TEST_F(FleetTest, ALogicalAgentGoneForGoodLosesItsRouteButKeepsWhatItsVehicleOccupiesTillTheToldOperatorReleasesIt) {
  constexpr std::uint32_t kDomain = 46;
  Fleet fleet(kDomain, "logical-gone");
  ASSERT_NO_FATAL_FAILURE(start_v1_towards_the_station(fleet, kDomain));
  ASSERT_NO_FATAL_FAILURE(fleet.crash("V1"));

  // Ten seconds without a heartbeat (the topology agent's default), V1's route goes but for
  // what its vehicle occupies: V2 gets the station V1's route held open-ended.
  ASSERT_EQ(send_order("V2", "v2-station", {{"right-4", "NOP"}}), "");
  const auto station = wait_order("v2-station");
  ASSERT_TRUE(station.has_value()) << "V2's order did not end";
  EXPECT_EQ(station->state(), msg::ORDER_FINISHED) << station->failure();

  {
    std::lock_guard lock(seen_.mutex);
    // The vehicle stopped on left-2, where its last move took it: that stays allocated, and
    // the operator is told so by the topology agent.
    EXPECT_EQ(seen_.holders["left-2"], "V1");
    const auto gone = std::find_if(seen_.alarms.begin(), seen_.alarms.end(), [](const msg::OperatorAlarm& alarm) {
      return alarm.agent() == "topology" && alarm.vehicle() == "V1" && alarm.severity() == msg::ALARM_ERROR &&
             alarm.text().find("is gone") != std::string::npos && alarm.text().find("'left-2'") != std::string::npos;
    });
    EXPECT_NE(gone, seen_.alarms.end()) << "no alarm of the topology agent about V1";
    EXPECT_TRUE(seen_.hold_violations.empty()) << seen_.hold_violations.front();
    EXPECT_TRUE(seen_.overlaps.empty()) << seen_.overlaps.front();
  }

  // The operator clears what V1 left (its vehicle towed away), with droverctl; V2, alive,
  // keeps what it holds.
  const std::string domain = std::to_string(kDomain);
  std::string out, err;
  EXPECT_EQ(droverctl(fleet, "release-live", {"release", "right-4", "--from", "V2", "--domain", domain}, out, err), 1)
      << out << err;
  EXPECT_NE(err.find("'V2' is alive"), std::string::npos) << err;
  EXPECT_EQ(droverctl(fleet, "release", {"release", "left-2", "--from", "V1", "--domain", domain}, out, err), 0)
      << out << err;
  EXPECT_NE(out.find("released left-2 from V1"), std::string::npos) << out;
  EXPECT_TRUE(seen_.wait([&] { return seen_.holders["left-2"].empty(); }, 30s)) << "left-2 is still V1's";
  EXPECT_EQ(droverctl(fleet, "release-again", {"release", "left-2", "--from", "V1", "--domain", domain}, out, err), 1)
      << out << err;
  EXPECT_NE(err.find("'V1' does not hold 'left-2'"), std::string::npos) << err;
  std::lock_guard lock(seen_.mutex);
  EXPECT_EQ(seen_.holders["right-4"], "V2");
}

TEST_F(FleetTest, ATopologyAgentRestartedFromItsJournalSweepsALogicalAgentThatWentAwayWhileItWasDown) {
  constexpr std::uint32_t kDomain = 48;
  Fleet fleet(kDomain, "gone-while-down");
  ASSERT_NO_FATAL_FAILURE(start_v1_towards_the_station(fleet, kDomain, "topology.db"));
  // The topology agent goes down, and V1's logical agent with it, for good: the next life
  // of the topology agent never hears V1, yet its journal has V1's route to the station.
  std::vector<std::string> topology_args;
  ASSERT_NO_FATAL_FAILURE(fleet.crash("topology", &topology_args));
  ASSERT_NO_FATAL_FAILURE(fleet.crash("V1"));
  fleet.start("topology", topology_args);

  ASSERT_EQ(send_order("V2", "v2-station", {{"right-4", "NOP"}}), "");
  const auto station = wait_order("v2-station");
  ASSERT_TRUE(station.has_value()) << "V2's order did not end";
  EXPECT_EQ(station->state(), msg::ORDER_FINISHED) << station->failure();

  std::lock_guard lock(seen_.mutex);
  const auto gone = std::find_if(seen_.alarms.begin(), seen_.alarms.end(), [](const msg::OperatorAlarm& alarm) {
    return alarm.agent() == "topology" && alarm.vehicle() == "V1" &&
           alarm.text().find("no heartbeat since this topology agent started") != std::string::npos;
  });
  EXPECT_NE(gone, seen_.alarms.end()) << "no alarm of the topology agent about V1";
  EXPECT_TRUE(seen_.hold_violations.empty()) << seen_.hold_violations.front();
  EXPECT_TRUE(seen_.overlaps.empty()) << seen_.overlaps.front();
}

TEST_F(FleetTest, VehicleLeavingItsAllocatedAreaIsStoppedWithACriticalAlarm) {
  constexpr std::uint32_t kDomain = 90;
  Fleet fleet(kDomain, "drift");
  std::optional<InProcessRan> ran;
  ASSERT_NO_FATAL_FAILURE(send_v1_off_on_a_faulty_ran(fleet, kDomain, "v1-drift", ran));
  ran->node->runner().with_driver([&](TimeNs) { ran->driver->drift(1.5); });

  const auto done = wait_order("v1-drift");
  ASSERT_TRUE(done.has_value());
  EXPECT_EQ(done->state(), msg::ORDER_FAILED);
  EXPECT_NE(done->failure().find("left its allocated area"), std::string::npos) << done->failure();
  // The vehicle is stopped: it comes to stand and stays there.
  EXPECT_TRUE(wait_status("V1", [](const ran::VehicleStatus& s) { return s.linear_speed == 0.0; }, 60s));
  EXPECT_TRUE(seen_.wait([&] { return alarm_seen(msg::ALARM_CRITICAL, "V1", "left its allocated area"); }, 30s))
      << "no critical alarm about the footprint";
  std::lock_guard lock(seen_.mutex);
  EXPECT_TRUE(seen_.latest["V1"].pose.y < 6.0) << "V1 drove on to the bar after leaving its area";
  // Stopping the logical agent before the in-process RAN goes away.
  fleet.stop();
}

TEST_F(FleetTest, ADriverThatDropsItsMovesFailsTheOrderAndTheVehicleWorksOnFromWhereItStopped) {
  constexpr std::uint32_t kDomain = 24;
  Fleet fleet(kDomain, "dropped-moves");
  std::optional<InProcessRan> ran;
  ASSERT_NO_FATAL_FAILURE(send_v1_off_on_a_faulty_ran(fleet, kDomain, "v1-dropped", ran));
  // The driver stops the vehicle and forgets its moves, reporting on as if it had none
  // (before, the order stayed running and the vehicle "driving" for ever).
  std::size_t dropped = 0;
  ran->node->runner().with_driver([&](TimeNs now) { dropped = ran->driver->drop_unended(now); });
  ASSERT_GT(dropped, 0u);
  const auto done = wait_order("v1-dropped");
  ASSERT_TRUE(done.has_value()) << "the order whose moves the driver dropped did not end";
  EXPECT_EQ(done->state(), msg::ORDER_FAILED);
  EXPECT_NE(done->failure().find("is no longer reported by the RAN, which never reported its end"), std::string::npos)
      << done->failure();
  EXPECT_TRUE(seen_.wait([&] { return alarm_seen(msg::ALARM_ERROR, "V1", "which never reported its end"); }, 30s));
  // Stopped part-way along the edge, the vehicle drives on to the vertex it was heading for
  // and works on from there (before, it stood there for ever: "stands on no vertex").
  EXPECT_TRUE(seen_.wait([&] { return seen_.holders["left-1"] == "V1"; }, 60s)) << "V1 did not drive on to left-1";
  ASSERT_EQ(send_order("V1", "v1-on", {{"left-4", "NOP"}}), "");
  const auto on = wait_order("v1-on");
  ASSERT_TRUE(on.has_value()) << "the next order did not end";
  EXPECT_EQ(on->state(), msg::ORDER_FINISHED) << on->failure();
  {
    std::lock_guard lock(seen_.mutex);
    EXPECT_FALSE(alarm_seen(msg::ALARM_ERROR, "V1", "stands on no vertex"));
    EXPECT_TRUE(seen_.hold_violations.empty()) << seen_.hold_violations.front();
  }
  // Stopping the logical agent before the in-process RAN goes away.
  fleet.stop();
}

TEST_F(FleetTest, RefusedRanStatusesRaiseAnAlarmThatSaysWhyAndTheVehicleIsCommandedOnceTheyAreGood) {
  constexpr std::uint32_t kDomain = 26;
  Fleet fleet(kDomain, "refused-statuses");
  fleet.start_infrastructure();
  watch(kDomain, fleet, {"V1"});
  auto ran = start_faulty_ran(kDomain, "left-0");
  ASSERT_TRUE(ran.has_value());
  // A driver that reports no outline: its statuses arrive, and none can be taken (before,
  // the agent only said "no status from the RAN", if anything).
  ran->node->runner().with_driver([&](TimeNs) { ran->driver->leave_out_footprint(true); });
  // Once the tester refuses them too, the last status kept for late joiners is a refused one.
  ASSERT_TRUE(poll_until([&] { return rans_["V1"]->refusal(1s).has_value(); }, 30s))
      << "the statuses without a footprint were taken";
  fleet.start_logical("V1", {"--park-after", "-1", "--charge-below", "0"});
  EXPECT_TRUE(seen_.wait([&] { return alarm_seen(msg::ALARM_ERROR, "V1", "the statuses of its RAN are refused"); },
                         60s))
      << "no alarm about the refused statuses";
  {
    std::lock_guard lock(seen_.mutex);
    EXPECT_TRUE(alarm_seen(msg::ALARM_ERROR, "V1", "the footprint is not a valid polygon"));
    EXPECT_TRUE(seen_.holders["left-0"].empty()) << "V1 held its vertex without a status saying where it is";
  }
  ran->node->runner().with_driver([&](TimeNs) { ran->driver->leave_out_footprint(false); });
  EXPECT_TRUE(wait_ready("V1", "left-0")) << "V1 was not taken over once its statuses were good";
  // Stopping the logical agent before the in-process RAN goes away.
  fleet.stop();
}

TEST_F(FleetTest, AnOrderForAnActionTheVehicleDoesNotPerformIsRefusedWhenSentAndOneItPerformsFinishes) {
  constexpr std::uint32_t kDomain = 27;
  Fleet fleet(kDomain, "actions");
  fleet.start_infrastructure();
  watch(kDomain, fleet, {"V1"});
  // Sent before the RAN is heard, an order is queued unchecked; it fails before the drive
  // once the RAN says what it performs (before, it drove to left-4 and failed there).
  fleet.start_logical("V1", {"--park-after", "-1", "--charge-below", "0"});
  ASSERT_EQ(send_order("V1", "honk-early", {{"left-4", "honk"}}), "");
  fleet.start_ran("V1", "left-0", {"--custom-action", "beep=1"});
  const auto early = wait_order("honk-early");
  ASSERT_TRUE(early.has_value());
  EXPECT_EQ(early->state(), msg::ORDER_FAILED);
  EXPECT_NE(early->failure().find("destination 0: vehicle 'V1' does not perform 'honk'"), std::string::npos)
      << early->failure();
  ASSERT_TRUE(wait_ready("V1", "left-0"));
  {
    std::lock_guard lock(seen_.mutex);
    for (const auto& [time, holder] : seen_.holder_log["left-1"]) EXPECT_NE(holder, "V1") << "V1 drove for it";
  }
  // Refused at once, nothing queued (before, the vehicle drove to left-4 and failed there).
  EXPECT_EQ(send_order("V1", "honk", {{"left-4", "honk"}}),
            "order 'honk': destination 0: vehicle 'V1' does not perform 'honk' (its RAN performs: load, unload, "
            "charge, beep)");
  ASSERT_EQ(send_order("V1", "beep", {{"left-4", "beep"}}), "");
  const auto done = wait_order("beep");
  ASSERT_TRUE(done.has_value());
  EXPECT_EQ(done->state(), msg::ORDER_FINISHED) << done->failure();
  std::lock_guard lock(seen_.mutex);
  EXPECT_FALSE(seen_.orders.contains("honk")) << "the refused order was published";
}

TEST_F(FleetTest, ASecondRanForOneVehicleIsRefusedWithAnAlarmAndTheVehicleWorksOnOnceItStops) {
  constexpr std::uint32_t kDomain = 28;
  Fleet fleet(kDomain, "twin-ran");
  fleet.start_infrastructure();
  watch(kDomain, fleet, {"V1"});
  fleet.start_vehicle("V1", "left-0");
  ASSERT_TRUE(wait_ready("V1", "left-0"));
  // A simulator left running with the vehicle's id, elsewhere: its statuses and those of the
  // real RAN alternate, and both would take the commands (before, nothing told).
  fleet.start("ran-V1-twin", {"ran-sim", "--id", "V1", "--topology", fleet.topology_file(), "--at", "right-4"});
  EXPECT_TRUE(seen_.wait([&] { return alarm_seen(msg::ALARM_ERROR, "V1", "two RANs report for this vehicle"); }, 60s))
      << "no alarm about the second RAN";
  // An order meanwhile would fail at once ("two RANs report for vehicle 'V1'"). The tester
  // tells the two apart too (so that it has seen the twin's statuses the agent saw); once
  // the second one stops, V1's statuses are taken again, the agent's within milliseconds.
  ASSERT_TRUE(poll_until([&] { return rans_["V1"]->two_rans(); }, 30s)) << "the tester did not see two RANs";
  fleet.stop("ran-V1-twin");
  poll_until([&] { return !rans_["V1"]->two_rans(); }, 30s);  // the status wait below says if not
  const TimeNs alone = clock_->now();
  ASSERT_TRUE(wait_status("V1", [&](const ran::VehicleStatus& s) { return s.time > alone + seconds_to_ns(1); }, 30s))
      << "V1's statuses are not taken again";
  ASSERT_EQ(send_order("V1", "after-twin", {{"left-4", "NOP"}}), "");
  const auto done = wait_order("after-twin");
  ASSERT_TRUE(done.has_value());
  EXPECT_EQ(done->state(), msg::ORDER_FINISHED) << done->failure();
}

TEST_F(FleetTest, IdleVehicleParksOnAFreeParkingVertex) {
  constexpr std::uint32_t kDomain = 91;
  Fleet fleet(kDomain, "park");
  fleet.start_infrastructure();
  watch(kDomain, fleet, {"V1", "V2"});
  // V2 stands on left-0, the parking vertex nearest to V1: V1 must take the other one.
  fleet.start_vehicle("V2", "left-0");
  ASSERT_TRUE(wait_ready("V2", "left-0"));
  fleet.start_vehicle("V1", "left-4", {}, {"--park-after", "5", "--charge-below", "0"});
  ASSERT_TRUE(wait_ready("V1", "left-4"));
  ASSERT_TRUE(seen_.wait([&] { return seen_.holders["right-0"] == "V1"; }, 120s)) << "V1 never reached right-0";
  EXPECT_TRUE(wait_status("V1", [](const ran::VehicleStatus& s) {
    return std::abs(s.pose.x - 10.0) < 0.05 && std::abs(s.pose.y) < 0.05 && s.linear_speed == 0.0;
  })) << "V1 does not stand on right-0";
  std::lock_guard lock(seen_.mutex);
  EXPECT_EQ(seen_.holders["left-0"], "V2");
  EXPECT_TRUE(seen_.hold_violations.empty()) << seen_.hold_violations.front();
  EXPECT_TRUE(seen_.overlaps.empty()) << seen_.overlaps.front();
  EXPECT_TRUE(seen_.alarms.empty()) << seen_.alarms.front().text();
}

TEST_F(FleetTest, IdleVehicleStandingOnAnothersDestinationMakesWay) {
  constexpr std::uint32_t kDomain = 85;
  Fleet fleet(kDomain, "make_way");
  fleet.start_infrastructure();
  watch(kDomain, fleet, {"V1", "V2"});
  // V2 stands idle on left-4 and never parks by itself; V1 is sent there.
  fleet.start_vehicle("V2", "left-4");
  fleet.start_vehicle("V1", "right-4");
  ASSERT_TRUE(wait_ready("V2", "left-4"));
  ASSERT_TRUE(wait_ready("V1", "right-4"));
  ASSERT_EQ(send_order("V1", "v1-to-v2", {{"left-4", "NOP"}}), "");

  const auto done = wait_order("v1-to-v2");
  ASSERT_TRUE(done.has_value()) << "V1's order did not end";
  EXPECT_EQ(done->state(), msg::ORDER_FINISHED) << done->failure();
  // V2 made way to the free parking vertex nearest to it, and stands there.
  EXPECT_TRUE(seen_.wait([&] { return seen_.holders["left-0"] == "V2"; }, 60s)) << "V2 is not on left-0";
  std::lock_guard lock(seen_.mutex);
  EXPECT_EQ(seen_.holders["left-4"], "V1");
  EXPECT_TRUE(seen_.hold_violations.empty()) << seen_.hold_violations.front();
  EXPECT_TRUE(seen_.overlaps.empty()) << seen_.overlaps.front();
  EXPECT_TRUE(seen_.alarms.empty()) << seen_.alarms.front().text();
}

TEST_F(FleetTest, VehicleUnderTheBatteryThresholdChargesBeforeItsOrder) {
  constexpr std::uint32_t kDomain = 92;
  Fleet fleet(kDomain, "charge");
  // The H crossing with a charger at right-0.
  auto json = nlohmann::json::parse(std::ifstream(source_dir() + "/launch/topologies/h_crossing.json"));
  for (auto& vertex : json["vertices"]) {
    if (vertex["id"] == "right-0") vertex["kind"] = "charger";
  }
  const auto file = (fleet.dir() / "h_charger.json").string();
  std::ofstream(file) << json.dump(2);
  fleet.use_topology(file);
  fleet.start_infrastructure();
  watch(kDomain, fleet, {"V1"});
  // 15 Wh of 100: under the 20 % threshold; charging takes it to 45 % (1 Wh/s).
  fleet.start_vehicle("V1", "left-4", {"--battery-capacity", "100", "--battery", "15"},
                      {"--park-after", "-1", "--charge-below", "0.2", "--charge-to", "0.45"});
  ASSERT_TRUE(seen_.wait([&] { return !seen_.holder_log["left-4"].empty(); }, 60s)) << "V1 never got ready";
  ASSERT_EQ(send_order("V1", "v1-after-charge", {{"left-0", "NOP"}}), "");

  const auto done = wait_order("v1-after-charge");
  ASSERT_TRUE(done.has_value());
  EXPECT_EQ(done->state(), msg::ORDER_FINISHED) << done->failure();
  std::lock_guard lock(seen_.mutex);
  ASSERT_FALSE(seen_.holder_log["right-0"].empty()) << "V1 never went to the charger";
  EXPECT_LE(seen_.holder_log["right-0"].front().first, done->started().ns())
      << "V1 started its order before it charged";
  EXPECT_EQ(seen_.holders["left-0"], "V1");
  // Charged to 45 %, then drove 22 m (0.5 Wh/m) to left-0.
  EXPECT_GT(seen_.latest["V1"].battery.state_of_charge, 0.3);
  EXPECT_TRUE(seen_.alarms.empty()) << seen_.alarms.front().text();
}

TEST_F(FleetTest, FatalRanErrorFailsTheOrderWithAnAlarmAndGivesUpTheRoute) {
  constexpr std::uint32_t kDomain = 93;
  Fleet fleet(kDomain, "fatal");
  fleet.start_infrastructure();
  watch(kDomain, fleet, {"V1"});
  ASSERT_NO_FATAL_FAILURE(send_v1_across(fleet, "v1-fatal"));
  const auto cancels = cancels_of("V1");
  ASSERT_TRUE(rans_["V1"]->inject_fault(ran::SimFault::battery_failure, 0, 10s));

  const auto done = wait_order("v1-fatal");
  ASSERT_TRUE(done.has_value());
  EXPECT_EQ(done->state(), msg::ORDER_FAILED);
  EXPECT_NE(done->failure().find("battery_failure"), std::string::npos) << done->failure();
  // The route ahead is given up on the topology agent.
  EXPECT_TRUE(gives_up_route("V1", cancels, {"left-2", "bar-2", "right-4"}));
  EXPECT_TRUE(seen_.wait([&] { return alarm_seen(msg::ALARM_CRITICAL, "V1", "battery_failure"); }, 30s))
      << "no critical alarm naming the RAN error";
}

TEST_F(FleetTest, StoppedLogicalAgentStopsItsVehicleAndCancelsItsRouteAhead) {
  constexpr std::uint32_t kDomain = 84;
  Fleet fleet(kDomain, "shutdown");
  fleet.start_infrastructure();
  watch(kDomain, fleet, {"V1"});
  ASSERT_NO_FATAL_FAILURE(send_v1_across(fleet, "v1-shutdown"));
  const auto cancels = cancels_of("V1");
  fleet.stop("V1");
  // The vehicle stood before the agent let go, and the reservations ahead are gone.
  EXPECT_TRUE(wait_status("V1", [](const ran::VehicleStatus& s) { return s.linear_speed == 0.0; }, 10s));
  EXPECT_TRUE(gives_up_route("V1", cancels, {"bar-2", "right-4"}));
  std::lock_guard lock(seen_.mutex);
  EXPECT_LT(seen_.latest["V1"].pose.y, 6.0) << "V1 drove on after its agent stopped";
}

TEST_F(FleetTest, WithdrawnOrdersEndAQueuedOneAtOnceARunningOneOnAVertexAndTheVehicleWorksOn) {
  constexpr std::uint32_t kDomain = 99;
  const std::string domain = std::to_string(kDomain);
  Fleet fleet(kDomain, "withdraw");
  fleet.start_infrastructure();
  watch(kDomain, fleet, {"V1"});
  ASSERT_NO_FATAL_FAILURE(send_v1_across(fleet, "v1-running"));
  ASSERT_EQ(send_order("V1", "v1-queued", {{"left-4", "NOP"}}), "");
  // A stall (shorter than the error limit) keeps V1 from arriving while droverctl works: the
  // running order is still running when its withdrawal comes.
  ASSERT_TRUE(rans_["V1"]->inject_fault(ran::SimFault::stall, seconds_to_ns(30), 10s));

  std::string out, err;
  EXPECT_EQ(droverctl(fleet, "queued", {"order", "withdraw", "V1", "v1-queued", "--reason", "not needed", "--domain", domain},
                      out, err), 0) << err;
  EXPECT_NE(out.find("order 'v1-queued' withdrawn"), std::string::npos) << out;
  const auto queued = wait_order("v1-queued");
  ASSERT_TRUE(queued.has_value());
  EXPECT_EQ(queued->state(), msg::ORDER_WITHDRAWN);
  EXPECT_EQ(queued->failure(), "not needed");
  EXPECT_FALSE(queued->started().present()) << "a withdrawn queued order never starts";

  const auto cancels = cancels_of("V1");
  EXPECT_EQ(droverctl(fleet, "running", {"order", "withdraw", "V1", "v1-running", "--reason", "aisle closed", "--wait",
                                         "200", "--domain", domain}, out, err), 0) << err;
  EXPECT_NE(out.find("being withdrawn"), std::string::npos) << out;
  const auto running = wait_order("v1-running");
  ASSERT_TRUE(running.has_value());
  EXPECT_EQ(running->state(), msg::ORDER_WITHDRAWN) << running->failure();
  EXPECT_EQ(running->failure(), "aisle closed");
  EXPECT_TRUE(gives_up_route("V1", cancels, {}));
  // It stopped short of its destination, standing on a vertex that it holds again, not on
  // an edge.
  const auto on_held_vertex = [&] {
    const auto& status = seen_.latest["V1"];
    const topology::Point position(status.pose.x, status.pose.y);
    for (topology::EntityIndex v = 0; v < world_->vertex_count(); ++v) {
      if (seen_.holders[world_->id(v)] == "V1" && status.linear_speed == 0.0 &&
          bg::distance(position, world_->vertex(v).position) < 0.05) {
        return world_->id(v) != "right-4";
      }
    }
    return false;
  };
  EXPECT_TRUE(seen_.wait(on_held_vertex, 60s)) << "V1 does not stand still on a vertex it holds, short of right-4";

  // An ended order cannot be withdrawn again, an unknown one not at all.
  EXPECT_EQ(droverctl(fleet, "again", {"order", "withdraw", "V1", "v1-running", "--domain", domain}, out, err), 1);
  EXPECT_NE(err.find("has ended already (withdrawn)"), std::string::npos) << err;
  EXPECT_EQ(droverctl(fleet, "unknown", {"order", "withdraw", "V1", "no-such-order", "--domain", domain}, out, err), 1);
  EXPECT_NE(err.find("no order 'no-such-order'"), std::string::npos) << err;

  // The vehicle takes new work from where it stopped.
  ASSERT_EQ(send_order("V1", "v1-after", {{"right-4", "NOP"}}), "");
  const auto after = wait_order("v1-after");
  ASSERT_TRUE(after.has_value());
  EXPECT_EQ(after->state(), msg::ORDER_FINISHED) << after->failure();
  std::lock_guard lock(seen_.mutex);
  EXPECT_TRUE(seen_.hold_violations.empty()) << seen_.hold_violations.front();
  for (const auto& alarm : seen_.alarms) ADD_FAILURE() << "alarm: " << alarm.text();
}

// A RAN out of reach mid-route: its cancel cannot be delivered and where it stands is not
// known, so its logical agent keeps everything the vehicle was allowed onto until the vehicle
// is seen again, stopped (before, it released all but the stale footprint's entities, and the
// vehicle drove on through them once back).
TEST_F(FleetTest, VehicleOutOfReachKeepsWhatItWasAllowedOntoUntilItIsSeenStandingAgain) {
  constexpr std::uint32_t kDomain = 100;
  Fleet fleet(kDomain, "lost");
  fleet.start_infrastructure();
  watch(kDomain, fleet, {"V1"});
  fleet.start_vehicle("V1", "left-0", {}, {"--park-after", "-1", "--charge-below", "0", "--error-limit", "4"});
  ASSERT_TRUE(wait_ready("V1", "left-0"));
  ASSERT_EQ(send_order("V1", "v1-lost", {{"right-4", "NOP"}}), "");
  ASSERT_TRUE(wait_status("V1", [](const ran::VehicleStatus& s) { return s.pose.y > 2.0; })) << "V1 never started";
  const TimeNs lost_at = clock_->now();
  // Longer than the error limit and the 10 s (real) the agent waits for a cancelled vehicle to
  // stand, together.
  constexpr DurationNs kLost = seconds_to_ns(40);
  ASSERT_TRUE(rans_["V1"]->inject_fault(ran::SimFault::lose_connection, kLost, 10s));

  // Silent for longer than the error limit: the order fails.
  const auto lost = wait_order("v1-lost");
  ASSERT_TRUE(lost.has_value());
  EXPECT_EQ(lost->state(), msg::ORDER_FAILED);
  EXPECT_NE(lost->failure().find("ran_lost"), std::string::npos) << lost->failure();
  // Back in reach, it stops, and what it no longer needs is released: at most the vertex it
  // stands on and the edges that vertex's footprint reaches into stay held.
  ASSERT_TRUE(wait_status("V1", [&](const ran::VehicleStatus& s) { return s.time > lost_at + kLost / 2; }, 120s))
      << "V1 never came back";
  EXPECT_TRUE(seen_.wait(
      [&] {
        std::size_t vertices = 0;
        for (const auto& [entity, holder] : seen_.holders) {
          if (holder == "V1" && world_->is_vertex(*world_->find(entity))) ++vertices;
        }
        return vertices == 1;
      },
      60s))
      << "V1 does not hold exactly the vertex it stands on";
  // From where it braked (often a little past that vertex) it takes new work.
  ASSERT_EQ(send_order("V1", "v1-home", {{"left-0", "NOP"}}), "");
  const auto home = wait_order("v1-home");
  ASSERT_TRUE(home.has_value());
  EXPECT_EQ(home->state(), msg::ORDER_FINISHED) << home->failure();

  std::lock_guard lock(seen_.mutex);
  const auto& times = seen_.status_times["V1"];
  const auto first_back = std::find_if(times.begin(), times.end(), [&](TimeNs t) { return t > lost_at + kLost / 2; });
  ASSERT_NE(first_back, times.end());
  ASSERT_NE(first_back, times.begin());
  // The silence began with the last status before it (the fault took effect some time
  // after it was asked for, later on a loaded host).
  const TimeNs last_heard = *std::prev(first_back);
  // The entities already passed when the last status came may go (the vehicle has left
  // them); nothing after, until the vehicle is seen again.
  for (const auto& [time, agent] : seen_.releases) {
    EXPECT_FALSE(agent == "V1" && time > last_heard + seconds_to_ns(2) && time < *first_back)
        << "V1 released an entity " << ns_to_seconds(time - last_heard) << " s into its silence";
  }
  EXPECT_FALSE(alarm_seen(msg::ALARM_CRITICAL, "V1", "left its allocated area")) << "V1 drove outside what it held";
  EXPECT_TRUE(seen_.hold_violations.empty()) << seen_.hold_violations.front();
}

// A vehicle that stands where its route planned to leave, and cannot plan on (a lock closes
// the only way to its destination): the vehicle behind it, due on that vertex next, must
// not wait for ever. Before, the stranded vehicle's window there ran out, so neither its
// re-plan nor, once its order failed, a hold of its vertex could be planned (the next
// vehicle's reservation lay on it), and it retried that hold 20 times a second for ever
// while the other waited for the vertex it still held.
TEST_F(FleetTest, VehicleStrandedOnAnothersWayKeepsItsVertexReservedThenClearsTheWay) {
  constexpr std::uint32_t kDomain = 101;
  Fleet fleet(kDomain, "stranded");
  fleet.start_infrastructure();
  watch(kDomain, fleet, {"V1", "V2"});
  fleet.start_vehicle("V1", "left-0", {}, {"--park-after", "-1", "--charge-below", "0", "--route-limit", "6"});
  fleet.start_vehicle("V2", "left-4");
  ASSERT_TRUE(wait_ready("V1", "left-0"));
  ASSERT_TRUE(wait_ready("V2", "left-4"));
  ASSERT_EQ(send_order("V1", "v1-stranded", {{"right-4", "NOP"}}), "");
  ASSERT_TRUE(wait_status("V1", [](const ran::VehicleStatus& s) { return s.pose.y > 1.0; })) << "V1 never started";
  // V2 follows V1 over the bar to right-1, after it (V1's route is reserved first).
  ASSERT_EQ(send_order("V2", "v2-behind", {{"right-1", "NOP"}}), "");
  ASSERT_TRUE(wait_status("V1", [](const ran::VehicleStatus& s) { return s.pose.x > 1.0; }))
      << "V1 never reached the bar";

  // right-3, the only way to right-4, closed for longer than a route may look ahead.
  auto lock_client = dds::ServiceClient<msg::LockRequest, msg::LockReply>::create(*participant_, "topology", "lock");
  ASSERT_TRUE(lock_client.has_value());
  msg::LockRequest lock;
  lock.entity("right-3");
  lock.window().start(clock_->now());
  lock.window().end(clock_->now() + seconds_to_ns(3 * 3600));
  lock.operator_id("tester");
  lock.reason("spill");
  auto locked = (*lock_client)->call(lock, 10s);
  ASSERT_TRUE(locked.has_value());
  ASSERT_EQ(locked->error().code(), msg::ERROR_NONE) << locked->error().message();

  // V1 cannot go on: its order fails where it stands, on V2's way.
  const auto stranded = wait_order("v1-stranded");
  ASSERT_TRUE(stranded.has_value());
  EXPECT_EQ(stranded->state(), msg::ORDER_FAILED);
  // It tells the operator it cannot hold its vertex, drives aside to a parking vertex, and
  // V2 gets through.
  const auto behind = wait_order("v2-behind");
  ASSERT_TRUE(behind.has_value()) << "V2 never got past the stranded V1";
  EXPECT_EQ(behind->state(), msg::ORDER_FINISHED) << behind->failure();
  // The nearest parking vertex a route leads to: where V1 stopped on the bar decides which.
  EXPECT_TRUE(seen_.wait([&] { return seen_.holders["right-0"] == "V1" || seen_.holders["left-0"] == "V1"; }, 60s))
      << "V1 did not clear the way to a parking vertex";

  std::lock_guard guard(seen_.mutex);
  const auto stranded_alarm = std::find_if(seen_.alarms.begin(), seen_.alarms.end(), [](const auto& alarm) {
    return alarm.severity() == msg::ALARM_WARNING && alarm.vehicle() == "V1" &&
           alarm.text().find("cannot hold") != std::string::npos;
  });
  ASSERT_NE(stranded_alarm, seen_.alarms.end()) << "no 'cannot hold' warning from V1";
  // Kept reserved, its vertex lets V1 drive off at its first or second try (every 10 s;
  // the second and the drive to the parking vertex take about 15 s, more on a loaded host).
  // Without that, the next vehicle's reservation lay on it and no route led away until that
  // vehicle's own lateness happened to push it back (35 s and more).
  const TimeNs stranded_at = stranded_alarm->time().ns();
  std::optional<TimeNs> parked_at;
  for (const auto* parking : {"left-0", "right-0"}) {
    for (const auto& [time, holder] : seen_.holder_log[parking]) {
      if (holder == "V1" && time >= stranded_at && (!parked_at || time < *parked_at)) parked_at = time;
    }
  }
  ASSERT_TRUE(parked_at.has_value());
  EXPECT_LE(*parked_at - stranded_at, seconds_to_ns(25)) << "V1 took long to clear the way";
  EXPECT_EQ(seen_.holders["right-1"], "V2");
  EXPECT_TRUE(seen_.hold_violations.empty()) << seen_.hold_violations.front();
  EXPECT_TRUE(seen_.overlaps.empty()) << seen_.overlaps.front();
  for (const auto& alarm : seen_.alarms) {
    EXPECT_NE(alarm.severity(), msg::ALARM_CRITICAL) << alarm.text();
  }
}

}  // namespace
}  // namespace drover::test
