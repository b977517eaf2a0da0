#pragma once
#include <CLI/CLI.hpp>

#include "agents/cli/command.hpp"

namespace drover::bench {

/// `drover bench plan --map M.map --scen S.scen --agents N [--paths OUT.jsonl]`: plans the
/// first N tasks of a MovingAI scenario one after another as real CARP routes and compares
/// the time with a reservation-free A* on the same pairs (docs/benchmarks.md).
void add_bench_plan_command(CLI::App& bench, cli::CommandContext& context);

}  // namespace drover::bench
