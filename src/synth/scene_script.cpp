// SPDX-License-Identifier: BSD-3-Clause
#include "scene_script.h"

#include <cmath>

namespace dynvo::detail {

namespace {

constexpr double PI = 3.14159265358979323846;
constexpr double HALF_PI = 0.5 * PI;

Eigen::Matrix3d
expRotation(const Eigen::Vector3d& rotation_vector)
{
  const double angle = rotation_vector.norm();
  if (angle == 0.0)
    return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, rotation_vector / angle).toRotationMatrix();
}

/// Camera looking 0.2 rad (11.5 deg) below the horizon from the room's origin.
Eigen::Matrix3d
cameraBaseRotation()
{
  return Eigen::AngleAxisd(-0.2, Eigen::Vector3d::UnitX()).toRotationMatrix();
}

/// Fixed camera (static-camera scenarios).
RigidPath
staticCamera()
{
  RigidPath path;
  path.base_rotation = cameraBaseRotation();
  return path;
}

/** Hand-held-like camera; `scale` 1 gives up to about 0.25 m/s and 4 deg/s. */
RigidPath
movingCamera(double scale)
{
  RigidPath path = staticCamera();
  path.translation = {{scale * Eigen::Vector3d(0.35, 0.0, 0.0), 0.45, 0.0},
                      {scale * Eigen::Vector3d(0.06, 0.0, 0.0), 1.1, 1.0},
                      {scale * Eigen::Vector3d(0.0, 0.08, 0.0), 0.6, 0.4},
                      {scale * Eigen::Vector3d(0.0, 0.0, 0.3), 0.35, 0.8}};
  path.rotation = {{scale * Eigen::Vector3d(0.0, 0.15, 0.0), 0.4, 0.3},
                   {scale * Eigen::Vector3d(0.06, 0.0, 0.0), 0.55, 1.2},
                   {scale * Eigen::Vector3d(0.0, 0.0, 0.03), 0.7, 0.0}};
  return path;
}

/// Elliptic path: first_axis sin(w s + phase) + second_axis cos(w s + phase).
std::vector<SineTerm>
ellipse(const Eigen::Vector3d& first_axis,
        const Eigen::Vector3d& second_axis,
        double omega,
        double phase)
{
  return {{first_axis, omega, phase}, {second_axis, omega, phase + HALF_PI}};
}

/// A box tumbling gently while it travels on an ellipse around `centre`.
ScriptedBox
ellipticBox(int id,
            const Eigen::Vector3d& half_extents,
            const Eigen::Vector3d& centre,
            const std::vector<SineTerm>& translation,
            double spin_rate)
{
  ScriptedBox box{id, half_extents, {}, {}};
  box.path.centre = centre;
  box.path.translation = translation;
  box.path.rotation = {{Eigen::Vector3d(0.15, 0.0, 0.0), 0.9, 0.0},
                       {Eigen::Vector3d(0.0, 0.0, 0.12), 0.7, 1.0}};
  box.path.spin_rate = spin_rate;
  return box;
}

std::vector<Scenario>
makeScenarios()
{
  using V = Eigen::Vector3d;
  std::vector<Scenario> scenarios;

  scenarios.push_back(
      {"static_one",
       "static camera, one box circling in the room",
       staticCamera(),
       {ellipticBox(1, V(0.25, 0.25, 0.25), V(0.0, 0.3, 1.4),
                    ellipse(V(0.6, 0.0, 0.0), V(0.0, 0.0, 0.3), 0.7, 0.0), 0.6)}});
  scenarios.back().objects[0].path.translation.push_back({V(0.0, 0.1, 0.0), 1.3, 0.0});

  scenarios.push_back(
      {"static_two",
       "static camera, two boxes moving independently",
       staticCamera(),
       {ellipticBox(1, V(0.22, 0.22, 0.22), V(-0.3, 0.3, 1.4),
                    ellipse(V(0.4, 0.0, 0.0), V(0.0, 0.0, 0.25), 1.0, 0.0), 0.7),
        ellipticBox(2, V(0.3, 0.15, 0.2), V(0.3, 0.0, 1.6),
                    ellipse(V(0.4, 0.0, 0.0), V(0.0, 0.3, 0.0), 1.1, 1.0), 0.0)}});

  scenarios.push_back(
      {"moving_crossing",
       "moving camera, a box entering from the left and crossing back and forth",
       movingCamera(1.0),
       {ellipticBox(1, V(0.3, 0.3, 0.3), V(0.0, 0.0, 1.35),
                    ellipse(V(1.2, 0.0, 0.0), V(0.0, 0.0, 0.2), 0.55, -HALF_PI),
                    0.5)}});

  // The box travels along the mean optical axis from 2.0 m to 0.9 m and back, every 10.5 s.
  // At its nearest it covers about 80 % of the image, and its front face comes to about
  // 0.5 m, where the sensor loses it for some 20 frames; the background around it stays
  // measured in every frame, so the camera's motion is always observable.
  ScriptedBox occluder{1, V(0.35, 0.35, 0.35), {}, {}};
  occluder.path.base_rotation = cameraBaseRotation();
  occluder.path.centre = cameraBaseRotation() * V(0.05, 0.0, 1.45);
  occluder.path.translation = {
      {cameraBaseRotation() * V(0.0, 0.0, 0.55), 0.6, HALF_PI}};
  occluder.path.rotation = {{V(0.1, 0.0, 0.0), 0.8, 0.0},
                            {V(0.0, 0.15, 0.0), 0.5, 0.3}};
  scenarios.push_back(
      {"moving_occluder",
       "moving camera, a box approaching until it covers most of the image",
       movingCamera(0.5),
       {occluder}});

  ScriptedBox first =
      ellipticBox(1, V(0.25, 0.25, 0.25), V(-0.45, 0.35, 1.3),
                  ellipse(V(0.25, 0.0, 0.0), V(0.0, 0.0, 0.2), 1.2, 0.0), 0.5);
  first.schedule = {10.0, {{2.0, 4.0}, {6.5, 8.5}}, 0.25};
  ScriptedBox second =
      ellipticBox(2, V(0.2, 0.3, 0.2), V(0.45, 0.1, 1.6),
                  ellipse(V(0.25, 0.0, 0.0), V(0.0, -0.25, 0.0), 1.3, 0.0), 0.4);
  second.schedule = {10.0, {{0.5, 2.5}, {5.0, 6.5}}, 0.25};
  scenarios.push_back({"stop_and_go",
                       "moving camera, two boxes resting for stretches, then moved",
                       movingCamera(0.6),
                       {first, second}});

  scenarios.push_back({"moving_static",
                       "moving camera in a static room (no moving object)",
                       movingCamera(1.0),
                       {}});
  return scenarios;
}

/// Integral of the window's speed profile from its start to x (seconds of motion).
double
windowProgress(double x, double length, double ramp)
{
  const auto ramp_up = [ramp](double y) {
    return 0.5 * (y - ramp / PI * std::sin(PI * y / ramp));
  };
  if (x <= 0.0)
    return 0.0;
  if (x >= length)
    return length - ramp;
  if (x < ramp)
    return ramp_up(x);
  if (x > length - ramp)
    return length - ramp - ramp_up(length - x);
  return 0.5 * ramp + (x - ramp);
}

} // namespace

