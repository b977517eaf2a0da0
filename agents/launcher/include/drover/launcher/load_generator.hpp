#pragma once
// The load generator (`drover load-generator`, docs/launch.md): keeps every idle vehicle
// busy with random transport orders between stations, like openTCS's continuous-load
// plugin. It watches drover/logical/vehicle; a vehicle that is idle (or parking on its
// own), has no order and none of ours outstanding gets the next order: load at one
// station, unload at another. An order stays outstanding until its progress says it
// finished or failed, or its request was refused. A vehicle that refuses an order as
// invalid (it does not perform load or unload, a station is unknown to it) is left out
// from then on: it would refuse every other order alike.

#include <atomic>
#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "drover/common/result.hpp"
#include "drover/dds/participant.hpp"
#include "drover/dds/reader.hpp"
#include "drover/dds/service_client.hpp"
#include "drover/launcher/station_picker.hpp"
#include "logical.h"

namespace drover::launcher {

struct LoadGeneratorOptions {
  /// Where orders go; at least two distinct vertex ids.
  std::vector<std::string> stations;
  /// The vehicles it serves; empty: every vehicle that reports its state.
  std::vector<std::string> vehicles;
  std::uint64_t seed = 1;
  /// Stop sending after this many orders were sent; 0: never stop.
  std::uint64_t max_orders = 0;
  /// Orders are named "<prefix>-<n>"; the agent id by default.
  std::string order_prefix;
  std::chrono::milliseconds request_timeout{5000};
};

struct LoadFigures {
  std::uint64_t queued = 0;    ///< orders a logical agent accepted
  std::uint64_t refused = 0;   ///< orders refused or not answered
  std::uint64_t left_out = 0;  ///< vehicles left out: they refused an order as invalid
  std::uint64_t finished = 0;  ///< of ours, finished
  std::uint64_t failed = 0;    ///< of ours, failed
  std::uint64_t withdrawn = 0;  ///< of ours, withdrawn (by an operator)
};

/// Why `stations` cannot serve a load generator, if they cannot: orders go between two
/// distinct stations, so at least two, none named twice.
std::optional<std::string> stations_problem(const std::vector<std::string>& stations);

/// Thread-safe. Must be destroyed before its Participant.
class LoadGenerator {
 public:
  /// \return the generator, or invalid_argument (stations_problem), or the DDS layer's
  ///         errors.
  static Result<std::unique_ptr<LoadGenerator>> create(dds::Participant& participant,
                                                       LoadGeneratorOptions options);
  ~LoadGenerator();

  LoadFigures figures() const;

 private:
  using OrderClient = dds::ServiceClient<msg::OrderRequest, msg::OrderReply>;

  explicit LoadGenerator(LoadGeneratorOptions options);
  void on_vehicle(const msg::VehicleState& state);
  void on_progress(const msg::OrderProgress& progress);
  /// Sends the next order to `vehicle` if it is free; called on either reader's thread.
  void consider(const std::string& vehicle);
  /// Sends `load` at `from` (unless empty), then `unload` at `to`.
  void send(const std::string& vehicle, const std::string& order, const std::string& from,
            const std::string& to);

  LoadGeneratorOptions options_;
  std::set<std::string> served_;  ///< empty: every vehicle

  mutable std::mutex mutex_;
  StationPicker picker_;
  std::map<std::string, msg::VehicleState> vehicles_;   ///< latest state per vehicle
  std::map<std::string, std::string> outstanding_;      ///< vehicle -> our order
  /// Vehicles whose order failed after its load: they may still carry it, so their next
  /// order only unloads (a load on a loaded vehicle fails).
  std::set<std::string> may_carry_;
  /// Vehicles that refused an order as invalid (invalid_argument), sent nothing more.
  std::set<std::string> left_out_;
  std::uint64_t next_number_ = 1;
  LoadFigures figures_;

  std::unique_ptr<OrderClient> orders_;
  std::unique_ptr<dds::Reader<msg::OrderProgress>> progress_reader_;
  std::unique_ptr<dds::Reader<msg::VehicleState>> vehicle_reader_;
};

}  // namespace drover::launcher
