#include "agents/cli/vehicle_states.hpp"

#include "drover/logical_agent/names.hpp"

namespace drover::cli {

Result<std::unique_ptr<VehicleStates>> VehicleStates::create(dds::Participant& participant) {
  std::unique_ptr<VehicleStates> self(new VehicleStates());
  VehicleStates* follower = self.get();
  auto reader = dds::Reader<msg::VehicleState>::create(
      participant, logical_agent::kVehicleStateTopic,
      [follower](const msg::VehicleState& state) { follower->on_state(state); });
  if (!reader) return unexpected(reader.error());
  self->reader_ = std::move(*reader);
  return self;
}

VehicleStates::~VehicleStates() { reader_.reset(); }

VehicleStates::States VehicleStates::states() const {
  std::lock_guard lock(mutex_);
  return states_;
}

bool VehicleStates::wait(const std::function<bool(const States&)>& condition,
                         std::chrono::milliseconds timeout) const {
  std::unique_lock lock(mutex_);
  return changed_.wait_for(lock, timeout, [&] { return condition(states_); });
}

void VehicleStates::on_state(const msg::VehicleState& state) {
  {
    std::lock_guard lock(mutex_);
    states_[state.vehicle()] = state;
  }
  changed_.notify_all();
}

}  // namespace drover::cli
