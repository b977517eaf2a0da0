#pragma once
// The latest state of every vehicle, as its logical agent publishes it (drover/logical/vehicle,
// kept for late joiners). Shared by `droverctl vehicles` and `droverctl pause`.

#include <chrono>
#include <condition_variable>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>

#include "drover/common/result.hpp"
#include "drover/dds/participant.hpp"
#include "drover/dds/reader.hpp"
#include "drover/logical_agent/messages.hpp"

namespace drover::cli {

/// Follows the vehicle states of a domain from its creation until destroyed. Thread-safe.
/// Must be destroyed before its Participant.
class VehicleStates {
 public:
  using States = std::map<std::string, msg::VehicleState>;

  /// \return the follower, or the reader's creation error.
  static Result<std::unique_ptr<VehicleStates>> create(dds::Participant& participant);
  ~VehicleStates();

  /// The latest state of each vehicle heard from so far, by vehicle id.
  States states() const;
  /// Waits until `condition` holds for the states (checked on each new state), at most
  /// `timeout`. \return whether it held.
  bool wait(const std::function<bool(const States&)>& condition, std::chrono::milliseconds timeout) const;

 private:
  VehicleStates() = default;
  void on_state(const msg::VehicleState& state);

  mutable std::mutex mutex_;
  mutable std::condition_variable changed_;
  States states_;
  std::unique_ptr<dds::Reader<msg::VehicleState>> reader_;  ///< reset first: its callback fills states_
};

}  // namespace drover::cli
