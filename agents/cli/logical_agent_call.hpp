#pragma once
// One request to one vehicle's logical agent (a service of drover/logical/*), with the
// messages and exit codes every droverctl command that asks one prints and returns.

#include <iostream>
#include <optional>
#include <string>

#include "agents/cli/command.hpp"
#include "agents/cli/dds_tool_options.hpp"
#include "drover/dds/service_client.hpp"
#include "drover/dds/wire_error.hpp"

namespace drover::cli {

/// What one vehicle's logical agent answered.
template <class Reply>
struct LogicalAgentAnswer {
  std::optional<Reply> reply;  ///< present when the agent accepted the request
  int exit_code = kExitOk;     ///< kExitNoAnswer, kExitFailure or kExitOk
  std::string error;           ///< why not accepted, naming the vehicle; empty when accepted
};

/// Sends `request` through `client` to `vehicle`'s logical agent and waits for its answer.
/// Prints nothing (callers asking several agents at once print the answers in order).
/// `refused` says what the agent did not do when it refused ("refused order 'x'").
/// \return the reply when accepted; otherwise kExitNoAnswer when nobody answered in time,
///         kExitFailure when the agent refused or the call failed, with the reason.
template <class Request, class Reply>
LogicalAgentAnswer<Reply> ask_logical_agent(dds::ServiceClient<Request, Reply>& client, const DdsToolOptions& options,
                                            const std::string& vehicle, const Request& request,
                                            const std::string& refused) {
  auto reply = client.call(request, options.timeout(), vehicle);
  if (!reply) {
    return {std::nullopt, reply.error().code == ErrorCode::timeout ? kExitNoAnswer : kExitFailure,
            "vehicle '" + vehicle + "': " + reply.error().message};
  }
  if (auto status = dds::from_wire(reply->error()); !status) {
    return {std::nullopt, kExitFailure, "vehicle '" + vehicle + "' " + refused + ": " + status.error().message};
  }
  return {std::move(*reply), kExitOk, {}};
}

/// As ask_logical_agent, for one vehicle: \return its reply when the agent accepted the
/// request; otherwise nullopt, with the reason printed on standard error and `exit_code` set.
template <class Request, class Reply>
std::optional<Reply> call_logical_agent(dds::ServiceClient<Request, Reply>& client, const DdsToolOptions& options,
                                        const std::string& vehicle, const Request& request,
                                        const std::string& refused, int& exit_code) {
  auto answer = ask_logical_agent(client, options, vehicle, request, refused);
  if (!answer.reply) std::cerr << "error: " << answer.error << "\n";
  exit_code = answer.exit_code;
  return std::move(answer.reply);
}

}  // namespace drover::cli
