#pragma once
// Connects a VehicleDriver to DDS, so that a vehicle integrator writes no DDS code:
//  - serves drover/ran/command for one vehicle (moves, actions, cancel, pause, resume),
//    delivering each command to the driver and replying with the driver's verdict;
//  - publishes every status the driver reports on drover/ran/status (keyed on the vehicle);
//  - calls the driver's on_tick at the status period.
// RanNode adds the participant and the agent heartbeat; run_ran_node() also handles the
// shutdown signals: a complete RAN process in one call.

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "drover/common/clock.hpp"
#include "drover/common/result.hpp"
#include "drover/dds/heartbeat_publisher.hpp"
#include "drover/dds/participant.hpp"
#include "drover/ran/vehicle_driver.hpp"
#include "drover/ran_runner/names.hpp"

namespace drover::ran {

struct RanRunnerOptions {
  std::string vehicle_id;
  /// Real time between two on_tick calls (and so between two status reports of a driver
  /// that reports on every tick).
  std::chrono::milliseconds status_period{100};
};

class RanRunner {
 public:
  /// Starts the driver (VehicleDriver::start), the command server, the status writer and
  /// the tick thread.
  /// \return the runner, or invalid_argument (empty vehicle id, status period not
  ///         positive), or the DDS layer's errors.
  /// Contract: `participant` and `driver` outlive the runner.
  static Result<std::unique_ptr<RanRunner>> create(dds::Participant& participant, SharedClock clock,
                                                   VehicleDriver& driver, RanRunnerOptions options);
  /// Stops ticking and serving, then stops the driver (VehicleDriver::stop); the driver is
  /// not called after this returns.
  ~RanRunner();

  /// Runs `action` with the driver's lock held (never concurrently with a driver call),
  /// passing the current shared-clock time, then ticks the driver so it reports.
  void with_driver(const std::function<void(TimeNs now)>& action);

  const std::string& vehicle_id() const noexcept { return options_.vehicle_id; }

 private:
  class Sink;
  class CommandServer;

  RanRunner(SharedClock clock, VehicleDriver& driver, RanRunnerOptions options);
  void tick_loop();

  SharedClock clock_;
  VehicleDriver& driver_;
  RanRunnerOptions options_;
  std::mutex driver_mutex_;  ///< serialises every driver call
  std::unique_ptr<Sink> sink_;
  std::unique_ptr<CommandServer> server_;

  std::mutex tick_mutex_;
  std::condition_variable tick_wake_;
  bool stopping_ = false;
  std::thread tick_thread_;
};

/// What a RAN process needs besides its driver.
struct RanNodeOptions {
  std::string vehicle_id;
  /// The participant name; empty: ran_agent_id(vehicle_id).
  std::string agent_id;
  std::uint32_t domain_id = 0;
  /// A Fast DDS XML profiles file (transports, security); empty: none.
  std::string xml_profile_file;
  std::chrono::milliseconds status_period{100};
};

/// A complete RAN: the participant (named after the agent id), the agent heartbeat (kind
/// "ran", owning the vehicle id) and a RanRunner for the driver.
class RanNode {
 public:
  /// \return the node, or invalid_argument / the DDS layer's errors.
  /// Contract: `driver` outlives the node.
  static Result<std::unique_ptr<RanNode>> create(VehicleDriver& driver, const RanNodeOptions& options,
                                                 SharedClock clock);
  ~RanNode();

  dds::Participant& participant() noexcept { return *participant_; }
  RanRunner& runner() noexcept { return *runner_; }

 private:
  RanNode() = default;
  std::unique_ptr<dds::Participant> participant_;
  std::unique_ptr<dds::HeartbeatPublisher> heartbeat_;
  std::unique_ptr<RanRunner> runner_;
};

/// Runs `driver` as a RAN until SIGINT or SIGTERM (installs the handlers itself): what an
/// integrator's main() calls.
/// \return success after a clean shutdown, or the first error setting up.
Status run_ran_node(VehicleDriver& driver, const RanNodeOptions& options, SharedClock clock);

}  // namespace drover::ran
