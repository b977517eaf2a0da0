#pragma once
// The shared-clock options every agent takes (shared/DESIGN.md "Time"): --time-factor,
// --epoch and --clock-origin. The launcher passes the same three values to every agent it
// starts, so their clocks agree however late each process comes up.

#include <optional>

#include <CLI/CLI.hpp>

#include "drover/common/clock.hpp"
#include "drover/common/result.hpp"

namespace drover::cli {

struct ClockArguments {
  double time_factor = 1.0;
  /// Shared-clock time at the origin; default: the Unix time at the origin.
  std::optional<TimeNs> epoch_ns;
  /// Unix time (ns) at which the clock read the epoch; default: when the clock is made.
  std::optional<TimeNs> origin_unix_ns;
};

/// Adds --time-factor F, --epoch NS (also spelt --epoch-ns) and --clock-origin NS to
/// `command`, filling `arguments`.
void add_clock_options(CLI::App& command, ClockArguments& arguments);

/// The clock the options describe: the wall clock when none was given.
/// \return the clock, or invalid_argument naming --time-factor when it is not positive.
Result<SharedClock> make_clock(const ClockArguments& arguments);

}  // namespace drover::cli
