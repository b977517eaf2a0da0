#pragma once
// What droverctl's topology commands (lock, unlock, timeline) share: shared-clock times
// given on the command line, and finding the topology agent that owns an entity.

#include <chrono>
#include <string>

#include "drover/common/clock.hpp"
#include "drover/common/result.hpp"
#include "drover/dds/agent_directory.hpp"
#include "drover/dds/participant.hpp"

namespace drover::cli {

/// A shared-clock time: "NS" (absolute, int64 ns), "now", "+D" (D after `now`) or "forever"
/// when allow_forever. D is a number with a unit: ns, us, ms, s, m, h (e.g. "+30s", "+1.5m").
/// \return the time, or invalid_argument naming `text` and the accepted forms.
Result<TimeNs> parse_time(const std::string& text, TimeNs now, bool allow_forever);

/// The live topology agent that owns `entity`, learnt from its entity description and the
/// heartbeats, waiting at most `timeout`.
/// \return the agent's record (its id and the shared-clock time of its last heartbeat), or
///         unavailable when no topology agent is alive on the domain, or not_found when
///         topology agents are alive but none describes `entity`.
Result<dds::AgentRecord> find_owner(dds::Participant& participant, const std::string& entity,
                                    std::chrono::milliseconds timeout);

/// Any live topology agent (for its clock), waiting at most `timeout`; unavailable if none.
Result<dds::AgentRecord> any_topology_agent(dds::Participant& participant, std::chrono::milliseconds timeout);

/// The exit code of a failure to reach the agents: kExitNoAnswer for unavailable or timeout,
/// kExitBadInput for not_found or invalid_argument, kExitFailure otherwise.
int exit_code_of(const Error& error);

}  // namespace drover::cli
