// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/common/rigid_fit.h>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <Eigen/LU>
#include <Eigen/SVD>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace dynvo {

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

RigidFitStatus
refineRigidFit(const std::vector<InformationPair>& pairs,
               int iterations,
               double huber,
               Eigen::Matrix4d& T_target_source)
{
  std::size_t count = 0;
  for (const InformationPair& pair : pairs)
    count += pair.weight > 0.0;
  if (count < 3)
    return RigidFitStatus::too_few_points;
  using Matrix6 = Eigen::Matrix<double, 6, 6>;
  using Vector6 = Eigen::Matrix<double, 6, 1>;
  Eigen::Matrix4d T = T_target_source;
  for (int iteration = 0; iteration < iterations; ++iteration) {
    Matrix6 H = Matrix6::Zero();
    Vector6 g = Vector6::Zero();
    const Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
    const Eigen::Vector3d t = T.topRightCorner<3, 1>();
    for (const InformationPair& pair : pairs) {
      if (!(pair.weight > 0.0))
        continue;
      const Eigen::Vector3d p = R * pair.source + t;
      const Eigen::Vector3d r = p - pair.target;
      const Eigen::Vector3d Wr = pair.information * r;
      const double d = std::sqrt(std::max(0.0, r.dot(Wr)));
      const double w = pair.weight * (d <= huber ? 1.0 : huber / d);
      // d(exp(xi) p)/d xi at 0 = [I, -[p]x]
      Eigen::Matrix<double, 3, 6> J;
      J.leftCols<3>().setIdentity();
      J.rightCols<3>() << 0.0, p.z(), -p.y(), -p.z(), 0.0, p.x(), p.y(), -p.x(), 0.0;
      H.noalias() += w * J.transpose() * pair.information * J;
      g.noalias() += w * J.transpose() * Wr;
    }
    const Eigen::LDLT<Matrix6> ldlt(H);
    if (ldlt.info() != Eigen::Success ||
        !(ldlt.vectorD().minCoeff() > 1e-12 * ldlt.vectorD().maxCoeff()))
      return RigidFitStatus::degenerate;
    const Vector6 xi = -ldlt.solve(g);
    Eigen::Matrix4d step = Eigen::Matrix4d::Identity();
    const Eigen::Vector3d omega = xi.tail<3>();
    if (omega.norm() > 0.0)
      step.topLeftCorner<3, 3>() =
          Eigen::AngleAxisd(omega.norm(), omega / omega.norm()).toRotationMatrix();
    step.topRightCorner<3, 1>() = xi.head<3>();
    T = step * T;
  }
  T_target_source = T;
  return RigidFitStatus::ok;
}

} // namespace dynvo
