#pragma once
// Every agent and tool is a subcommand of the one `drover` executable. Each subcommand
// registers itself on the CLI11 app and reports its exit code through CommandContext.

#include <cmath>
#include <sstream>
#include <string>

#include <CLI/CLI.hpp>

namespace drover::cli {

/// Exit codes shared by every Drover tool.
enum ExitCode : int {
  kExitOk = 0,
  kExitFailure = 1,     ///< the operation ran and failed
  kExitBadInput = 2,    ///< bad usage or invalid input
  kExitNoAnswer = 3,    ///< no agent answered
};

/// CLI11 checks of a number's sign with plain messages ("must be > 0, got 0"): CLI11's own
/// PositiveNumber and NonNegativeNumber name a range from 0 to 1.8e308 instead.
inline CLI::Validator sign_check(bool zero_allowed) {
  return CLI::Validator(
      [zero_allowed](std::string& input) -> std::string {
        double value = 0;
        if (!CLI::detail::lexical_cast(input, value)) return "'" + input + "' is not a number";
        const bool fine = zero_allowed ? value >= 0 : value > 0;
        return fine ? std::string() : std::string(zero_allowed ? "must be >= 0" : "must be > 0") +
                                          ", got " + input;
      },
      zero_allowed ? "NONNEGATIVE" : "POSITIVE");
}
/// The number must be > 0.
inline CLI::Validator positive() { return sign_check(false); }
/// The number must be >= 0.
inline CLI::Validator non_negative() { return sign_check(true); }

/// The number must lie in [low, high], and be whole when `whole`. Plain messages ("'abc' is
/// not a number", "must be a whole number, got 1.5", "must be from 1 to 100, got 0"):
/// CLI11's Range says "Value abc not in range 1 to 100" for all three, and lets NaN pass.
inline CLI::Validator range_check(double low, double high, bool whole) {
  const auto text = [](double value) {
    std::ostringstream out;
    out << value;
    return out.str();
  };
  return CLI::Validator(
      [=](std::string& input) -> std::string {
        double value = 0;
        if (!CLI::detail::lexical_cast(input, value)) return "'" + input + "' is not a number";
        if (whole && value != std::floor(value)) return "must be a whole number, got " + input;
        const bool fine = value >= low && value <= high;  // false for NaN
        return fine ? std::string()
                    : "must be from " + text(low) + " to " + text(high) + ", got " + input;
      },
      whole ? "INT in [" + text(low) + " - " + text(high) + "]"
            : "FLOAT in [" + text(low) + " - " + text(high) + "]");
}
/// A whole number in [low, high].
inline CLI::Validator whole_in(long long low, long long high) {
  return range_check(static_cast<double>(low), static_cast<double>(high), true);
}
/// A number in [low, high].
inline CLI::Validator number_in(double low, double high) { return range_check(low, high, false); }

/// Filled in by the subcommand that ran.
struct CommandContext {
  int exit_code = kExitOk;
};

/// Parses the command line into `app` and runs the chosen subcommand. Help and version
/// requests print and exit 0; a parse error prints CLI11's message and gives kExitBadInput;
/// an exception escaping a command (commands report expected failures themselves) prints
/// "error: internal: ..." and gives kExitFailure. Output that could not be written to
/// standard output prints "error: cannot write to standard output" and fails the run
/// (kExitFailure, unless the command had failed already). \return the exit code.
int run_app(CLI::App& app, const CommandContext& context, int argc, char** argv);

/// `drover topology ...` (validate and friends).
void add_topology_commands(CLI::App& app, CommandContext& context);

/// `drover topology-agent`: a topology agent process (agents/topology_agent/).
void add_topology_agent_command(CLI::App& app, CommandContext& context);

/// `drover routing-agent`: a routing agent process (agents/routing_agent/).
void add_routing_agent_command(CLI::App& app, CommandContext& context);

/// `drover logical-agent`: the logical agent of one vehicle (agents/logical_agent/).
void add_logical_agent_command(CLI::App& app, CommandContext& context);

/// `drover ran-sim ...`: a simulated vehicle as a RAN process (agents/ran_runner/cli/).
void add_ran_commands(CLI::App& app, CommandContext& context);

/// `drover launch FILE`: starts and supervises the agents of a launch file (agents/launcher/).
void add_launch_command(CLI::App& app, CommandContext& context);

/// `drover load-generator`: random orders between stations to idle vehicles (agents/launcher/).
void add_load_generator_command(CLI::App& app, CommandContext& context);

}  // namespace drover::cli
