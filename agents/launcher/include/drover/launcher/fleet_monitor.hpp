#pragma once
// The launcher's view of the fleet over DDS: order progress (for the progress line and the
// summary), RAN statuses (vehicles moving) and, with a trace, every RAN status and every
// topology event written to it.

#include <map>
#include <memory>
#include <mutex>
#include <string>

#include "drover/common/clock.hpp"
#include "drover/common/result.hpp"
#include "drover/dds/participant.hpp"
#include "drover/dds/reader.hpp"
#include "drover/launcher/order_tally.hpp"
#include "drover/launcher/trace_writer.hpp"
#include "logical.h"
#include "ran.h"
#include "topology.h"

namespace drover::launcher {

struct FleetFigures {
  OrderFigures orders;
  std::size_t vehicles_reporting = 0;  ///< vehicles whose RAN status arrived
  std::size_t vehicles_moving = 0;     ///< of those, the ones moving in their latest status
  std::uint64_t statuses = 0;          ///< RAN statuses received
  std::uint64_t topology_events = 0;   ///< topology events received
};

/// Thread-safe. Must be destroyed before its Participant.
class FleetMonitor {
 public:
  /// Subscribes to drover/logical/order_progress, drover/ran/status and the topology
  /// events; `trace` (may be null) gets every RAN status and topology event.
  /// \return the monitor, or the DDS layer's errors.
  static Result<std::unique_ptr<FleetMonitor>> create(dds::Participant& participant, TraceWriter* trace);
  ~FleetMonitor();

  FleetFigures figures() const;

 private:
  explicit FleetMonitor(TraceWriter* trace) : trace_(trace) {}
  void on_status(const msg::RanStatus& status);
  void on_progress(const msg::OrderProgress& progress);
  void on_topology_event(const msg::TopologyEvent& event);

  TraceWriter* trace_;
  mutable std::mutex mutex_;
  OrderTally orders_;
  std::map<std::string, bool> moving_;  ///< per vehicle, from its latest status
  std::uint64_t statuses_ = 0;
  std::uint64_t topology_events_ = 0;
  std::unique_ptr<dds::Reader<msg::RanStatus>> status_reader_;
  std::unique_ptr<dds::Reader<msg::OrderProgress>> progress_reader_;
  std::unique_ptr<dds::Reader<msg::TopologyEvent>> event_reader_;
};

}  // namespace drover::launcher
