#pragma once
// Whether the RAN still knows a command it accepted.

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>

#include "drover/ran/status.hpp"

namespace drover::logical_agent {

/// Follows one command the RAN accepted through the RAN's statuses. The RAN contract
/// (docs/ran-sdk.md, "The status") is that every status lists a command from its acceptance
/// until a while after it ended, so the logical agent sees each end. A RAN that breaks it —
/// one that restarted, or a driver that dropped a command without ending it — would leave
/// the agent waiting for an end that never comes, the vehicle standing "driving" for ever.
/// Not thread-safe (the executor's).
class CommandWatch {
 public:
  using Clock = std::chrono::steady_clock;

  /// How the RAN lost the command.
  enum class Loss {
    none,          ///< listed, or not yet due to be
    restarted,     ///< listed once, then missing from a status whose sequence went back
                   ///< (a RAN that started again counts from 1)
    dropped,       ///< listed once, then missing from a later status, its end never reported
    never_listed,  ///< missing from every status received `grace` and more after acceptance
  };

  /// \param accepted  when the RAN's reply accepted the command (real time).
  /// \param grace     how long after that a status may still not list it (the status and
  ///                  the reply travel separately).
  CommandWatch(Clock::time_point accepted, Clock::duration grace) : accepted_(accepted), grace_(grace) {}

  /// Takes `status`, received at `received`, into account (a status seen before changes
  /// nothing). \pre the command's end has not been seen in any status: an ended command
  /// may leave the list. \return how the RAN lost the command, if it did.
  Loss observe(const ran::VehicleStatus& status, const ran::CommandId& command, Clock::time_point received);

 private:
  Clock::time_point accepted_;
  Clock::duration grace_;
  std::optional<std::uint64_t> listed_in_;  ///< sequence of the latest status that listed it
};

/// What happened to the command, for a failure text that begins with what it was ("the move
/// to 'x' " + loss_text(...)). \pre `loss` is not Loss::none.
std::string loss_text(CommandWatch::Loss loss);

}  // namespace drover::logical_agent
