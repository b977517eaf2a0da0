#pragma once
// What droverctl's topology commands (lock, unlock, timeline, release) share: shared-clock
// times given on the command line, finding the topology agent that owns an entity, and
// calling it.

#include <chrono>
#include <iostream>
#include <optional>
#include <string>

#include "drover/common/clock.hpp"
#include "drover/common/result.hpp"
#include "drover/dds/agent_directory.hpp"
#include "drover/dds/participant.hpp"
#include "drover/dds/service_client.hpp"
#include "agents/cli/command.hpp"
#include "common.h"

namespace drover::cli {

/// A shared-clock time: "NS" (absolute, int64 ns), "now", "+D" (D after `now`) or "forever"
/// when allow_forever. D is a number with a unit: ns, us, ms, s, m, h (e.g. "+30s", "+1.5m").
/// \return the time, or invalid_argument naming `text` and the accepted forms, or the
///         clock's range [0, kLatestTime] for a time beyond it.
Result<TimeNs> parse_time(const std::string& text, TimeNs now, bool allow_forever);

/// Whether parse_time reads `text` relative to `now` ("now", "+D").
bool relative_time(const std::string& text);

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

/// Calls topology agent `agent` with `request`. \return its reply when it answered without
/// error; otherwise nullopt, with "error: topology agent 'ID': ..." printed and `exit_code`
/// set: kExitNoAnswer when it did not answer, kExitFailure when it refused.
template <class Req, class Rep>
std::optional<Rep> call_topology_agent(dds::ServiceClient<Req, Rep>& client, const Req& request,
                                       std::chrono::milliseconds timeout, const std::string& agent, int& exit_code) {
  auto reply = client.call(request, timeout, agent);
  if (!reply) {
    std::cerr << "error: topology agent '" << agent << "': " << reply.error().message << "\n";
    exit_code = kExitNoAnswer;
    return std::nullopt;
  }
  if (reply->error().code() != msg::ERROR_NONE) {
    std::cerr << "error: topology agent '" << agent << "' refused: " << reply->error().message() << "\n";
    exit_code = kExitFailure;
    return std::nullopt;
  }
  return std::move(*reply);
}

}  // namespace drover::cli
