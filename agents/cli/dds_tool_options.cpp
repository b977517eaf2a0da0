#include "agents/cli/dds_tool_options.hpp"

#include <unistd.h>

#include "agents/cli/command.hpp"

namespace drover::cli {

void add_dds_tool_options(CLI::App& command, DdsToolOptions& options, double default_timeout_seconds) {
  options.timeout_seconds = default_timeout_seconds;
  command.add_option("--domain", options.domain_id, "DDS domain id of the agents (default 0)")
      ->transform(cli::whole_in(0, 232));
  if (default_timeout_seconds > 0) {
    command.add_option("--timeout", options.timeout_seconds, "Seconds to wait for agents to answer")
        ->transform(cli::positive())
        ->capture_default_str();
  }
  command.add_option("--xml-profile", options.xml_profile, "Fast DDS XML profiles file (transports, security)")
      ->check(CLI::ExistingFile);
}

Result<std::unique_ptr<dds::Participant>> open_tool_participant(const DdsToolOptions& options) {
  dds::ParticipantOptions participant;
  participant.domain_id = options.domain_id;
  participant.agent_id = "droverctl-" + std::to_string(::getpid());
  participant.xml_profile_file = options.xml_profile;
  return dds::Participant::create(participant);
}

}  // namespace drover::cli
