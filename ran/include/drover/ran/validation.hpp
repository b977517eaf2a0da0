#pragma once
// Checks a driver runs on every command before it accepts it. A failed check yields a
// Rejection: the code goes into CommandProgress::code, the reason into ::reason.

#include <string>

#include "drover/common/result.hpp"
#include "drover/ran/commands.hpp"
#include "drover/topology/model.hpp"

namespace drover::ran {

/// Why a command was refused: a stable machine-readable code and a reason for people that
/// names the offending field and value.
struct Rejection {
  std::string code;
  std::string reason;

  friend bool operator==(const Rejection&, const Rejection&) = default;
};

/// The rejection codes Drover's own drivers use (integrators may add their own).
namespace rejection_code {
inline constexpr const char* kMalformed = "malformed";            ///< missing or non-finite field
inline constexpr const char* kInvalidSpeed = "invalid_speed";     ///< max speed <= 0 or not finite
inline constexpr const char* kDuplicateId = "duplicate_id";       ///< id already used
inline constexpr const char* kUnknownVertex = "unknown_vertex";
inline constexpr const char* kUnknownEdge = "unknown_edge";
inline constexpr const char* kEdgeMismatch = "edge_mismatch";     ///< edge does not lead there
inline constexpr const char* kOutsideArea = "outside_area";       ///< would leave its area
inline constexpr const char* kUnsupportedAction = "unsupported_action";
inline constexpr const char* kInvalidParameter = "invalid_parameter";
inline constexpr const char* kNotReady = "not_ready";             ///< fatal error, empty battery
inline constexpr const char* kUnknownCommand = "unknown_command"; ///< cancel of an unknown id
}  // namespace rejection_code

using CommandCheck = Result<void, Rejection>;

/// Well-formedness of a move on its own: non-empty id and target vertex, finite target,
/// finite positive max speed, a non-empty motion area whose parts have at least 3 corners
/// and finite coordinates.
CommandCheck validate(const MoveCommand& command);

/// Well-formedness of an action on its own: non-empty id; a custom action has a name.
/// (Whether the vehicle supports it is the driver's decision.)
CommandCheck validate(const ActionCommand& command);

/// A move checked against the topology the commander plans on:
///  - the target vertex exists and `command.target` lies within `position_tolerance` metres
///    of its position;
///  - a non-empty edge exists, ends at the target vertex and may be driven towards it, and
///    `start` (where the move begins) lies on it within `position_tolerance` (normally at
///    its other end, or part-way along it when an earlier move was cancelled or paused
///    there) or inside the footprint of its other end (a vehicle that braked to a stop a
///    little past that vertex, onto another edge); the command's max speed does not exceed
///    the edge's;
///  - an empty edge means a turn on the spot: `start` must be at the target vertex.
/// \param start  where the vehicle is when the move begins (the end of the previous move).
CommandCheck check_against_topology(const MoveCommand& command, const topology::Topology& topology,
                                    const Pose& start, double position_tolerance);

}  // namespace drover::ran
