#pragma once
// Loading a topology from a file whose format follows from its extension.

#include <filesystem>

#include "drover/common/result.hpp"
#include "drover/topology/model.hpp"
#include "drover/topology/movingai.hpp"
#include "drover/topology/topology_builder.hpp"

namespace drover::topology {

struct TopologyFileOptions {
  MovingAiOptions movingai;  ///< used for .map files
};

/// Loads `path` as JSON (".json", docs/topology-format.md) or as a MovingAI grid map
/// (".map"). \return the topology, or every problem found; any other extension is one
/// Diagnostic with an empty `where`.
Result<Topology, Diagnostics> load_topology_file(const std::filesystem::path& path,
                                                 const TopologyFileOptions& options = {});

}  // namespace drover::topology
