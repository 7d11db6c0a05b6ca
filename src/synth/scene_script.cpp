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

/** Hand-held fast sweep (see the fast_sweep scenario): panning back and forth with the
 *  hand swinging along, a slower drift in depth, a small bob and roll. */
RigidPath
sweepingCamera()
{
  RigidPath path = staticCamera();
  path.translation = {{Eigen::Vector3d(0.36, 0.0, 0.0), 2.6, 0.0},
                      {Eigen::Vector3d(0.0, 0.05, 0.0), 4.1, 0.7},
                      {Eigen::Vector3d(0.0, 0.0, 0.25), 1.3, 0.2}};
  path.rotation = {{Eigen::Vector3d(0.0, 0.62, 0.0), 2.6, 0.0},
                   {Eigen::Vector3d(0.06, 0.0, 0.0), 3.3, 1.1},
                   {Eigen::Vector3d(0.0, 0.0, 0.05), 2.1, 0.4}};
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

  // 1.0 m wide, 1.6 m tall, 0.6 m deep, standing on the floor 2.7 m ahead (about a quarter
  // of the image), sliding sideways at up to 0.25 m/s with a slight yaw.
  ScriptedBox large{1, V(0.5, 0.8, 0.3), {}, {}};
  large.path.centre = V(0.0, 0.2, 2.7);
  large.path.translation = {{V(0.55, 0.0, 0.0), 0.45, 0.0}};
  large.path.rotation = {{V(0.0, 0.06, 0.0), 0.3, 0.5}};
  scenarios.push_back({"large_box_slow",
                       "moving camera, a large box (1.0 x 1.6 x 0.6 m) sliding slowly",
                       movingCamera(1.0),
                       {large}});

  // A 1.2 x 0.9 m panel facing the camera: from 3.3 m it comes to 1.12 m (about 80 % of
  // the image), stays nearer than 1.4 m (over half of it) for about 1.5 s while drifting
  // sideways, then leaves to the right.
  ScriptedBox panel{1, V(0.6, 0.45, 0.02), {}, {}};
  panel.path.base_rotation = cameraBaseRotation();
  const auto ahead = [](double x, double z) -> Eigen::Vector3d {
    return cameraBaseRotation() * V(x, 0.0, z);
  };
  panel.path.waypoints = {{0.0, ahead(-0.9, 3.3)},  {2.6, ahead(-0.15, 1.6)},
                          {3.2, ahead(-0.05, 1.2)}, {3.8, ahead(0.1, 1.22)},
                          {4.3, ahead(0.25, 1.5)},  {6.3, ahead(2.4, 2.1)}};
  panel.path.rotation = {{V(0.04, 0.0, 0.0), 0.9, 0.0}, {V(0.0, 0.05, 0.0), 0.6, 0.4}};
  scenarios.push_back({"panel_approach",
                       "moving camera, a panel approaching until it covers 80 % of the "
                       "image, then leaving",
                       movingCamera(0.5),
                       {panel}});

  // Box 1 at 1.5 m goes right while box 2 at 2.5 m goes left; they cross in the image.
  ScriptedBox near_box = ellipticBox(1, V(0.25, 0.25, 0.25), V(0.0, 0.25, 1.5),
                                     {{V(1.1, 0.0, 0.0), 0.55, -HALF_PI}}, 0.4);
  ScriptedBox far_box = ellipticBox(2, V(0.3, 0.2, 0.2), V(0.0, 0.0, 2.5),
                                    {{V(1.2, 0.0, 0.0), 0.55, HALF_PI}}, -0.3);
  scenarios.push_back({"two_crossing",
                       "moving camera, two boxes crossing in opposite directions",
                       movingCamera(1.0),
                       {near_box, far_box}});

  // Enters from the left, rests 2 s, moves on, rests 2 s, leaves to the right.
  ScriptedBox visitor{1, V(0.25, 0.25, 0.25), {}, {}};
  visitor.path.centre = V(0.0, 0.2, 1.5);
  visitor.path.waypoints = {{0.0, V(-1.95, 0.0, 0.0)},
                            {1.5, V(-0.45, 0.0, 0.0)},
                            {3.0, V(0.45, 0.0, 0.1)},
                            {4.5, V(1.95, 0.0, 0.0)}};
  visitor.schedule = {20.0, {{0.0, 1.75}, {3.75, 5.5}, {7.5, 9.25}}, 0.25};
  scenarios.push_back({"enter_stop_leave",
                       "moving camera, a box coming in, resting 2 s twice, leaving",
                       movingCamera(0.6),
                       {visitor}});

  // A 12 cm cube tossed across the view 2.3 m away every 1.08 s, at 3.8 m/s (up to
  // about 35 px per frame with the camera's motion), blurred over a 20 ms exposure. The
  // arc is shallower than a free fall: a throw under gravity at that image speed cannot
  // cross a room-wide view before landing in it.
  ScriptedBox ball{1, V(0.06, 0.06, 0.06), {}, {}};
  ball.path.centre = V(-2.05, 0.1, 2.3);
  ball.path.velocity = V(3.7, -1.0, 0.0);
  ball.path.acceleration = V(0.0, 2.0, 0.0);
  ball.path.rotation = {{V(4.0, 0.0, 0.0), 1.0, 0.0}};
  ball.path.spin_rate = 6.0;
  ball.path.repeat = 1.08;
  scenarios.push_back(
      {"thrown_object",
       "moving camera, a small cube tossed across the view, motion blur",
       movingCamera(0.6),
       {ball}});
  scenarios.back().exposure = 0.02;

  // The camera circles a box 1.9 m ahead while looking at it; the box bobs up and down
  // (perpendicular to the optical axis) at up to 0.1 m/s.
  RigidPath circling;
  circling.centre = V(0.0, 0.2, 1.9);
  circling.orbit_radius = 1.9;
  circling.rotation = {{V(0.0, 0.5, 0.0), 0.25, 0.0},
                       {V(0.03, 0.0, 0.0), 0.7, 1.0},
                       {V(0.0, 0.0, 0.02), 0.9, 0.0}};
  circling.translation = {{V(0.0, 0.04, 0.0), 0.8, 0.3}};
  ScriptedBox bobbing{1, V(0.2, 0.2, 0.2), {}, {}};
  bobbing.path.centre = V(0.0, 0.2, 1.9);
  bobbing.path.translation = {{V(0.0, 0.08, 0.0), 1.2, 0.0}};
  scenarios.push_back({"circling_bobbing",
                       "camera circling a slowly bobbing box",
                       circling,
                       {bobbing}});

  // A hand-held sweep as fast as the fastest stretches of TUM fr1/desk: the camera pans
  // back and forth (up to 90 deg/s) while the hand swings sideways (up to 1 m/s), holding
  // still for 0.75 s after every 2.5 s of motion (0.25 s raised-cosine speed ramps), as
  // when someone stops to look. A 20 ms exposure blurs the whole image while it moves.
  scenarios.push_back(
      {"fast_sweep",
       "hand-held fast sweep (1 m/s, 90 deg/s) with holds, static room, "
       "motion blur",
       sweepingCamera(),
       {}});
  scenarios.back().exposure = 0.02;
  scenarios.back().camera_schedule = {3.25, {{0.0, 2.5}}, 0.25};
  return scenarios;
}

