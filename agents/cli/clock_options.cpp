#include "agents/cli/clock_options.hpp"

#include "agents/cli/number_checks.hpp"

namespace drover::cli {

void add_clock_options(CLI::App& command, ClockArguments& arguments) {
  command.add_option("--time-factor", arguments.time_factor,
                     "Shared-clock seconds per real second, at most 1000 (default 1)")
      ->transform(positive_at_most(kMaxTimeFactor));
  command.add_option("--epoch,--epoch-ns", arguments.epoch_ns,
                     "Shared-clock time at the clock origin, ns (default: the Unix time then)")
      ->transform(exact_whole_in(0, kLatestTime));
  command.add_option("--clock-origin", arguments.origin_unix_ns,
                     "Unix time, ns, at which the clock read --epoch (default: this process's "
                     "start); the launcher gives every agent the same one")
      ->transform(exact_whole_in(0, kLatestTime));
}

Result<SharedClock> make_clock(const ClockArguments& arguments) {
  if (!arguments.epoch_ns && !arguments.origin_unix_ns && arguments.time_factor == 1.0) {
    return SharedClock::wall();
  }
  const TimeNs origin = arguments.origin_unix_ns.value_or(SharedClock::unix_now());
  auto clock = SharedClock::create_at_origin(arguments.epoch_ns.value_or(origin),
                                             arguments.time_factor, origin);
  if (!clock) return fail(ErrorCode::invalid_argument, "clock: " + clock.error().message);
  return clock;
}

}  // namespace drover::cli
