#pragma once
// The JSON topology format, documented in docs/topology-format.md: a loader that reports
// every problem with its JSON path, and a writer whose output loads back to an equal
// topology.

#include <filesystem>
#include <string>
#include <string_view>

#include "drover/common/result.hpp"
#include "drover/topology/model.hpp"
#include "drover/topology/topology_builder.hpp"

namespace drover::topology {

/// Loads a topology from a JSON file.
/// \return the topology, or every problem found: an unreadable or empty file (where ""),
///         malformed JSON or a NUL byte (where "line L, column C"), keys given twice, wrong
///         types, missing or unknown fields (where the JSON path, e.g. "vertices[2].x"), and
///         everything TopologyBuilder::build() rejects.
Result<Topology, Diagnostics> load_topology_json(const std::filesystem::path& path);

/// Same as load_topology_json, from the text of a document.
Result<Topology, Diagnostics> parse_topology_json(std::string_view text);

/// The topology as a JSON document (one entity per line). Generated footprints are left
/// out (the loader generates them again from the same footprint options); edge lengths are
/// always written. Guarantee: parse_topology_json(write_topology_json(t)) succeeds and
/// yields a topology equal to t in every field, conflict set and move.
std::string write_topology_json(const Topology& topology);

}  // namespace drover::topology
