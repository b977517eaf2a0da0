#pragma once
// Conversions between the SDK's plain C++ types (drover/ran/commands.hpp, status.hpp) and
// the DDS messages of idl/ran.idl. Converting to the wire cannot fail; converting from it
// fails on what a well-behaved peer never sends (unknown enum names).

#include "drover/common/result.hpp"
#include "drover/ran/commands.hpp"
#include "drover/ran/status.hpp"
#include "ran.h"

namespace drover::ran {

msg::RanMove to_wire(const MoveCommand& command);
MoveCommand from_wire(const msg::RanMove& move);

msg::RanAction to_wire(const ActionCommand& command);
/// \return the action, or invalid_argument for an unknown action kind.
Result<ActionCommand> from_wire(const msg::RanAction& action);

msg::RanStatus to_wire(const VehicleStatus& status);
/// \return the status, or invalid_argument naming an unknown command state, error level or
///         load state.
Result<VehicleStatus> from_wire(const msg::RanStatus& status);

}  // namespace drover::ran
