#pragma once
// Counts the orders of a run from their progress (drover/logical/order_progress): how many
// finished, failed and were withdrawn, and their mean lead time (finished - created on the
// shared clock).

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <utility>

#include "drover/common/clock.hpp"

namespace drover::launcher {

enum class OrderOutcome { open, finished, failed, withdrawn };

struct OrderFigures {
  std::uint64_t open = 0;
  std::uint64_t finished = 0;
  std::uint64_t failed = 0;
  std::uint64_t withdrawn = 0;
  /// Mean of finished - created over the finished orders that carry both times.
  std::optional<double> mean_lead_time_s;
};

/// Not thread-safe; the monitor guards it.
class OrderTally {
 public:
  /// Records the latest progress of `vehicle`'s `order` (names are unique per vehicle). An
  /// order that ended stays ended (a late duplicate of an earlier state does not reopen it).
  void update(const std::string& vehicle, const std::string& order, OrderOutcome outcome,
              std::optional<TimeNs> created, std::optional<TimeNs> finished);
  OrderFigures figures() const;

 private:
  struct Entry {
    OrderOutcome outcome = OrderOutcome::open;
    std::optional<DurationNs> lead_time;
  };
  std::map<std::pair<std::string, std::string>, Entry> orders_;  ///< by (vehicle, order)
};

}  // namespace drover::launcher
