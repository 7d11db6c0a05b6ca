// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/common/rigid_fit.h>

#include <Eigen/LU>
#include <Eigen/SVD>

#include <cmath>
#include <stdexcept>

namespace dynvo {

void
RigidFitAccumulator::add(const Eigen::Vector3d& source,
                         const Eigen::Vector3d& target,
                         double weight)
{
  if (!source.allFinite() || !target.allFinite() || !std::isfinite(weight) ||
      weight < 0.0)
    throw std::invalid_argument("[dynvo::RigidFitAccumulator::add] points must be "
                                "finite and the weight finite and "
                                ">= 0");
  if (weight == 0.0)
    return;
  if (count_ == 0) {
    source_origin_ = source;
    target_origin_ = target;
  }
  const Eigen::Vector3d s = source - source_origin_;
  const Eigen::Vector3d q = target - target_origin_;
  ++count_;
  weight_sum_ += weight;
  source_sum_ += weight * s;
  target_sum_ += weight * q;
  cross_sum_.noalias() += (weight * q) * s.transpose();
}

void
RigidFitAccumulator::clear()
{
  *this = RigidFitAccumulator();
}

RigidFitStatus
RigidFitAccumulator::solve(Eigen::Matrix4d& T_target_source) const
{
  if (count_ < 3)
    return RigidFitStatus::too_few_points;
  // Centroids relative to the first pair, then the centred cross-covariance
  // M = sum w (q - qbar)(s - sbar)^T = sum w q s^T - W qbar sbar^T.
  const Eigen::Vector3d source_mean = source_sum_ / weight_sum_;
  const Eigen::Vector3d target_mean = target_sum_ / weight_sum_;
  const Eigen::Matrix3d M =
      cross_sum_ - weight_sum_ * target_mean * source_mean.transpose();
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(M, Eigen::ComputeFullU |
                                                     Eigen::ComputeFullV);
  const Eigen::Vector3d& s = svd.singularValues();
  if (!(s(0) > 0.0) || s(1) < 1e-9 * s(0))
    return RigidFitStatus::degenerate;
  Eigen::Vector3d guard = Eigen::Vector3d::Ones();
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0.0)
    guard(2) = -1.0;
  const Eigen::Matrix3d R =
      svd.matrixU() * guard.asDiagonal() * svd.matrixV().transpose();
  T_target_source.setIdentity();
  T_target_source.topLeftCorner<3, 3>() = R;
  T_target_source.topRightCorner<3, 1>() =
      (target_origin_ + target_mean) - R * (source_origin_ + source_mean);
  return RigidFitStatus::ok;
}

} // namespace dynvo