/// Cubic Hermite spline through the waypoints (see RigidPath).
Eigen::Vector3d
waypointPosition(const std::vector<Waypoint>& points, double s)
{
  if (points.empty())
    return Eigen::Vector3d::Zero();
  if (s <= points.front().s)
    return points.front().position;
  if (s >= points.back().s)
    return points.back().position;
  std::size_t j = 1;
  while (points[j].s < s)
    ++j;
  const auto tangent = [&points](std::size_t i) -> Eigen::Vector3d {
    if (i == 0 || i + 1 == points.size())
      return Eigen::Vector3d::Zero();
    return (points[i + 1].position - points[i - 1].position) /
           (points[i + 1].s - points[i - 1].s);
  };
  const Waypoint &a = points[j - 1], &b = points[j];
  const double h = b.s - a.s, x = (s - a.s) / h;
  const double x2 = x * x, x3 = x2 * x;
  return (2 * x3 - 3 * x2 + 1) * a.position + (x3 - 2 * x2 + x) * h * tangent(j - 1) +
         (-2 * x3 + 3 * x2) * b.position + (x3 - x2) * h * tangent(j);
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
  const double r = repeat > 0.0 ? s - repeat * std::floor(s / repeat) : s;
  Eigen::Vector3d translation_now = centre + waypointPosition(waypoints, r) +
                                    velocity * r + 0.5 * acceleration * r * r;
  for (const SineTerm& term : translation)
    translation_now += term.amplitude * std::sin(term.omega * r + term.phase);
  Eigen::Vector3d rotation_vector = Eigen::Vector3d::Zero();
  for (const SineTerm& term : rotation)
    rotation_vector += term.amplitude * std::sin(term.omega * r + term.phase);
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() =
      base_rotation *
      Eigen::AngleAxisd(spin_rate * r, Eigen::Vector3d::UnitY()).toRotationMatrix() *
      expRotation(rotation_vector);
  pose.translation() = translation_now - orbit_radius * pose.linear().col(2);
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
  // An office seen by a hand-held Kinect from about 1 m above the floor: the far wall is
  // 4.0 m away (3.7-4.3 m from the moving camera), with furniture at 1.5-3.9 m: two low
  // boxes on the floor at the sides, a table, a tall shelf, and a dark cabinet that
  // returns almost no depth. Scripted boxes never enter the walls or the furniture.
  static const Room ROOM{
      Eigen::Vector3d(-2.2, -1.4, -1.0),
      Eigen::Vector3d(2.2, 1.0, 4.0),
      {{Eigen::Vector3d(-1.5, 0.8, 1.85), Eigen::Vector3d(0.4, 0.2, 0.35)},
       {Eigen::Vector3d(1.45, 0.85, 1.85), Eigen::Vector3d(0.35, 0.15, 0.35)},
       {Eigen::Vector3d(0.0, 0.6, 3.35), Eigen::Vector3d(0.5, 0.4, 0.3)},
       {Eigen::Vector3d(-1.5, 0.05, 3.55), Eigen::Vector3d(0.45, 0.95, 0.25)},
       {Eigen::Vector3d(1.3, 0.5, 3.6), Eigen::Vector3d(0.5, 0.5, 0.25), true}}};
  return ROOM;
}

const std::vector<Scenario>&
allScenarios()
{
  static const std::vector<Scenario> SCENARIOS = makeScenarios();
  return SCENARIOS;
}

} // namespace dynvo::detail
