// SPDX-License-Identifier: BSD-3-Clause
// Rigid motions for tests.
#pragma once

#include <Eigen/Geometry>

namespace dynvo::test {

/// Rigid motion from an axis-angle rotation (radians) and a translation (metres).
inline Eigen::Matrix4d
makeMotion(const Eigen::Vector3d& axis, double angle, const Eigen::Vector3d& translation)
{
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T.topLeftCorner<3, 3>() = Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
  T.topRightCorner<3, 1>() = translation;
  return T;
}

} // namespace dynvo::test
