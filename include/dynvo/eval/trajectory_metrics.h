// SPDX-License-Identifier: BSD-3-Clause
// Trajectory accuracy metrics of the TUM RGB-D benchmark (RPE and ATE).
#pragma once

#include <dynvo/common/export.h>
#include <dynvo/common/trajectory.h>

#include <cstddef>
#include <string>

namespace dynvo {

/// Unit of the RPE delta.
enum class DeltaUnit {
  seconds, ///< delta in seconds (the paper's protocol: 1 s)
  frames,  ///< delta in frames of the estimate
};

/// Options of computeRpe(); the defaults are evaluate_rpe.py --fixed_delta --delta 1 --delta_unit s.
struct RpeOptions {
  double delta = 1.0;                  ///< pose-pair spacing, in `unit`
  DeltaUnit unit = DeltaUnit::seconds; ///< unit of delta
};

/// Relative pose error over all pairs.
struct RpeResult {
  double trans_rmse = 0.0; ///< translational RMSE (metres per delta: m/s for 1 s)
  double trans_mean = 0.0; ///< translational mean (metres per delta)
  double rot_rmse = 0.0;   ///< rotational RMSE (degrees per delta)
  double rot_mean = 0.0;   ///< rotational mean (degrees per delta)
  std::size_t pairs = 0;   ///< pose pairs evaluated
};

/** \brief Relative pose error as the TUM benchmark's evaluate_rpe.py with --fixed_delta.
 *
 * For each estimated pose i, j is the estimated pose closest to t_i + delta (in seconds
 * or in frames); pairs whose j is the last pose are skipped, as are pairs where either
 * stamp has no ground truth within twice the median ground-truth period. The error of a
 * pair is inv(inv(est_j) est_i) (inv(gt_j) gt_i). Unlike the script, every pair is used
 * (the script samples 10000 at random only beyond 10000 pairs).
 * \throws std::invalid_argument when a trajectory has fewer than 2 poses, delta is not
 *         positive, or no pair can be formed
 */
DYNVO_EXPORTS RpeResult computeRpe(const Trajectory& groundtruth,
                                   const Trajectory& estimate,
                                   const RpeOptions& options = {});

/** \brief Translational RPE of a tracked object's trajectory against the true object's.
 *
 * An estimated object frame and the true one differ by a fixed unknown offset, and the
 * plain RPE of object poses is not invariant to it, so what is scored is the world path
 * of one point of the object: the origin of the estimated object frame. Its estimated
 * positions are p_k = T_truth_estimate * estimate[k] origin (in the truth's world); its
 * true positions are q = truth(t) * b, with b = inv(truth(t_0)) * p_0 its coordinates
 * in the true object frame at the estimate's first stamp t_0 (truth interpolated,
 * interpolatePose()). computeRpe() of the two point paths then gives, per pair,
 * |(p_j - p_i) - (q_j - q_i)| (metres per delta); the rotation fields are 0 (the
 * object's rotation enters through q only).
 * \param[in] truth true object-to-world poses
 * \param[in] estimate estimated object-to-world poses (the estimate's world)
 * \param[in] T_truth_estimate maps the estimate's world into the truth's
 * \param[in] options pair spacing, as computeRpe()
 * \throws std::invalid_argument as computeRpe(), or when truth has no pose within 0.1 s
 *         of the estimate's first stamp
 */
DYNVO_EXPORTS RpeResult computeObjectRpe(const Trajectory& truth,
                                         const Trajectory& estimate,
                                         const Eigen::Isometry3d& T_truth_estimate,
                                         const RpeOptions& options = {});

/// Absolute trajectory error after rigid alignment.
struct AteResult {
  double rmse = 0.0;     ///< RMSE of the aligned position differences (metres)
  std::size_t pairs = 0; ///< associated pose pairs
  Eigen::Isometry3d T_groundtruth_estimate =
      Eigen::Isometry3d::Identity(); ///< alignment
};

/** \brief Absolute trajectory error as evaluate_ate.py: stamps associated one-to-one
 * within max_difference seconds, closed-form rigid alignment (rotation and translation,
 * no scale) of the estimated positions onto the ground truth, RMSE of the residuals.
 * \throws std::invalid_argument when fewer than 3 stamps associate
 */
DYNVO_EXPORTS AteResult computeAte(const Trajectory& groundtruth,
                                   const Trajectory& estimate,
                                   double max_difference = 0.02);

/** \brief The estimate moved into the ground truth's world frame by the ATE alignment
 * (for plotting both together); unchanged when fewer than 3 stamps associate.
 */
DYNVO_EXPORTS Trajectory alignToGroundTruth(const Trajectory& groundtruth,
                                            const Trajectory& estimate);

/** \brief The result line of dynvo_evaluate:
 * "rpe_trans_rmse=<m/s> rpe_trans_mean=<m/s> rpe_rot_rmse=<deg/s> ate_rmse=<m> pairs=<n>",
 * or the same fields as one JSON object; no trailing newline.
 */
DYNVO_EXPORTS std::string
formatMetrics(const RpeResult& rpe, const AteResult& ate, bool json = false);

} // namespace dynvo