Eigen::Isometry3d
RigidPath::pose(double s) const
{
  Eigen::Vector3d translation_now = centre;
  for (const SineTerm& term : translation)
    translation_now += term.amplitude * std::sin(term.omega * s + term.phase);
  Eigen::Vector3d rotation_vector = Eigen::Vector3d::Zero();
  for (const SineTerm& term : rotation)
    rotation_vector += term.amplitude * std::sin(term.omega * s + term.phase);
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() =
      base_rotation *
      Eigen::AngleAxisd(spin_rate * s, Eigen::Vector3d::UnitY()).toRotationMatrix() *
      expRotation(rotation_vector);
  pose.translation() = translation_now;
  return pose;
}

double
MotionSchedule::progress(double t) const
{
  if (windows.empty())
    return t;
  double per_period = 0.0;
  for (const auto& window : windows)
    per_period += window.second - window.first - ramp;
  const double periods = std::floor(t / period);
  const double tau = t - periods * period;
  double progress = periods * per_period;
  for (const auto& [start, end] : windows)
    progress += windowProgress(tau - start, end - start, ramp);
  return progress;
}

const Room&
room()
{
  // Sized like an office corner seen by a hand-held Kinect (TUM fr1 scenes are mostly at
  // 1-2.5 m): the far wall is 2.2 m away, where the sensor's depth noise is about 6 mm.
  // Scripted boxes, tumbling included, never enter the walls or the furniture.
  static const Room ROOM{
      Eigen::Vector3d(-2.0, -1.3, -1.0),
      Eigen::Vector3d(2.0, 1.0, 2.2),
      {{Eigen::Vector3d(-1.5, 0.8, 1.85), Eigen::Vector3d(0.4, 0.2, 0.35)},
       {Eigen::Vector3d(1.45, 0.85, 1.85), Eigen::Vector3d(0.35, 0.15, 0.35)}}};
  return ROOM;
}

const std::vector<Scenario>&
allScenarios()
{
  static const std::vector<Scenario> SCENARIOS = makeScenarios();
  return SCENARIOS;
}

} // namespace dynvo::detail
