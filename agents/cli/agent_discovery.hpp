#pragma once
// How droverctl learns which agents a domain has: from their heartbeats, within a discovery
// window (see discover_live_agents). Shared by `droverctl agents`, `vehicles`, `orders` and
// `pause --all`.

#include <chrono>
#include <functional>
#include <string>
#include <vector>

#include "drover/common/result.hpp"
#include "drover/dds/agent_directory.hpp"
#include "drover/dds/participant.hpp"

namespace drover::cli {

/// Listens to the heartbeats on `participant`'s domain until the listing is complete (every
/// remote participant present has shown its heartbeat, at least one agent is alive, and no
/// new agent appeared for a short while, at least one announcement period after the start)
/// and `also` holds for the records (when given; evaluated whenever the records change and
/// at least every 300 ms), or until `timeout`.
/// \return the live agents then (possibly none), or the directory's creation error.
Result<std::vector<dds::AgentRecord>> discover_live_agents(
    dds::Participant& participant, std::chrono::milliseconds timeout,
    const std::function<bool(const std::vector<dds::AgentRecord>&)>& also = {});

/// The vehicles of the live logical agents among `agents` (a logical agent's heartbeat names
/// the vehicle it owns), sorted, each once.
std::vector<std::string> live_logical_vehicles(const std::vector<dds::AgentRecord>& agents);

}  // namespace drover::cli
