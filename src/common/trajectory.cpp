// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/common/trajectory.h>

#include <algorithm>

namespace dynvo {

Eigen::Isometry3d
blendPose(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b, double x)
{
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::Quaterniond(a.linear())
                      .slerp(x, Eigen::Quaterniond(b.linear()))
                      .toRotationMatrix();
  pose.translation() = (1.0 - x) * a.translation() + x * b.translation();
  return pose;
}

std::optional<Eigen::Isometry3d>
interpolatePose(const Trajectory& trajectory, double stamp, double max_gap)
{
  const auto after = std::lower_bound(trajectory.begin(), trajectory.end(), stamp,
                                      [](const StampedPose& pose, double t) {
                                        return pose.timestamp < t;
                                      });
  if (after == trajectory.end() || after == trajectory.begin() ||
      after->timestamp - (after - 1)->timestamp > max_gap) {
    if (after != trajectory.end() && after->timestamp == stamp)
      return after->T_world_camera;
    return std::nullopt;
  }
  const StampedPose& a = *(after - 1);
  const StampedPose& b = *after;
  return blendPose(a.T_world_camera, b.T_world_camera,
                   (stamp - a.timestamp) / (b.timestamp - a.timestamp));
}

} // namespace dynvo
