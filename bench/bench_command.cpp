#include "bench/bench_command.hpp"

namespace drover::bench {

void add_bench_commands(CLI::App& app, cli::CommandContext& context) {
  auto* bench = app.add_subcommand("bench", "Run a benchmark and print its figures as JSON");
  bench->require_subcommand(1);
  (void)context;
}

}  // namespace drover::bench
