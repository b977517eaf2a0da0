#include "drover/topology/topology_file.hpp"

#include "drover/topology/json_format.hpp"

namespace drover::topology {

Result<Topology, Diagnostics> load_topology_file(const std::filesystem::path& path,
                                                 const TopologyFileOptions& options) {
  const auto extension = path.extension();
  if (extension == ".json") return load_topology_json(path);
  if (extension == ".map") return load_movingai_map(path, options.movingai);
  return unexpected(Diagnostics{
      Diagnostic{"", "unknown format: the file name must end in .json (Drover topology) or "
                     ".map (MovingAI grid map)"}});
}

}  // namespace drover::topology
