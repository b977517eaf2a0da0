#pragma once
#include <CLI/CLI.hpp>

#include "agents/cli/command.hpp"

namespace drover::bench {

/// `drover bench ...`: the benchmarks (plan, and later rpc).
void add_bench_commands(CLI::App& app, cli::CommandContext& context);

}  // namespace drover::bench
