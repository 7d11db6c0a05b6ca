// SPDX-License-Identifier: BSD-3-Clause
// Grid scene flow on real TUM fr1/xyz frames (skipped when the shared data is absent,
// failed under CI=true).
#include <dynvo/io/trajectory_io.h>
#include <dynvo/io/tum_folder_source.h>
#include <dynvo/scene_flow/grid_scene_flow_estimation.h>

#include <pcl/point_types.h>

#include <gtest/gtest.h>

#include "support/shared_data.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <stdexcept>
#include <vector>

namespace {

const std::string FOLDER = dynvo::test::sharedDataPath("tum_fr1_xyz_200");

/// Ground-truth camera-to-world pose at time t (the 100 Hz samples around it).
Eigen::Isometry3d
groundTruthAt(const dynvo::Trajectory& trajectory, double t)
{
  const auto pose = dynvo::interpolatePose(trajectory, t, 0.25);
  if (!pose)
    throw std::out_of_range("no ground truth around t = " + std::to_string(t));
  return *pose;
}

class TumFlowTest : public ::testing::TestWithParam<std::size_t> {
protected:
  void SetUp() override
  {
    DYNVO_REQUIRE_SHARED_DATA(FOLDER + "/groundtruth.txt");
    dynvo::TumFolderSource::Options options;
    options.intrinsics = dynvo::CameraIntrinsics::fromPreset("fr1");
    source_ = std::make_unique<dynvo::TumFolderSource>(FOLDER, options);
    estimation_.setCameraIntrinsics(options.intrinsics);
  }

  std::unique_ptr<dynvo::TumFolderSource> source_;
  dynvo::GridSceneFlowEstimation<pcl::PointXYZRGB> estimation_;
};

TEST_P(TumFlowTest, MostCellsAreValidAndAgreeWithTheGroundTruthMotion)
{
  const std::size_t k = GetParam();
  const dynvo::Frame previous = source_->read(k - 1);
  const dynvo::Frame current = source_->read(k);
  estimation_.setPreviousCloud(previous.cloud);
  estimation_.setInputCloud(current.cloud);
  pcl::PointCloud<dynvo::PointFlow> flow;
  estimation_.compute(flow);
  ASSERT_EQ(flow.size(), 1200u);

  const dynvo::Trajectory truth = dynvo::readTrajectory(FOLDER + "/groundtruth.txt");
  const Eigen::Isometry3d T_curr_prev =
      groundTruthAt(truth, current.timestamp).inverse() *
      groundTruthAt(truth, previous.timestamp);
  std::size_t tracked = 0, with_depth = 0, tracked_without_depth = 0;
  std::vector<double> error;
  for (const dynvo::PointFlow& f : flow) {
    tracked += f.valid_2d;
    with_depth += std::isfinite(f.z);
    tracked_without_depth += f.valid_2d && !std::isfinite(f.z);
    if (!f.valid_3d)
      continue;
    const Eigen::Vector3d a(f.prev_x, f.prev_y, f.prev_z);
    error.push_back((T_curr_prev * a - f.getVector3fMap().cast<double>()).norm());
  }
  // About a quarter of the fr1 image has no depth at all (top rows, right border). Only cells
  // with depth at their centre are tracked (the others give no 3D flow), so both shares are
  // taken over those: 82-85 % of them pass LK and the check on these pairs, 78-82 % also have
  // depth at p_i; the misses are blank walls and occlusion borders.
  EXPECT_EQ(tracked_without_depth, 0u);
  EXPECT_GE(tracked, with_depth * 3 / 4);
  EXPECT_GE(error.size(), with_depth * 7 / 10);
  ASSERT_FALSE(error.empty());
  std::nth_element(error.begin(), error.begin() + error.size() / 2, error.end());
  const double median = error[error.size() / 2];
  RecordProperty("median_error_mm", std::to_string(median * 1000.0));
  // 2 cm: Kinect depth noise at 0.6-1.2 m (~2-6 mm), uncorrected lens distortion (up to a few
  // px at the borders) and motion-capture timing (~0.1-0.5 mm per ms at this speed).
  EXPECT_LT(median, 0.02);
}

// Evenly spaced pairs of the clip; none falls on one of its motion-blurred frames.
INSTANTIATE_TEST_SUITE_P(Fr1Xyz, TumFlowTest, ::testing::Values(40, 80, 120, 160));

} // namespace
