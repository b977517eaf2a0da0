#pragma once
// Serves drover/ran/sim_fault for a simulated vehicle run by a RanRunner: tests, demos and
// operators inject stalls, protective-field stops, battery failures and connection losses
// (SimVehicle's faults) into a running `drover ran-sim`.

#include <memory>

#include "drover/common/result.hpp"
#include "drover/dds/participant.hpp"
#include "drover/dds/service_server.hpp"
#include "drover/ran/sim_driver.hpp"
#include "drover/ran_runner/runner.hpp"
#include "ran.h"

namespace drover::ran {

class SimFaultServer {
 public:
  /// \return the server, or the DDS layer's errors.
  /// Contract: `runner` runs `driver` and outlives the server.
  static Result<std::unique_ptr<SimFaultServer>> create(dds::Participant& participant,
                                                        RanRunner& runner, SimDriver& driver);

 private:
  using Server = dds::ServiceServer<msg::SimFaultRequest, msg::SimFaultReply>;
  SimFaultServer(RanRunner& runner, SimDriver& driver) : runner_(runner), driver_(driver) {}
  Status apply(const msg::SimFaultRequest& request);

  RanRunner& runner_;
  SimDriver& driver_;
  std::unique_ptr<Server> server_;
};

}  // namespace drover::ran
