#pragma once
// The commands a robot agent node (RAN) receives from its logical agent. Plain C++ types:
// an integrator never sees DDS; the runner translates DDS samples into these.

#include <map>
#include <optional>
#include <string>

#include <boost/geometry/geometries/multi_polygon.hpp>

#include "drover/topology/geometry.hpp"

namespace drover::ran {

/// Identifies one command of one vehicle; chosen by the commander, unique per vehicle.
using CommandId = std::string;

/// A vehicle pose in the plant frame: metres and radians (theta counter-clockwise from +x).
struct Pose {
  double x = 0;
  double y = 0;
  double theta = 0;

  friend bool operator==(const Pose&, const Pose&) = default;
};

/// Where a move ends: a position and, when the vehicle must face a direction there, a
/// heading. Without a heading the vehicle keeps the direction it arrived in.
struct TargetPose {
  double x = 0;
  double y = 0;
  std::optional<double> theta;

  friend bool operator==(const TargetPose&, const TargetPose&) = default;
};

/// The area a vehicle may use while executing a move: the footprints of the topology
/// entities allocated to it (typically the vertex it stands on, the edge, and the target
/// vertex). A multi-polygon because those footprints need not form one polygon; its parts
/// MAY overlap (they are footprints as the topology defines them), so it is not a valid
/// OGC multi-polygon as given: normalized_area() (motion_area.hpp) merges the parts.
using MotionArea = boost::geometry::model::multi_polygon<topology::Polygon>;

/// Drive from where the previous move ends (or where the vehicle stands) along `edge` to
/// the vertex `target_vertex` at `target`, never faster than `max_speed` and never with any
/// part of the vehicle outside `area`.
struct MoveCommand {
  CommandId id;
  std::string target_vertex;  ///< topology vertex id
  TargetPose target;          ///< the vertex's position (and the heading required there)
  std::string edge;           ///< topology edge id; empty only for a turn on the spot
  double max_speed = 0;       ///< m/s, > 0; the vehicle also respects its own limit
  MotionArea area;            ///< non-empty

  friend bool operator==(const MoveCommand&, const MoveCommand&) = default;
};

enum class ActionKind { load, unload, charge, custom };

/// Stable lower-case names, as used on the wire and by tools.
const char* to_string(ActionKind kind) noexcept;
std::optional<ActionKind> action_kind_from_string(const std::string& name) noexcept;

/// Operate where the vehicle stands: load, unload, charge, or a vehicle-specific custom
/// operation named by `name`, with free string parameters.
struct ActionCommand {
  CommandId id;
  ActionKind kind = ActionKind::custom;
  std::string name;  ///< required for custom actions; optional label otherwise
  std::map<std::string, std::string> parameters;

  friend bool operator==(const ActionCommand&, const ActionCommand&) = default;
};

}  // namespace drover::ran
