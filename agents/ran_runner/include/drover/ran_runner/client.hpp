#pragma once
// The commander's side of a RAN (a logical agent, a tool, a test): sends commands to one
// vehicle's RAN over drover/ran/command and follows its status on drover/ran/status.

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "drover/common/result.hpp"
#include "drover/dds/participant.hpp"
#include "drover/dds/reader.hpp"
#include "drover/dds/service_client.hpp"
#include "drover/ran/commands.hpp"
#include "drover/ran/status.hpp"
#include "drover/ran_runner/names.hpp"
#include "drover/ran_runner/twin_writer_watch.hpp"
#include "ran.h"

namespace drover::ran {

/// What the RAN said about a command it delivered to its driver.
struct CommandVerdict {
  /// The command's state in the driver's report right after delivery (accepted, rejected,
  /// or already further); nullopt when the driver had not reported it yet.
  std::optional<CommandState> state;
  std::string code;    ///< for rejected: the rejection code
  std::string reason;  ///< for rejected: why

  bool rejected() const noexcept { return state == CommandState::rejected; }
};

/// Faults a simulated vehicle (drover ran-sim) accepts on drover/ran/sim_fault.
enum class SimFault {
  stall,                   ///< for a duration
  protective_field,        ///< until clear_protective_field
  clear_protective_field,
  battery_failure,
  lose_connection,         ///< for a duration; <= 0: until restore_connection
  restore_connection,
};

/// Thread-safe. Must be destroyed before its Participant.
class RanClient {
 public:
  /// Called with every status received, on the client's reader thread, after it is
  /// recorded and before wait_for() sees it; it must not destroy the client.
  using StatusCallback = std::function<void(const VehicleStatus&)>;
  /// Called with the reason, on the client's reader thread, when the RAN's statuses begin
  /// to be refused: the first refused one after one taken (or before any). Not again while
  /// they go on being refused, whatever each one's reason; it must not destroy the client.
  using RefusalCallback = std::function<void(const std::string&)>;

  /// A client for `vehicle_id`'s RAN, whose agent id is `ran_agent` (empty: ran_agent_id()),
  /// keeping the last `history_limit` (>= 1) statuses received.
  /// \return the client, or the DDS layer's errors.
  static Result<std::unique_ptr<RanClient>> create(dds::Participant& participant,
                                                   std::string vehicle_id,
                                                   std::string ran_agent = {},
                                                   std::size_t history_limit = 1000,
                                                   StatusCallback on_status = {},
                                                   RefusalCallback on_refusal = {});
  ~RanClient();

  /// Sends a command and waits for the RAN's reply.
  /// \return the verdict (a rejection is a verdict, not an error), or timeout (no RAN
  ///         answered), or the RAN's refusal: not_found (wrong vehicle), unavailable (it
  ///         cannot reach its vehicle), invalid_argument (malformed).
  Result<CommandVerdict> move(const MoveCommand& command, std::chrono::milliseconds timeout);
  Result<CommandVerdict> action(const ActionCommand& command, std::chrono::milliseconds timeout);
  Status cancel(const CommandId& command, std::chrono::milliseconds timeout);
  Status pause(std::chrono::milliseconds timeout);
  Status resume(std::chrono::milliseconds timeout);

  /// Injects a fault into a simulated vehicle. \return success, or the RAN's error.
  Status inject_fault(SimFault fault, DurationNs duration, std::chrono::milliseconds timeout);

  /// The latest status received, if any.
  std::optional<VehicleStatus> latest() const;
  /// Waits until a status satisfies `condition`: the latest one already received, or any
  /// one received while waiting. \return that status, or nullopt after `timeout`.
  std::optional<VehicleStatus> wait_for(const std::function<bool(const VehicleStatus&)>& condition,
                                        std::chrono::milliseconds timeout) const;
  /// The statuses received (at most the history limit), oldest first.
  std::vector<VehicleStatus> history() const;
  /// Why the RAN's latest status was refused (a malformed message, e.g. a footprint that is
  /// no valid polygon), when it came within `max_age` and no status was taken since: such a
  /// RAN reports, yet nothing it says is heard. nullopt otherwise (the latest status was
  /// taken, none arrived, or the RAN has gone quiet since).
  std::optional<std::string> refusal(std::chrono::steady_clock::duration max_age) const;
  /// Whether two RANs report for the vehicle (TwinWriterWatch): the latest status was
  /// refused for that, within the last two seconds. Both take the commands sent to the
  /// vehicle's RAN agent id, so a commander sends nothing but cancels meanwhile.
  bool two_rans() const;

  const std::string& vehicle_id() const noexcept { return vehicle_id_; }

 private:
  using CommandClient = dds::ServiceClient<msg::RanCommandRequest, msg::RanCommandReply>;
  using FaultClient = dds::ServiceClient<msg::SimFaultRequest, msg::SimFaultReply>;

  RanClient(std::string vehicle_id, std::string ran_agent, std::size_t history_limit,
            StatusCallback on_status, RefusalCallback on_refusal);
  Result<CommandVerdict> send(msg::RanCommandRequest request, std::chrono::milliseconds timeout);
  void receive(const msg::RanStatus& status, const dds::SampleSource& source);

  std::string vehicle_id_;
  std::string ran_agent_;
  std::unique_ptr<CommandClient> commands_;
  std::unique_ptr<FaultClient> faults_;

  mutable std::mutex mutex_;
  mutable std::condition_variable arrived_;
  std::size_t history_limit_;
  StatusCallback on_status_;
  RefusalCallback on_refusal_;
  std::deque<VehicleStatus> history_;
  std::uint64_t received_ = 0;  ///< statuses received so far; history_.back() is number received_
  /// Why the latest status was refused, and when; nullopt once one is taken (refusal()).
  struct Refusal {
    std::string reason;
    std::chrono::steady_clock::time_point when;
    bool two_rans = false;  ///< refused because two RANs report
  };
  std::optional<Refusal> refusal_;
  TwinWriterWatch twins_;  ///< a second RAN reporting for this vehicle
  std::unique_ptr<dds::Reader<msg::RanStatus>> reader_;  // last: stopped first
};

}  // namespace drover::ran
