// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/eval/trajectory_metrics.h>
#include <dynvo/io/trajectory_io.h>

#include "support/shared_data.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

namespace {

/// 30 Hz trajectory over `seconds`, pose(t) given by the callable.
template <typename PoseAt>
dynvo::Trajectory
sample(double seconds, PoseAt pose_at)
{
  dynvo::Trajectory trajectory;
  for (int k = 0; k <= static_cast<int>(std::lround(seconds * 30.0)); ++k) {
    const double t = 100.0 + k / 30.0;
    trajectory.push_back({t, pose_at(t - 100.0)});
  }
  return trajectory;
}

Eigen::Isometry3d
wobble(double t)
{
  return Eigen::Translation3d(0.3 * std::sin(t), 0.1 * t, 1.0 + 0.2 * std::cos(2 * t)) *
         Eigen::AngleAxisd(0.4 * std::sin(0.7 * t),
                           Eigen::Vector3d(0.2, 1, 0.3).normalized());
}

TEST(TrajectoryMetrics, IdenticalTrajectoriesScoreZero)
{
  const auto gt = sample(5.0, wobble);
  const auto rpe = dynvo::computeRpe(gt, gt);
  EXPECT_NEAR(rpe.trans_rmse, 0.0, 1e-12);
  EXPECT_NEAR(rpe.rot_rmse, 0.0, 1e-5); // acos near 1 amplifies rounding to ~1e-6 deg
  // 151 poses at 30 Hz: pose i pairs with i + 30 unless that is the last pose (150).
  EXPECT_EQ(rpe.pairs, 120u);
  const auto ate = dynvo::computeAte(gt, gt);
  EXPECT_NEAR(ate.rmse, 0.0, 1e-9);
  EXPECT_EQ(ate.pairs, gt.size());
}

TEST(TrajectoryMetrics, ConstantRigidOffsetGivesZeroAteAndRpe)
{
  // The same motion expressed in another world frame: relative poses are unchanged and
  // rigid alignment removes the offset entirely.
  const Eigen::Isometry3d T_other_world =
      Eigen::Translation3d(2.0, -1.0, 0.5) *
      Eigen::AngleAxisd(1.2, Eigen::Vector3d::UnitZ());
  const auto gt = sample(5.0, wobble);
  const auto est = sample(5.0, [&](double t) {
    return T_other_world * wobble(t);
  });
  EXPECT_NEAR(dynvo::computeAte(gt, est).rmse, 0.0, 1e-9);
  EXPECT_NEAR(dynvo::computeRpe(gt, est).trans_rmse, 0.0, 1e-9);
  EXPECT_TRUE(dynvo::computeAte(gt, est).T_groundtruth_estimate.isApprox(
      T_other_world.inverse(), 1e-9));
}

TEST(TrajectoryMetrics, KnownDriftPerSecondGivesKnownRpe)
{
  // Static camera in the ground truth; the estimate drifts 1 cm/s along x and turns
  // 2 deg/s about z. Over the 1 s delta the error is exactly 0.01 m and 2 degrees.
  const auto gt = sample(5.0, [](double) {
    return Eigen::Isometry3d::Identity();
  });
  const auto est = sample(5.0, [](double t) {
    return Eigen::Isometry3d(
        Eigen::Translation3d(0.01 * t, 0.0, 0.0) *
        Eigen::AngleAxisd(2.0 * M_PI / 180.0 * t, Eigen::Vector3d::UnitZ()));
  });
  const auto rpe = dynvo::computeRpe(gt, est);
  EXPECT_NEAR(rpe.trans_rmse, 0.01, 1e-9);
  EXPECT_NEAR(rpe.trans_mean, 0.01, 1e-9);
  EXPECT_NEAR(rpe.rot_rmse, 2.0, 1e-6);

  // The same in frames: 30 frames at 30 Hz is 1 s.
  dynvo::RpeOptions frames;
  frames.delta = 30;
  frames.unit = dynvo::DeltaUnit::frames;
  EXPECT_NEAR(dynvo::computeRpe(gt, est, frames).trans_rmse, 0.01, 1e-9);
  // Half a second: half the drift.
  dynvo::RpeOptions half;
  half.delta = 0.5;
  EXPECT_NEAR(dynvo::computeRpe(gt, est, half).trans_rmse, 0.005, 1e-9);
}

TEST(TrajectoryMetrics, PairsWithoutGroundTruthAreSkipped)
{
  // A static camera, so that substituting a nearby gt pose changes nothing.
  const auto line = [](double) {
    return Eigen::Isometry3d::Identity();
  };
  auto gt = sample(5.0, line);
  // Remove ground truth between 1 s and 2 s: estimate stamps more than twice the median
  // gt period (2/30 s) from any remaining gt stamp lose their pairs.
  gt.erase(std::remove_if(gt.begin(), gt.end(),
                          [](const dynvo::StampedPose& p) {
                            return p.timestamp > 101.0 && p.timestamp < 102.0;
                          }),
           gt.end());
  const auto est = sample(5.0, line);
  const auto rpe = dynvo::computeRpe(gt, est);
  // About 25 of the 29 stamps inside the gap are more than 2 periods from its edges; each
  // drops the pair it starts and the pair ending on it, so at least 40 of 120 pairs go.
  EXPECT_LT(rpe.pairs, 80u) << rpe.pairs;
  EXPECT_GT(rpe.pairs, 50u) << rpe.pairs;
  EXPECT_LT(rpe.trans_rmse, 1e-12);
}

TEST(TrajectoryMetrics, DegenerateInputsThrow)
{
  const auto gt = sample(5.0, wobble);
  EXPECT_THROW(dynvo::computeRpe(gt, {gt.front()}), std::invalid_argument);
  dynvo::RpeOptions bad;
  bad.delta = 0.0;
  EXPECT_THROW(dynvo::computeRpe(gt, gt, bad), std::invalid_argument);
  // Disjoint in time: nothing associates.
  auto later = gt;
  for (auto& pose : later)
    pose.timestamp += 1000.0;
  EXPECT_THROW(dynvo::computeAte(gt, later), std::invalid_argument);
  EXPECT_THROW(dynvo::computeRpe(gt, later), std::invalid_argument);
}

TEST(TrajectoryMetricsRealData, Fr1GroundTruthAgainstDriftingCopy)
{
  const auto path =
      std::filesystem::path(dynvo::test::sharedDataPath("tum_fr1_xyz_200")) /
      "groundtruth.txt";
  DYNVO_REQUIRE_SHARED_DATA(path.string());
  const auto gt = dynvo::readTrajectory(path.string());
  // Estimate: every third ground-truth pose (about 33 Hz) with a world-frame drift of
  // 2 cm/s along x. The relative error of a pair is the drift over its time span
  // (about 1 s, within one gt period of 10 ms), whatever the camera's rotation.
  dynvo::Trajectory est;
  const double v = 0.02;
  for (std::size_t i = 0; i < gt.size(); i += 3) {
    auto pose = gt[i];
    pose.T_world_camera.pretranslate(
        Eigen::Vector3d(v * (pose.timestamp - gt[0].timestamp), 0, 0));
    est.push_back(pose);
  }
  const auto rpe = dynvo::computeRpe(gt, est);
  EXPECT_NEAR(rpe.trans_rmse, v, v * 0.015);
  EXPECT_NEAR(rpe.rot_rmse, 0.0, 1e-4);
  EXPECT_GT(rpe.pairs, 150u);
  // Rigid alignment can absorb a linear ramp at best as well as a pure translation does,
  // which leaves an RMS of v * T / sqrt(12) for a ramp over T seconds.
  const double span = est.back().timestamp - est.front().timestamp;
  const auto ate = dynvo::computeAte(gt, est);
  EXPECT_GT(ate.rmse, 0.0);
  EXPECT_LE(ate.rmse, v * span / std::sqrt(12.0) + 1e-6);
}

TEST(ObjectRpe, FixedOffsetsOfWorldAndObjectFrameScoreZero)
{
  // The estimate is the true object seen from another world (A) with another object
  // frame (B: a point on its surface, other axes). Plain RPE of the poses is not
  // invariant to B once the object rotates; the point path is.
  const Eigen::Isometry3d A = Eigen::Translation3d(0.5, -0.2, 1.0) *
                              Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitY());
  const Eigen::Isometry3d B = Eigen::Translation3d(0.1, -0.15, 0.2) *
                              Eigen::AngleAxisd(-0.4, Eigen::Vector3d::UnitX());
  const auto truth = sample(4.0, wobble);
  const auto estimate = sample(4.0, [&](double t) {
    return A * wobble(t) * B;
  });
  EXPECT_GT(dynvo::computeRpe(truth, estimate).trans_rmse, 0.01); // B matters for RPE
  const auto rpe = dynvo::computeObjectRpe(truth, estimate, A.inverse());
  EXPECT_GT(rpe.pairs, 0u);
  EXPECT_NEAR(rpe.trans_rmse, 0.0, 1e-9);
}

TEST(ObjectRpe, DriftOfTheObjectPathIsItsRate)
{
  // The estimated path drifts 2 cm/s along x: every 1 s pair is off by 2 cm.
  const Eigen::Isometry3d B(Eigen::Translation3d(0.05, 0.0, -0.1));
  const auto truth = sample(4.0, wobble);
  const auto estimate = sample(4.0, [&](double t) {
    return Eigen::Translation3d(0.02 * t, 0.0, 0.0) * wobble(t) * B;
  });
  const auto rpe =
      dynvo::computeObjectRpe(truth, estimate, Eigen::Isometry3d::Identity());
  EXPECT_NEAR(rpe.trans_rmse, 0.02, 1e-6); // the 1 s pairs span 30 frames exactly
  EXPECT_DOUBLE_EQ(rpe.rot_rmse, 0.0);
  EXPECT_THROW(dynvo::computeObjectRpe(truth, {}, Eigen::Isometry3d::Identity()),
               std::invalid_argument);
}

} // namespace
