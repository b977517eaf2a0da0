// `drover topology validate FILE`: loads a topology file (.json or .map), prints a one-line
// summary and exits 0, or prints one `error: FILE:WHERE: WHAT` line per problem and exits 2.

#include <exception>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include "agents/cli/command.hpp"
#include "drover/topology/topology_file.hpp"

namespace drover::cli {

namespace {

/// Enough lines to find every problem of a damaged file without flooding the terminal.
constexpr std::size_t kMaxReportedProblems = 100;

struct ValidateArguments {
  std::string file;
  std::optional<double> cell_size;
};

std::string join(const std::vector<std::string>& names) {
  std::string joined;
  for (const auto& name : names) joined += (joined.empty() ? "" : ", ") + name;
  return joined;
}

int validate(const ValidateArguments& arguments) {
  const std::filesystem::path path(arguments.file);
  if (arguments.cell_size && path.extension() != ".map") {
    std::cerr << "error: " << arguments.file << ": --cell-size applies to .map files only\n";
    return kExitBadInput;
  }
  topology::TopologyFileOptions options;
  if (arguments.cell_size) options.movingai.cell_size = *arguments.cell_size;

  const auto loaded = topology::load_topology_file(path, options);
  if (!loaded) {
    const auto& problems = loaded.error();
    for (std::size_t i = 0; i < problems.size() && i < kMaxReportedProblems; ++i) {
      std::cerr << "error: " << topology::diagnostic_text(arguments.file, problems[i]) << "\n";
    }
    if (problems.size() > kMaxReportedProblems) {
      std::cerr << "error: " << arguments.file << ": " << problems.size() - kMaxReportedProblems
                << " more problems not shown\n";
    }
    return kExitBadInput;
  }
  const auto& topology = *loaded;
  std::cout << arguments.file << ": " << topology.vertex_count() << " vertices, "
            << topology.edge_count() << " edges, " << topology.conflict_pair_count()
            << " conflict pairs, partitions: " << join(topology.partitions()) << "\n";
  return kExitOk;
}

}  // namespace

void add_topology_commands(CLI::App& app, CommandContext& context) {
  auto* topology = app.add_subcommand("topology", "Work with topology files");
  topology->require_subcommand(1);

  auto arguments = std::make_shared<ValidateArguments>();
  auto* validate_command = topology->add_subcommand(
      "validate",
      "Load a topology file (.json: Drover format, .map: MovingAI grid map), check it and "
      "print a one-line summary; exit 2 with one line per problem if it is invalid");
  validate_command->add_option("FILE", arguments->file, "The topology file")->required()->check(cli::non_empty());
  validate_command
      ->add_option("--cell-size", arguments->cell_size,
                   "Side of a grid cell in metres, 0.01 to 1000 (.map files; default 1)")
      ->transform(cli::number_in(0.01, 1000.0));
  validate_command->callback([arguments, &context] {
    try {
      context.exit_code = validate(*arguments);
    } catch (const std::exception& e) {
      // The loaders return errors as values; this only guards against a bug or exhaustion.
      std::cerr << "error: " << arguments->file << ": internal error: " << e.what() << "\n";
      context.exit_code = kExitFailure;
    }
  });
}

}  // namespace drover::cli
