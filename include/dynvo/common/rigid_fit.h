// SPDX-License-Identifier: BSD-3-Clause
// Weighted least-squares rigid fit of point pairs (docs/algorithm.md §2), shared by the modules.
#pragma once

#include <dynvo/common/export.h>

#include <Eigen/Core>

#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <vector>

namespace dynvo {

/// Outcome of RigidFitAccumulator::solve().
enum class RigidFitStatus {
  ok,             ///< a unique rigid transformation was found
  too_few_points, ///< fewer than 3 pairs with a positive weight
  degenerate ///< the pairs are (nearly) collinear: s2 < 1e-9 s1, or all at one point
};

/** \brief Weighted least-squares rigid fit without scale (Kabsch/Umeyama, Eggert et al. 1997).
 *
 * Finds the rigid T_target_source = [R t; 0 1] minimising
 * sum_i w_i || R s_i + t - q_i ||^2 over pairs (s_i, q_i) (docs/algorithm.md §2). The moments are
 * accumulated in double precision relative to the first pair added, so points far from the
 * origin lose no precision; the 3x3 cross-covariance is decomposed with Eigen's JacobiSVD and a
 * reflection guard keeps det(R) = +1, so planar point sets give a proper rotation.
 * Only the sums are stored: add() is O(1), solve() is O(1) and may be called repeatedly.
 * \code
 * dynvo::RigidFitAccumulator fit;
 * for (const auto& cell : flow)
 *   if (cell.valid_3d)
 *     fit.add(cell.getVector3fMap().cast<double>(),                       // b_i, frame k
 *             Eigen::Vector3d(cell.prev_x, cell.prev_y, cell.prev_z),      // a_i, frame k-1
 *             cell.weight);
 * Eigen::Matrix4d T_prev_curr;
 * if (fit.solve(T_prev_curr) == dynvo::RigidFitStatus::ok) { ... }
 * \endcode
 */
class DYNVO_EXPORTS RigidFitAccumulator {
public:
  /** \brief Adds one pair.
   * \param[in] source point s_i (metres, source frame)
   * \param[in] target the same physical point q_i (metres, target frame)
   * \param[in] weight w_i >= 0; a pair of weight 0 is ignored
   * \throws std::invalid_argument when a coordinate or the weight is not finite, or weight < 0
   */
  void add(const Eigen::Vector3d& source,
           const Eigen::Vector3d& target,
           double weight = 1.0);

  /// Forgets every pair.
  void clear();

  /// Number of pairs added with a positive weight.
  std::size_t size() const { return count_; }

  /** \brief Solves for the rigid transformation.
   * \param[out] T_target_source maps source points into the target frame; written only when
   *             the result is RigidFitStatus::ok, so a caller can keep a previous fit
   * \return ok, too_few_points (fewer than 3 pairs) or degenerate (see RigidFitStatus)
   */
  RigidFitStatus solve(Eigen::Matrix4d& T_target_source) const;

private:
  std::size_t count_ = 0;   ///< pairs with weight > 0
  double weight_sum_ = 0.0; ///< sum w_i
  Eigen::Vector3d source_origin_ =
      Eigen::Vector3d::Zero(); ///< s of the first pair (metres)
  Eigen::Vector3d target_origin_ =
      Eigen::Vector3d::Zero(); ///< q of the first pair (metres)
  Eigen::Vector3d source_sum_ =
      Eigen::Vector3d::Zero(); ///< sum w_i (s_i - source_origin_)
  Eigen::Vector3d target_sum_ =
      Eigen::Vector3d::Zero(); ///< sum w_i (q_i - target_origin_)
  Eigen::Matrix3d cross_sum_ =
      Eigen::Matrix3d::Zero(); ///< sum w_i (q_i - q0)(s_i - s0)^T
};

// Inline: the segmentation's hypotheses add about 20000 pairs per frame.
inline void
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

/// One pair of an information-weighted fit: R source + t should equal target, with the
/// error's information matrix (m^-2, symmetric positive semi-definite) and a weight >= 0.
struct InformationPair {
  Eigen::Vector3d source;      ///< s_i (metres, source frame)
  Eigen::Vector3d target;      ///< q_i (metres, target frame)
  Eigen::Matrix3d information; ///< W_i, e.g. SensorNoiseModel::transferInformation()
  double weight = 1.0;         ///< w_i >= 0
};

/** \brief Gauss-Newton refinement of a rigid fit under anisotropic noise
 * (docs/algorithm.md §7.2).
 *
 * Minimises sum_i w_i rho(d_i) with the Mahalanobis distance
 * d_i^2 = r_i^T W_i r_i, r_i = R s_i + t - q_i, and Huber's rho with threshold huber (sigma):
 * pairs with d_i > huber count with weight huber / d_i (iteratively reweighted). Each step
 * solves the 6x6 normal equations for a left increment exp(xi) T, xi = (t, omega); it starts
 * from T_target_source (a RigidFitAccumulator fit). Structured-light depth is 1.6-6x noisier
 * along the ray than across it over 0.6-4.5 m (Kinect v1) and its noise grows with z^2, so
 * this fit trusts each pair's lateral (tracked) component and the near points more, where
 * the metric fit lets the far points' depth noise dominate.
 * \param[in] pairs at least 3 pairs with a positive weight
 * \param[in] iterations Gauss-Newton steps (>= 0; 0 leaves T_target_source unchanged)
 * \param[in] huber threshold of the robust loss (sigma, > 0)
 * \param[in,out] T_target_source start and result; written only when the result is ok
 * \return ok, too_few_points, or degenerate when the normal equations are singular
 */
DYNVO_EXPORTS RigidFitStatus refineRigidFit(const std::vector<InformationPair>& pairs,
                                            int iterations,
                                            double huber,
                                            Eigen::Matrix4d& T_target_source);

/** \brief Squared transfer error E_i = || R s + t - q ||^2 (m^2) of one pair under
 * T_target_source (the paper's eq. 1, docs/algorithm.md §2).
 */
inline double
squaredTransferError(const Eigen::Matrix4d& T_target_source,
                     const Eigen::Vector3d& source,
                     const Eigen::Vector3d& target)
{
  return (T_target_source.topLeftCorner<3, 3>() * source +
          T_target_source.topRightCorner<3, 1>() - target)
      .squaredNorm();
}

/// Inverse of a rigid motion: [R^T, -R^T t] (exact for a rotation R, unlike a general inverse).
inline Eigen::Matrix4d
rigidInverse(const Eigen::Matrix4d& T)
{
  Eigen::Matrix4d inv = Eigen::Matrix4d::Identity();
  inv.topLeftCorner<3, 3>() = T.topLeftCorner<3, 3>().transpose();
  inv.topRightCorner<3, 1>() = -inv.topLeftCorner<3, 3>() * T.topRightCorner<3, 1>();
  return inv;
}

} // namespace dynvo
