#include "bench/bench_command.hpp"

#include "bench/bench_plan.hpp"
#include "bench/bench_rpc.hpp"

namespace drover::bench {

void add_bench_commands(CLI::App& app, cli::CommandContext& context) {
  auto* bench = app.add_subcommand("bench", "Run a benchmark and print its figures as JSON");
  bench->require_subcommand(1);
  add_bench_plan_command(*bench, context);
  add_bench_rpc_command(*bench, context);
}

}  // namespace drover::bench
