// SPDX-License-Identifier: BSD-3-Clause
// Scripted geometry and motions of the synthetic scenarios (private to dynvo_synth).
#pragma once

#include <Eigen/Geometry>

#include <string>
#include <utility>
#include <vector>

namespace dynvo::detail {

/// amplitude * sin(omega * s + phase); amplitude in metres or radians, omega in rad/s.
struct SineTerm {
  Eigen::Vector3d amplitude;
  double omega;
  double phase;
};

/// A point the path passes through at progress s.
struct Waypoint {
  double s;                 ///< seconds of motion
  Eigen::Vector3d position; ///< metres, added to the centre
};

/** \brief Smooth rigid motion as a function of the progress s (seconds of motion).
 *
 * With r = s modulo repeat (r = s when repeat is 0):
 * rotation(r) = base_rotation * Ry(spin_rate r) * exp([sum of rotation terms]x);
 * translation(r) = centre + waypoint spline + velocity r + acceleration r^2 / 2 + sum
 * of translation terms, minus orbit_radius times the optical (z) axis of rotation(r)
 * (a camera circling `centre` while looking at it). The waypoint spline is a cubic
 * Hermite through the waypoints (Catmull-Rom tangents, zero at the ends), held at the
 * first and last position outside them.
 */
struct RigidPath {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();            ///< metres
  Eigen::Matrix3d base_rotation = Eigen::Matrix3d::Identity(); ///< at s = 0
  std::vector<SineTerm> translation;                           ///< metres
  std::vector<SineTerm> rotation;                         ///< rotation vector (rad)
  double spin_rate = 0.0;                                 ///< about local y (rad/s)
  std::vector<Waypoint> waypoints;                        ///< increasing s
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();     ///< m/s
  Eigen::Vector3d acceleration = Eigen::Vector3d::Zero(); ///< m/s^2
  double orbit_radius = 0.0;                              ///< metres (0: no orbit)
  double repeat = 0.0; ///< seconds of motion after which the path restarts

  Eigen::Isometry3d pose(double s) const;
};

/** \brief Maps time to motion progress. Without windows the object always moves
 * (progress = t). Otherwise it moves only inside the windows (repeated every period),
 * with raised-cosine speed ramps of length `ramp` at both ends of each window, and
 * rests between them. Window lengths and the ramp are multiples of 0.25 s, so the
 * progress of a rest is an exactly representable constant and "did the pose change"
 * can be decided by comparing progress values exactly.
 */
struct MotionSchedule {
  double period = 0.0;                            ///< seconds
  std::vector<std::pair<double, double>> windows; ///< [start, end] in [0, period] (s)
  double ramp = 0.25;                             ///< seconds

  double progress(double t) const;
};

/// One scripted box; id is its label value.
struct ScriptedBox {
  int id;
  Eigen::Vector3d half_extents; ///< metres
  RigidPath path;
  MotionSchedule schedule;
};

/// A static axis-aligned box of the room (furniture).
struct StaticBox {
  Eigen::Vector3d centre;       ///< metres, world
  Eigen::Vector3d half_extents; ///< metres
  bool dark = false;            ///< dark, shiny material (almost no depth return)
};

/// The room shared by every scenario.
struct Room {
  Eigen::Vector3d min_corner; ///< metres, world
  Eigen::Vector3d max_corner; ///< metres, world
  std::vector<StaticBox> furniture;
};

struct Scenario {
  std::string name;
  std::string description;
  RigidPath camera; ///< T_world_camera as a function of time (progress = t)
  std::vector<ScriptedBox> objects;
  double exposure = 0.0; ///< colour exposure (s) averaged into motion blur; 0 = sharp
  /// Progress of the camera's path over time (no windows: always moving)
  MotionSchedule camera_schedule;
};

/// The room (same for every scenario).
const Room& room();

/// Every scenario, in the fixed public order.
const std::vector<Scenario>& allScenarios();

} // namespace dynvo::detail
