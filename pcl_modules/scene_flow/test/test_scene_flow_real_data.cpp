// SPDX-License-Identifier: BSD-3-Clause
// Grid scene flow on real TUM fr1/xyz frames (skipped when the shared data is absent).
#include <dynvo/io/trajectory_io.h>
#include <dynvo/io/tum_folder_source.h>
#include <dynvo/scene_flow/grid_scene_flow_estimation.h>

#include <pcl/point_types.h>

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace {

const std::string FOLDER = std::string(DYNVO_SHARED_DATA_DIR) + "/tum_fr1_xyz_200";

/// Ground-truth camera-to-world pose at time t: linear in translation, slerp in rotation
/// between the two bracketing 100 Hz samples.
Eigen::Isometry3d
groundTruthAt(const dynvo::Trajectory& trajectory, double t)
{
  const auto after = std::lower_bound(trajectory.begin(), trajectory.end(), t,
                                      [](const dynvo::StampedPose& pose, double stamp) {
                                        return pose.timestamp < stamp;
                                      });
  if (after == trajectory.begin() || after == trajectory.end())
    throw std::out_of_range("no ground truth around t = " + std::to_string(t));
  const auto before = after - 1;
  const double s = (t - before->timestamp) / (after->timestamp - before->timestamp);
  const Eigen::Quaterniond q0(before->T_world_camera.linear());
  const Eigen::Quaterniond q1(after->T_world_camera.linear());
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = q0.slerp(s, q1).toRotationMatrix();
  T.translation() = (1.0 - s) * before->T_world_camera.translation() +
                    s * after->T_world_camera.translation();
  return T;
}

class TumFlowTest : public ::testing::TestWithParam<std::size_t> {
protected:
  void SetUp() override
  {
    if (!std::filesystem::exists(FOLDER + "/groundtruth.txt"))
      GTEST_SKIP() << "shared data not found at " << FOLDER;
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
  std::size_t tracked = 0, with_depth = 0;
  std::vector<double> error;
  for (const dynvo::PointFlow& f : flow) {
    tracked += f.valid_2d;
    with_depth += std::isfinite(f.z);
    if (!f.valid_3d)
      continue;
    const Eigen::Vector3d a(f.prev_x, f.prev_y, f.prev_z);
    error.push_back((T_curr_prev * a - f.getVector3fMap().cast<double>()).norm());
  }
  // About a quarter of the fr1 image has no depth at all (top rows, right border), so the 3D
  // share is taken over the cells that have depth at their centre.
  EXPECT_GE(tracked, flow.size() * 7 / 10);
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
