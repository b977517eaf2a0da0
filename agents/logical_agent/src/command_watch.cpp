#include "agents/logical_agent/src/command_watch.hpp"

namespace drover::logical_agent {

CommandWatch::Loss CommandWatch::observe(const ran::VehicleStatus& status, const ran::CommandId& command,
                                         Clock::time_point received) {
  if (status.find_command(command) != nullptr) {
    listed_in_ = status.sequence;
    return Loss::none;
  }
  if (!listed_in_) return received - accepted_ > grace_ ? Loss::never_listed : Loss::none;
  if (status.sequence < *listed_in_) return Loss::restarted;
  return status.sequence > *listed_in_ ? Loss::dropped : Loss::none;
}

std::string loss_text(CommandWatch::Loss loss) {
  switch (loss) {
    case CommandWatch::Loss::restarted:
      return "is no longer reported by the RAN, which restarted";
    case CommandWatch::Loss::dropped:
      return "is no longer reported by the RAN, which never reported its end (a RAN lists a command until it "
             "ends, and for a while after)";
    case CommandWatch::Loss::never_listed:
      return "was accepted by the RAN but never appeared in its statuses";
    case CommandWatch::Loss::none:
      break;
  }
  return "is reported by the RAN";
}

}  // namespace drover::logical_agent
