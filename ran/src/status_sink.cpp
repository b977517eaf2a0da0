#include <utility>

#include "drover/ran/vehicle_driver.hpp"

namespace drover::ran {

void StatusSink::report(VehicleStatus status) {
  std::lock_guard lock(mutex_);
  status.sequence = ++last_sequence_;
  deliver(status);
}

}  // namespace drover::ran
