#pragma once
// The interface a vehicle integrator implements: a VehicleDriver receives commands and
// reports status through a StatusSink. The runner (drover::ran_runner) connects a driver to
// DDS; tests and tools can drive one directly. See docs/ran-sdk.md for the contract.

#include <cstdint>
#include <mutex>

#include "drover/common/clock.hpp"
#include "drover/ran/commands.hpp"
#include "drover/ran/status.hpp"

namespace drover::ran {

/// Where a driver sends its status reports. report() is thread-safe, so a driver may report
/// from its own threads (e.g. a thread reading the vehicle's telemetry).
class StatusSink {
 public:
  virtual ~StatusSink() = default;

  /// Stamps `status.sequence` with the next number of this sink (1, 2, 3, ...) and delivers
  /// the status. Reports are delivered one at a time, in sequence order.
  void report(VehicleStatus status);

 protected:
  /// Publishes or records one stamped status. Called with the sink's lock held: never
  /// call report() from here.
  virtual void deliver(const VehicleStatus& status) = 0;

 private:
  std::mutex mutex_;
  std::uint64_t last_sequence_ = 0;
};

/// A vehicle driver. The runner calls its members one at a time, never concurrently (each
/// call completes before the next starts, possibly on another thread), so an implementation
/// needs no locking for its own state unless it starts threads itself. Every call carries
/// `now`, the shared-clock time of the call.
///
/// Contract (what the commander relies on):
///  - Every command is answered by a report listing it: accepted (queued), or rejected with
///    a code and reason. Commands execute in the order received.
///  - A command's state changes are reported as they happen: running, then finished,
///    failed (with code and reason) or cancelled. When a command fails, the commands queued
///    after it fail too (they started where it should have ended).
///  - The vehicle stays inside the motion area of the move it executes; a move it cannot
///    execute inside its area is rejected, never started.
///  - Status is reported on every change and at least every status period, whether the
///    vehicle moves or not (on_tick is the natural place): a commander that hears nothing
///    for 3 s takes the RAN for lost.
class VehicleDriver {
 public:
  virtual ~VehicleDriver() = default;

  /// The runner is ready; from now on report through `sink`, until stop(). Report the
  /// initial status here.
  virtual void start(StatusSink& sink, TimeNs now) = 0;
  /// The runner is shutting down: the sink must not be used once this returns (stop any
  /// thread that reports). No other member is called afterwards. Default: nothing.
  virtual void stop(TimeNs now) { (void)now; }
  /// Queue a move after the commands already queued.
  virtual void on_move(const MoveCommand& command, TimeNs now) = 0;
  /// Queue an action after the commands already queued.
  virtual void on_action(const ActionCommand& command, TimeNs now) = 0;
  /// Cancel a command and every command queued after it. A moving vehicle brakes; a command
  /// already completed is not undone.
  virtual void on_cancel(const CommandId& command, TimeNs now) = 0;
  /// Stop (braking normally) and hold until on_resume; queued commands are kept.
  virtual void on_pause(TimeNs now) = 0;
  virtual void on_resume(TimeNs now) = 0;
  /// Called periodically (the status period) so the driver can report; default: nothing.
  virtual void on_tick(TimeNs now) { (void)now; }
  /// False while the driver cannot reach its vehicle: the runner then answers commands
  /// with "unavailable" instead of delivering them. Default: always reachable.
  virtual bool connected() const { return true; }
};

}  // namespace drover::ran
