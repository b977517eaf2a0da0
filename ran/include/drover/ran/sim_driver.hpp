#pragma once
// The simulated vehicle behind the VehicleDriver interface: what `drover ran-sim` runs.
// Every call first advances the simulation to the call's shared-clock time.

#include "drover/ran/sim_vehicle.hpp"
#include "drover/ran/vehicle_driver.hpp"

namespace drover::ran {

class SimDriver final : public VehicleDriver {
 public:
  explicit SimDriver(SimVehicle vehicle) : vehicle_(std::move(vehicle)) {}

  void start(StatusSink& sink, TimeNs now) override;
  void stop(TimeNs now) override;
  void on_move(const MoveCommand& command, TimeNs now) override;
  void on_action(const ActionCommand& command, TimeNs now) override;
  void on_cancel(const CommandId& command, TimeNs now) override;
  void on_pause(TimeNs now) override;
  void on_resume(TimeNs now) override;
  /// Advances the simulation and reports (the runner calls this at the status rate).
  void on_tick(TimeNs now) override;
  /// False while a simulated connection loss lasts (SimVehicle::lose_connection).
  bool connected() const override { return vehicle_.connected(); }

  /// The simulation, e.g. to inject faults; call it from the runner's thread only, and
  /// call on_tick afterwards so the change is reported.
  SimVehicle& vehicle() noexcept { return vehicle_; }

 private:
  /// Reports the current status unless the simulated link is down.
  void report();
  void log_refusal(const char* what, const CommandId& id, const CommandCheck& check) const;

  SimVehicle vehicle_;
  StatusSink* sink_ = nullptr;
};

}  // namespace drover::ran
