#include "drover/ran_runner/sim_fault_server.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "drover/dds/wire_error.hpp"
#include "ran_messages.hpp"

namespace drover::ran {

namespace {

const char* fault_name(msg::SimFaultKind kind) {
  switch (kind) {
    case msg::SIM_FAULT_STALL: return "stall";
    case msg::SIM_FAULT_PROTECTIVE_FIELD: return "protective field";
    case msg::SIM_FAULT_CLEAR_PROTECTIVE_FIELD: return "protective field cleared";
    case msg::SIM_FAULT_BATTERY_FAILURE: return "battery failure";
    case msg::SIM_FAULT_LOSE_CONNECTION: return "connection lost";
    case msg::SIM_FAULT_RESTORE_CONNECTION: return "connection restored";
  }
  return "unknown";
}

}  // namespace

Result<std::unique_ptr<SimFaultServer>> SimFaultServer::create(dds::Participant& participant,
                                                               RanRunner& runner,
                                                               SimDriver& driver) {
  std::unique_ptr<SimFaultServer> faults(new SimFaultServer(runner, driver));
  auto server = Server::create(
      participant, kServiceArea, kSimFaultService,
      [raw = faults.get()](const msg::SimFaultRequest& request,
                           dds::ReplyHandle<msg::SimFaultReply> reply) {
        msg::SimFaultReply answer;
        const auto applied = raw->apply(request);
        answer.error(applied ? dds::wire_ok() : dds::to_wire(applied.error()));
        if (auto sent = reply.send(std::move(answer)); !sent) {
          spdlog::warn("sim fault reply not sent: {}", sent.error().message);
        }
      });
  if (!server) return unexpected(server.error());
  faults->server_ = std::move(*server);
  return faults;
}

Status SimFaultServer::apply(const msg::SimFaultRequest& request) {
  if (request.vehicle_id() != runner_.vehicle_id()) {
    return fail(ErrorCode::not_found, fmt::format("this RAN simulates vehicle '{}', not '{}'",
                                                  runner_.vehicle_id(), request.vehicle_id()));
  }
  const DurationNs duration = request.duration_ns();
  if (request.kind() == msg::SIM_FAULT_STALL && duration <= 0) {
    return fail(ErrorCode::invalid_argument, "a stall needs a positive duration_ns");
  }
  Status outcome;
  runner_.with_driver([&](TimeNs now) {
    SimVehicle& vehicle = driver_.vehicle();
    vehicle.advance_to(now);
    switch (request.kind()) {
      case msg::SIM_FAULT_STALL: vehicle.inject_stall(duration); break;
      case msg::SIM_FAULT_PROTECTIVE_FIELD: vehicle.trigger_protective_field(); break;
      case msg::SIM_FAULT_CLEAR_PROTECTIVE_FIELD: vehicle.clear_protective_field(); break;
      case msg::SIM_FAULT_BATTERY_FAILURE: vehicle.fail_battery(); break;
      case msg::SIM_FAULT_LOSE_CONNECTION:
        vehicle.lose_connection(duration > 0 ? duration : kForever);
        break;
      case msg::SIM_FAULT_RESTORE_CONNECTION: vehicle.restore_connection(); break;
      default:
        outcome = fail(ErrorCode::invalid_argument,
                       fmt::format("unknown fault kind {}", static_cast<int>(request.kind())));
        return;
    }
    spdlog::info("{}: fault injected: {}", runner_.vehicle_id(), fault_name(request.kind()));
  });
  return outcome;
}

}  // namespace drover::ran
