// The launcher's order figures (the progress line and the summary of `drover launch`).

#include <gtest/gtest.h>

#include "drover/launcher/order_tally.hpp"

namespace drover::launcher {
namespace {

TEST(OrderTally, CountsEachOrderByHowItEndedAndKeepsItEnded) {
  OrderTally tally;
  tally.update("V1", "a", OrderOutcome::open, 0, std::nullopt);
  tally.update("V1", "a", OrderOutcome::finished, 0, seconds_to_ns(40));
  tally.update("V1", "b", OrderOutcome::failed, 0, seconds_to_ns(10));
  tally.update("V1", "c", OrderOutcome::withdrawn, seconds_to_ns(5), seconds_to_ns(6));
  tally.update("V1", "d", OrderOutcome::open, 0, std::nullopt);
  tally.update("V1", "e", OrderOutcome::finished, seconds_to_ns(10), seconds_to_ns(30));
  // A late duplicate of an earlier state does not reopen an order.
  tally.update("V1", "c", OrderOutcome::open, seconds_to_ns(5), std::nullopt);
  // Names are unique per vehicle: V2's "a" is another order.
  tally.update("V2", "a", OrderOutcome::open, 0, std::nullopt);

  const OrderFigures figures = tally.figures();
  EXPECT_EQ(figures.open, 2u);
  EXPECT_EQ(figures.finished, 2u);
  EXPECT_EQ(figures.failed, 1u);
  EXPECT_EQ(figures.withdrawn, 1u);
  ASSERT_TRUE(figures.mean_lead_time_s.has_value());
  EXPECT_DOUBLE_EQ(*figures.mean_lead_time_s, 30.0) << "only finished orders have a lead time";
}

}  // namespace
}  // namespace drover::launcher
