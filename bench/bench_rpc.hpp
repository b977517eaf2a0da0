#pragma once
#include <CLI/CLI.hpp>

#include "agents/cli/command.hpp"

namespace drover::bench {

/// `drover bench rpc`: request/reply round trips over the DDS service layer between two
/// processes against a raw Fast DDS ping-pong of the same payload, in the same run
/// (docs/benchmarks.md "Request/reply"). Also registers the hidden `rpc-server` role it
/// starts as a child process.
void add_bench_rpc_command(CLI::App& bench, cli::CommandContext& context);

}  // namespace drover::bench
