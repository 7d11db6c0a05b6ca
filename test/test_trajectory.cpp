// SPDX-License-Identifier: BSD-3-Clause
// blendPose and interpolatePose: poses between (and beyond) two samples.
#include <dynvo/common/trajectory.h>

#include <gtest/gtest.h>

#include "support/pose_compare.h"

namespace {

dynvo::Trajectory
twoSamples(double gap)
{
  const Eigen::Isometry3d a = Eigen::Isometry3d::Identity();
  const Eigen::Isometry3d b = dynvo::test::makePose(Eigen::Vector3d::UnitZ(), 0.2,
                                                    Eigen::Vector3d(1.0, 0.0, 0.0));
  return {{10.0, a}, {10.0 + gap, b}};
}

TEST(BlendPose, EndsInterpolationAndOneStepBeyond)
{
  const auto samples = twoSamples(0.1);
  const Eigen::Isometry3d& a = samples[0].T_world_camera;
  const Eigen::Isometry3d& b = samples[1].T_world_camera;
  const auto expectPose = [](const Eigen::Isometry3d& pose,
                             const Eigen::Isometry3d& expected) {
    EXPECT_LT(dynvo::test::translationError(pose.matrix(), expected.matrix()), 1e-9);
    EXPECT_LT(dynvo::test::rotationError(pose.matrix(), expected.matrix()), 1e-9);
  };
  expectPose(dynvo::blendPose(a, b, 0.0), a);
  expectPose(dynvo::blendPose(a, b, 1.0), b);
  // Halfway: 0.5 m and 0.1 rad; x = 2 repeats the step (1 m, 0.2 rad about z) once more,
  // x = -0.5 goes half a step back.
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
  expectPose(dynvo::blendPose(a, b, 0.5),
             dynvo::test::makePose(z, 0.1, Eigen::Vector3d(0.5, 0.0, 0.0)));
  expectPose(dynvo::blendPose(a, b, 2.0),
             dynvo::test::makePose(z, 0.4, Eigen::Vector3d(2.0, 0.0, 0.0)));
  expectPose(dynvo::blendPose(a, b, -0.5),
             dynvo::test::makePose(z, -0.1, Eigen::Vector3d(-0.5, 0.0, 0.0)));
}

TEST(InterpolatePose, LinearTranslationAndSlerpRotationBetweenSamples)
{
  const auto trajectory = twoSamples(0.1);
  const auto pose = dynvo::interpolatePose(trajectory, 10.025, 0.25);
  ASSERT_TRUE(pose.has_value());
  // A quarter of the way: 0.25 m and a quarter of 0.2 rad about z.
  const Eigen::Isometry3d expected = dynvo::test::makePose(
      Eigen::Vector3d::UnitZ(), 0.05, Eigen::Vector3d(0.25, 0.0, 0.0));
  EXPECT_LT(dynvo::test::translationError(pose->matrix(), expected.matrix()), 1e-9);
  EXPECT_LT(dynvo::test::rotationError(pose->matrix(), expected.matrix()), 1e-9);
}

TEST(InterpolatePose, ExactSamplesOnlyOutsideOrAcrossLongGaps)
{
  const auto trajectory = twoSamples(1.0);
  EXPECT_FALSE(dynvo::interpolatePose(trajectory, 10.5, 0.25)); // gap of 1 s
  EXPECT_TRUE(dynvo::interpolatePose(trajectory, 10.5, 2.0));
  EXPECT_FALSE(dynvo::interpolatePose(trajectory, 9.0, 2.0));  // before the first
  EXPECT_FALSE(dynvo::interpolatePose(trajectory, 12.0, 2.0)); // after the last
  const auto first = dynvo::interpolatePose(trajectory, 10.0, 0.25);
  ASSERT_TRUE(first.has_value());
  EXPECT_TRUE(first->isApprox(trajectory[0].T_world_camera, 0.0));
  const auto last = dynvo::interpolatePose(trajectory, 11.0, 0.25);
  ASSERT_TRUE(last.has_value());
  EXPECT_EQ(last->matrix(), trajectory[1].T_world_camera.matrix());
  EXPECT_FALSE(dynvo::interpolatePose({}, 10.0, 1.0));
}

} // namespace
