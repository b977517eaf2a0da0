#pragma once
// A vehicle driver as an integrator writes one: this "vehicle" drives in a straight line at
// constant speed (no acceleration) and "loads" in one second. A real driver would send the
// commands to its vehicle and report what the vehicle tells it.

#include <deque>
#include <string>
#include <variant>

#include <drover/ran/validation.hpp>
#include <drover/ran/vehicle_driver.hpp>

class StraightLineDriver final : public drover::ran::VehicleDriver {
 public:
  StraightLineDriver(std::string vehicle_id, drover::ran::Pose start);

  void start(drover::ran::StatusSink& sink, drover::TimeNs now) override;
  void stop(drover::TimeNs now) override;
  void on_move(const drover::ran::MoveCommand& command, drover::TimeNs now) override;
  void on_action(const drover::ran::ActionCommand& command, drover::TimeNs now) override;
  void on_cancel(const drover::ran::CommandId& command, drover::TimeNs now) override;
  void on_pause(drover::TimeNs now) override;
  void on_resume(drover::TimeNs now) override;
  void on_tick(drover::TimeNs now) override;

  /// True when no command is queued or running.
  bool idle() const { return queue_.empty(); }

 private:
  using Command = std::variant<drover::ran::MoveCommand, drover::ran::ActionCommand>;
  struct Queued {
    Command command;
    double remaining = 0;  ///< metres to drive, or seconds to operate
  };

  static drover::ran::CommandId id_of(const Command& command);
  void advance(drover::TimeNs now);
  void accept(Command command, double amount);
  void reject(const drover::ran::CommandId& id, const drover::ran::Rejection& why);
  void end_front(drover::ran::CommandState state, std::string reason);
  void set_state(const drover::ran::CommandId& id, drover::ran::CommandState state,
                 std::string code = {}, std::string reason = {});
  void report(drover::TimeNs now);

  drover::ran::StatusSink* sink_ = nullptr;
  drover::ran::VehicleStatus status_;
  drover::ran::Pose planned_end_;  ///< where the last queued move ends
  std::deque<Queued> queue_;
  drover::TimeNs last_update_ = 0;
};
