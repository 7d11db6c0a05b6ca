// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/common/timestamps.h>
#include <dynvo/eval/trajectory_metrics.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace dynvo {

namespace {

std::vector<double>
stampsOf(const Trajectory& trajectory)
{
  std::vector<double> stamps;
  stamps.reserve(trajectory.size());
  for (const auto& pose : trajectory)
    stamps.push_back(pose.timestamp);
  return stamps;
}

double
median(std::vector<double> values)
{
  const auto middle = values.begin() + values.size() / 2;
  std::nth_element(values.begin(), middle, values.end());
  if (values.size() % 2 == 1)
    return *middle;
  return 0.5 * (*middle + *std::max_element(values.begin(), middle));
}

} // namespace

RpeResult
computeRpe(const Trajectory& groundtruth,
           const Trajectory& estimate,
           const RpeOptions& options)
{
  if (groundtruth.size() < 2 || estimate.size() < 2)
    throw std::invalid_argument(
        "[dynvo::computeRpe] both trajectories need at least 2 poses");
  if (!(options.delta > 0.0))
    throw std::invalid_argument("[dynvo::computeRpe] delta must be positive");

  const std::vector<double> stamps_gt = stampsOf(groundtruth);
  const std::vector<double> stamps_est = stampsOf(estimate);
  std::vector<double> index_est = stamps_est;
  if (options.unit == DeltaUnit::frames)
    for (std::size_t i = 0; i < index_est.size(); ++i)
      index_est[i] = static_cast<double>(i);

  std::vector<double> periods;
  for (std::size_t i = 1; i < stamps_gt.size(); ++i)
    periods.push_back(stamps_gt[i] - stamps_gt[i - 1]);
  const double max_time_difference = 2.0 * median(periods);

  double sum_t = 0.0, sum_t2 = 0.0, sum_r = 0.0, sum_r2 = 0.0;
  std::size_t pairs = 0;
  for (std::size_t i = 0; i < estimate.size(); ++i) {
    const std::size_t j = findClosestIndex(index_est, index_est[i] + options.delta);
    if (j == estimate.size() - 1)
      continue;
    const std::size_t gi = findClosestIndex(stamps_gt, stamps_est[i]);
    const std::size_t gj = findClosestIndex(stamps_gt, stamps_est[j]);
    if (std::abs(stamps_gt[gi] - stamps_est[i]) > max_time_difference ||
        std::abs(stamps_gt[gj] - stamps_est[j]) > max_time_difference)
      continue;
    const Eigen::Isometry3d rel_est =
        estimate[j].T_world_camera.inverse() * estimate[i].T_world_camera;
    const Eigen::Isometry3d rel_gt =
        groundtruth[gj].T_world_camera.inverse() * groundtruth[gi].T_world_camera;
    const Eigen::Isometry3d error = rel_est.inverse() * rel_gt;
    const double trans = error.translation().norm();
    const double cos_angle =
        std::clamp((error.linear().trace() - 1.0) / 2.0, -1.0, 1.0);
    const double rot = std::acos(cos_angle) * 180.0 / M_PI;
    sum_t += trans;
    sum_t2 += trans * trans;
    sum_r += rot;
    sum_r2 += rot * rot;
    ++pairs;
  }
  if (pairs == 0)
    throw std::invalid_argument(
        "[dynvo::computeRpe] no pose pair: the trajectories do not overlap in time or "
        "are shorter than delta");
  RpeResult result;
  const double n = static_cast<double>(pairs);
  result.trans_rmse = std::sqrt(sum_t2 / n);
  result.trans_mean = sum_t / n;
  result.rot_rmse = std::sqrt(sum_r2 / n);
  result.rot_mean = sum_r / n;
  result.pairs = pairs;
  return result;
}

RpeResult
computeObjectRpe(const Trajectory& truth,
                 const Trajectory& estimate,
                 const Eigen::Isometry3d& T_truth_estimate,
                 const RpeOptions& options)
{
  if (estimate.empty())
    throw std::invalid_argument("[dynvo::computeObjectRpe] the estimate is empty");
  // 0.1 s: three frames at 30 Hz; the truth of a synthetic sequence has every frame.
  const auto first = interpolatePose(truth, estimate.front().timestamp, 0.1);
  if (!first)
    throw std::invalid_argument("[dynvo::computeObjectRpe] no true pose at the "
                                "estimate's first stamp");
  const Eigen::Vector3d b =
      first->inverse() *
      (T_truth_estimate * estimate.front().T_world_camera.translation());
  const auto points = [](const Trajectory& poses, const Eigen::Isometry3d& T_world_pose,
                         const Eigen::Vector3d& point) {
    Trajectory path;
    for (const StampedPose& pose : poses) {
      StampedPose position{pose.timestamp, Eigen::Isometry3d::Identity()};
      position.T_world_camera.translation() =
          T_world_pose * pose.T_world_camera * point;
      path.push_back(position);
    }
    return path;
  };
  return computeRpe(points(truth, Eigen::Isometry3d::Identity(), b),
                    points(estimate, T_truth_estimate, Eigen::Vector3d::Zero()),
                    options);
}

AteResult
computeAte(const Trajectory& groundtruth,
           const Trajectory& estimate,
           double max_difference)
{
  const auto matches =
      associateTimestamps(stampsOf(estimate), stampsOf(groundtruth), max_difference);
  if (matches.size() < 3)
    throw std::invalid_argument(
        "[dynvo::computeAte] only " + std::to_string(matches.size()) +
        " stamps associate within " + std::to_string(max_difference) + " s; need 3");
  Eigen::Matrix3Xd est(3, matches.size()), gt(3, matches.size());
  for (std::size_t k = 0; k < matches.size(); ++k) {
    est.col(k) = estimate[matches[k].first].T_world_camera.translation();
    gt.col(k) = groundtruth[matches[k].second].T_world_camera.translation();
  }
  AteResult result;
  result.T_groundtruth_estimate.matrix() = Eigen::umeyama(est, gt, false);
  const Eigen::Matrix3Xd residual = (result.T_groundtruth_estimate * est) - gt;
  result.rmse = std::sqrt(residual.colwise().squaredNorm().mean());
  result.pairs = matches.size();
  return result;
}

Trajectory
alignToGroundTruth(const Trajectory& groundtruth, const Trajectory& estimate)
{
  Trajectory aligned = estimate;
  if (associateTimestamps(stampsOf(estimate), stampsOf(groundtruth), 0.02).size() < 3)
    return aligned;
  const Eigen::Isometry3d T = computeAte(groundtruth, estimate).T_groundtruth_estimate;
  for (auto& pose : aligned)
    pose.T_world_camera = T * pose.T_world_camera;
  return aligned;
}

std::string
formatMetrics(const RpeResult& rpe, const AteResult& ate, bool json)
{
  const char* format =
      json ? "{\"rpe_trans_rmse\": %.6f, \"rpe_trans_mean\": %.6f, \"rpe_rot_rmse\": "
             "%.6f, "
             "\"ate_rmse\": %.6f, \"pairs\": %zu}"
           : "rpe_trans_rmse=%.6f rpe_trans_mean=%.6f rpe_rot_rmse=%.6f ate_rmse=%.6f "
             "pairs=%zu";
  char line[256];
  std::snprintf(line, sizeof(line), format, rpe.trans_rmse, rpe.trans_mean,
                rpe.rot_rmse, ate.rmse, rpe.pairs);
  return line;
}

} // namespace dynvo
