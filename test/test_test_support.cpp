// SPDX-License-Identifier: BSD-3-Clause
// The shared test generator and comparators: they must be right for the tests to mean
// anything.
#include "support/pose_compare.h"
#include "support/synthetic_scene.h"

#include <pcl/point_types.h>

#include <gtest/gtest.h>

#include <cmath>

namespace {

using dynvo::test::makePose;
using dynvo::test::radians;

dynvo::CameraIntrinsics
smallCamera()
{
  return {131.25, 131.25, 79.5, 59.5}; // 525 px at 160x120
}

TEST(PoseCompare, AnglesAreRadiansAndSymmetric)
{
  const Eigen::Matrix4d a = makePose({0, 1, 0}, 0.3, {0.1, 0.2, 0.3}).matrix();
  const Eigen::Matrix4d b =
      makePose({0, 1, 0}, 0.3 + radians(2.0), {0.1, 0.2, 0.35}).matrix();
  EXPECT_NEAR(dynvo::test::rotationError(a, b), radians(2.0), 1e-12);
  EXPECT_NEAR(dynvo::test::rotationError(b, a), radians(2.0), 1e-12);
  EXPECT_NEAR(dynvo::test::translationError(a, b), 0.05, 1e-12);
  EXPECT_NEAR(radians(180.0), M_PI, 1e-15);
  // Float against double, and tiny angles stay accurate (atan2, not acos).
  const Eigen::Matrix4f af = a.cast<float>();
  EXPECT_LT(dynvo::test::rotationError(af, a), 1e-6);
  const Eigen::Matrix4d c = makePose({1, 0, 0}, 1e-6, {0, 0, 0}).matrix();
  EXPECT_NEAR(dynvo::test::rotationError(Eigen::Matrix4d::Identity().eval(), c), 1e-6,
              1e-12);
  EXPECT_EQ(dynvo::test::makeMotion({0, 0, 1}, 0.1, {1, 2, 3}),
            makePose({0, 0, 1}, 0.1, {1, 2, 3}).matrix());
}

TEST(SyntheticScene, FrontoParallelQuadGivesExactDepthAndIds)
{
  const std::vector<dynvo::test::SceneBox> boxes = {
      dynvo::test::texturedQuad(Eigen::Isometry3d(Eigen::Translation3d(0, 0, 2.0)),
                                10.0, 10.0, 1),
      dynvo::test::texturedQuad(Eigen::Isometry3d(Eigen::Translation3d(0, 0, 1.0)), 0.1,
                                0.1, 2)};
  const auto view = dynvo::test::render<pcl::PointXYZRGB>(
      boxes, Eigen::Isometry3d::Identity(), smallCamera(), 160, 120);
  ASSERT_EQ(view.cloud->width, 160u);
  ASSERT_EQ(view.cloud->height, 120u);
  // The small quad at 1 m covers +-0.1 m = +-13 px around the centre; the wall is behind.
  EXPECT_EQ(view.ids[60 * 160 + 80], 1);
  EXPECT_NEAR((*view.cloud)(80, 60).z, 1.0f, 1e-6f);
  EXPECT_EQ(view.ids[5 * 160 + 5], 0);
  EXPECT_NEAR((*view.cloud)(5, 5).z, 2.0f, 1e-6f);
  // Textured: neighbouring pixels differ somewhere.
  int changes = 0;
  for (int u = 1; u < 160; ++u)
    changes += (*view.cloud)(u, 5).r != (*view.cloud)(u - 1, 5).r;
  EXPECT_GT(changes, 40);
}

TEST(SyntheticScene, IdealFlowMapsCurrentPointsBackToThePreviousFrame)
{
  dynvo::test::SceneBox cube;
  cube.T_world_box = Eigen::Isometry3d(Eigen::Translation3d(0.0, 0.0, 1.2));
  cube.half_size = Eigen::Vector3d(0.15, 0.15, 0.15);
  cube.moving = true;
  const std::vector<dynvo::test::SceneBox> boxes = {
      dynvo::test::texturedQuad(Eigen::Isometry3d(Eigen::Translation3d(0, 0, 2.5)),
                                10.0, 10.0, 1),
      cube};
  const Eigen::Isometry3d T_world_curr =
      makePose({0, 1, 0}, radians(1.0), {0.02, 0, 0});
  const Eigen::Isometry3d motion = makePose({0, 0, 1}, radians(5.0), {0.05, 0, 0});
  const auto current = dynvo::test::render<pcl::PointXYZRGB>(
      dynvo::test::moveBoxes(boxes, motion), T_world_curr, smallCamera(), 160, 120);
  std::vector<std::uint8_t> static_cell;
  const auto flow = dynvo::test::idealFlow(current, boxes, T_world_curr,
                                           Eigen::Isometry3d::Identity(), motion,
                                           smallCamera(), 16, &static_cell);
  ASSERT_EQ(flow.width, 10u);
  ASSERT_EQ(flow.height, 7u);
  std::size_t moving = 0, still = 0;
  for (std::size_t i = 0; i < flow.size(); ++i) {
    const dynvo::PointFlow& f = flow[i];
    ASSERT_TRUE(f.valid_3d); // the wall fills the view
    const Eigen::Vector3d b = f.getVector3fMap().cast<double>();
    const Eigen::Vector3d a(f.prev_x, f.prev_y, f.prev_z);
    // Static: a = T_prev_curr b. Moving: the world point moved by `motion` in between.
    const Eigen::Vector3d expected =
        static_cell[i] ? Eigen::Vector3d(T_world_curr * b)
                       : Eigen::Vector3d(motion.inverse() * (T_world_curr * b));
    EXPECT_LT((a - expected).norm(), 1e-5) << "cell " << i;
    (static_cell[i] ? still : moving) += 1;
  }
  EXPECT_GT(moving, 0u);
  EXPECT_GT(still, moving);
}

} // namespace
