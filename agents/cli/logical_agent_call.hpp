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

/// Sends `request` through `client` to `vehicle`'s logical agent. \return its reply when the
/// agent accepted the request; otherwise nullopt, with the reason printed on standard error
/// and `exit_code` set: kExitNoAnswer when nobody answered in time, kExitFailure when the
/// agent refused (`refused` says what it did not do: "refused order 'x'") or the call failed.
template <class Request, class Reply>
std::optional<Reply> call_logical_agent(dds::ServiceClient<Request, Reply>& client, const DdsToolOptions& options,
                                        const std::string& vehicle, const Request& request,
                                        const std::string& refused, int& exit_code) {
  auto reply = client.call(request, options.timeout(), vehicle);
  if (!reply) {
    std::cerr << "error: vehicle '" << vehicle << "': " << reply.error().message << "\n";
    exit_code = reply.error().code == ErrorCode::timeout ? kExitNoAnswer : kExitFailure;
    return std::nullopt;
  }
  if (auto status = dds::from_wire(reply->error()); !status) {
    std::cerr << "error: vehicle '" << vehicle << "' " << refused << ": " << status.error().message << "\n";
    exit_code = kExitFailure;
    return std::nullopt;
  }
  exit_code = kExitOk;
  return std::move(*reply);
}

}  // namespace drover::cli
