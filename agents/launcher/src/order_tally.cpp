#include "drover/launcher/order_tally.hpp"

namespace drover::launcher {

void OrderTally::update(const std::string& vehicle, const std::string& order, OrderOutcome outcome,
                        std::optional<TimeNs> created, std::optional<TimeNs> finished) {
  Entry& entry = orders_[{vehicle, order}];
  if (entry.outcome != OrderOutcome::open) return;
  entry.outcome = outcome;
  if (outcome == OrderOutcome::finished && created && finished) entry.lead_time = *finished - *created;
}

OrderFigures OrderTally::figures() const {
  OrderFigures figures;
  DurationNs lead_time_sum = 0;
  std::uint64_t timed = 0;
  for (const auto& [key, entry] : orders_) {
    switch (entry.outcome) {
      case OrderOutcome::open: ++figures.open; break;
      case OrderOutcome::failed: ++figures.failed; break;
      case OrderOutcome::withdrawn: ++figures.withdrawn; break;
      case OrderOutcome::finished:
        ++figures.finished;
        if (entry.lead_time) {
          lead_time_sum += *entry.lead_time;
          ++timed;
        }
        break;
    }
  }
  if (timed > 0) figures.mean_lead_time_s = ns_to_seconds(lead_time_sum) / static_cast<double>(timed);
  return figures;
}

}  // namespace drover::launcher
