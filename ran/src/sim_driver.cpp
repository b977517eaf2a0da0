#include "drover/ran/sim_driver.hpp"

#include <spdlog/spdlog.h>

namespace drover::ran {

void SimDriver::start(StatusSink& sink, TimeNs now) {
  sink_ = &sink;
  vehicle_.advance_to(now);
  report();
}

void SimDriver::stop(TimeNs now) {
  vehicle_.advance_to(now);
  sink_ = nullptr;
}

void SimDriver::on_move(const MoveCommand& command, TimeNs now) {
  vehicle_.advance_to(now);
  log_refusal("move", command.id, vehicle_.submit(command));
  report();
}

void SimDriver::on_action(const ActionCommand& command, TimeNs now) {
  vehicle_.advance_to(now);
  log_refusal("action", command.id, vehicle_.submit(command));
  report();
}

void SimDriver::on_cancel(const CommandId& command, TimeNs now) {
  vehicle_.advance_to(now);
  log_refusal("cancel of", command, vehicle_.cancel(command));
  report();
}

void SimDriver::on_pause(TimeNs now) {
  vehicle_.advance_to(now);
  vehicle_.pause();
  report();
}

void SimDriver::on_resume(TimeNs now) {
  vehicle_.advance_to(now);
  vehicle_.resume();
  report();
}

void SimDriver::on_tick(TimeNs now) {
  vehicle_.advance_to(now);
  report();
}

void SimDriver::report() {
  if (sink_ != nullptr && vehicle_.connected()) sink_->report(vehicle_.status());
}

void SimDriver::log_refusal(const char* what, const CommandId& id, const CommandCheck& check) const {
  if (check) return;
  spdlog::warn("{}: {} '{}' refused ({}): {}", vehicle_.config().vehicle_id, what, id,
               check.error().code, check.error().reason);
}

}  // namespace drover::ran
