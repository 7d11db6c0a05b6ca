// SPDX-License-Identifier: BSD-3-Clause
// Rigid motions for tests and the pose comparators every test uses: angles in radians,
// translations in metres.
#pragma once

#include <Eigen/Geometry>

#include <cmath>

namespace dynvo::test {

/// Radians from degrees (tolerances are often easier to read in degrees).
constexpr double
radians(double degrees)
{
  return degrees * M_PI / 180.0;
}

/// Rigid motion from an axis-angle rotation (radians) and a translation (metres).
inline Eigen::Isometry3d
makePose(const Eigen::Vector3d& axis, double angle, const Eigen::Vector3d& translation)
{
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
  T.translation() = translation;
  return T;
}

/// makePose() as a 4x4 matrix.
inline Eigen::Matrix4d
makeMotion(const Eigen::Vector3d& axis,
           double angle,
           const Eigen::Vector3d& translation)
{
  return makePose(axis, angle, translation).matrix();
}

/** \brief Rotation angle (radians, in [0, pi]) of R_a^T R_b for two 4x4 rigid motions of
 * any scalar type. atan2 of the skew and symmetric parts stays accurate near 0, where
 * acos((trace - 1) / 2) turns the 1e-7 round-off of a float rotation into 5e-4 rad.
 */
template <typename A, typename B>
double
rotationError(const Eigen::MatrixBase<A>& T_a, const Eigen::MatrixBase<B>& T_b)
{
  const Eigen::Matrix3d dR =
      T_a.template topLeftCorner<3, 3>().template cast<double>().transpose() *
      T_b.template topLeftCorner<3, 3>().template cast<double>();
  const Eigen::Vector3d skew(dR(2, 1) - dR(1, 2), dR(0, 2) - dR(2, 0),
                             dR(1, 0) - dR(0, 1));
  return std::atan2(skew.norm() / 2.0, (dR.trace() - 1.0) / 2.0);
}

/// Distance (metres) between the translations of two 4x4 rigid motions.
template <typename A, typename B>
double
translationError(const Eigen::MatrixBase<A>& T_a, const Eigen::MatrixBase<B>& T_b)
{
  return (T_a.template topRightCorner<3, 1>().template cast<double>() -
          T_b.template topRightCorner<3, 1>().template cast<double>())
      .norm();
}

} // namespace dynvo::test
