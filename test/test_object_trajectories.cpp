// SPDX-License-Identifier: BSD-3-Clause
// Object-to-world trajectories composed from camera poses and segment motions, and the
// objects folder (dynvo_odometry -objects_dir).
#include <dynvo/app/object_trajectories.h>

#include <pcl/exceptions.h>

#include <gtest/gtest.h>

#include "support/pose_compare.h"
#include "support/temp_dir.h"

#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>
#include <tuple>

namespace {

using dynvo::test::makePose;

/// Camera and object moving over a sequence; the frames give what the pipeline would.
class MovingObject : public ::testing::Test {
protected:
  static Eigen::Isometry3d camera(int k)
  {
    return makePose({0.1, 1.0, 0.2}, 0.01 * k, {0.02 * k, -0.005 * k, 0.01 * k});
  }

  /// The object rests (frames 3-6) between two stretches of motion.
  static Eigen::Isometry3d object(int k)
  {
    const int t = k < 4 ? k : (k <= 6 ? 3 : k - 3);
    return makePose({1.0, 0.3, 0.0}, 0.05 * t, {0.3 - 0.04 * t, 0.1, 2.0 + 0.01 * t});
  }

  /// The object's three points (object frame, metres).
  const std::vector<Eigen::Vector3d> points_{
      {0.1, 0.0, 0.0}, {-0.1, 0.2, 0.05}, {0.0, -0.2, -0.05}};

  /// Frame k: cloud with the object's points and a NaN point, its segment unless
  /// `visible` is false, its motion T_curr_prev = inv(C_k) O_k inv(O_k-1) C_k-1.
  dynvo::app::FrameResult
  frame(int k, bool visible, pcl::PointCloud<pcl::PointXYZRGB>& cloud) const
  {
    cloud = pcl::PointCloud<pcl::PointXYZRGB>(4, 1);
    const Eigen::Isometry3d T_camera_object = camera(k).inverse() * object(k);
    for (std::size_t i = 0; i < points_.size(); ++i)
      cloud[i].getVector3fMap() = (T_camera_object * points_[i]).cast<float>();
    cloud[3].x = cloud[3].y = cloud[3].z = std::numeric_limits<float>::quiet_NaN();
    dynvo::app::FrameResult result;
    result.timestamp = 10.0 + k / 30.0;
    result.T_world_curr = camera(k).matrix();
    result.segments.resize(1);
    result.segment_labels = {1};
    result.motions.push_back(Eigen::Matrix4f::Identity());
    if (visible && k > 0) {
      pcl::PointIndices segment;
      segment.indices = {0, 1, 2, 3};
      result.segments.push_back(segment);
      result.segment_labels.push_back(5);
      result.motions.push_back(
          (camera(k).inverse() * object(k) * object(k - 1).inverse() * camera(k - 1))
              .matrix()
              .cast<float>());
    }
    return result;
  }
};

TEST_F(MovingObject, PosesFollowTheObjectFromItsFirstCentroidWithCameraAxes)
{
  dynvo::app::ObjectTrajectories objects;
  const int frames = 12;
  for (int k = 0; k < frames; ++k) {
    pcl::PointCloud<pcl::PointXYZRGB> cloud;
    // Not segmented while it rests (frames 4-6), as the segmentation does.
    const auto result = frame(k, k < 4 || k > 6, cloud);
    objects.add(result, cloud, camera(k));
  }
  // Id 5 comes back after frames without it: a second run with its own object frame.
  ASSERT_EQ(objects.tracks().size(), 2u);
  const Eigen::Vector3d centroid = (points_[0] + points_[1] + points_[2]) / 3.0;
  for (const auto& [run, first, last] : {std::tuple{1, 1, 3}, std::tuple{2, 7, 11}}) {
    const auto& track = objects.tracks()[run - 1];
    EXPECT_EQ(track.id, 5);
    EXPECT_EQ(track.run, run);
    ASSERT_EQ(track.poses.size(), static_cast<std::size_t>(last - first + 1));
    // The run's first frame defines the object frame: the centroid of the finite points
    // (the NaN point is skipped), camera axes.
    const Eigen::Isometry3d T_object_frame =
        object(first).inverse() * camera(first) *
        Eigen::Translation3d(camera(first).inverse() * object(first) * centroid);
    for (int k = first; k <= last; ++k) {
      const auto& pose = track.poses[k - first];
      EXPECT_DOUBLE_EQ(pose.timestamp, 10.0 + k / 30.0);
      // Float motions (7 digits) over at most 4 compositions: well under 10 um.
      const Eigen::Isometry3d expected = object(k) * T_object_frame;
      EXPECT_LT(dynvo::test::translationError(pose.T_world_camera.matrix(),
                                              expected.matrix()),
                1e-5)
          << "frame " << k;
      EXPECT_LT(
          dynvo::test::rotationError(pose.T_world_camera.matrix(), expected.matrix()),
          1e-5)
          << "frame " << k;
    }
    // The path is the sum of the origin's steps; every step here is faster than
    // 0.05 m/s (4 cm per frame in x).
    double path = 0.0;
    for (std::size_t j = 1; j < track.poses.size(); ++j)
      path += (track.poses[j].T_world_camera.translation() -
               track.poses[j - 1].T_world_camera.translation())
                  .norm();
    EXPECT_NEAR(track.path_length, path, 1e-12);
    EXPECT_GT(path, 0.07); // at least two steps of 4 cm
    EXPECT_EQ(track.frames_moving, track.poses.size() - 1);
    EXPECT_NEAR(track.meanSpeed(),
                path / (track.poses.back().timestamp - track.poses.front().timestamp),
                1e-12);
  }
}

TEST_F(MovingObject, FolderRoundTripsAndTheSummaryIsItsIndex)
{
  dynvo::app::ObjectTrajectories objects;
  dynvo::Trajectory cameras;
  for (int k = 0; k < 6; ++k) {
    pcl::PointCloud<pcl::PointXYZRGB> cloud;
    const auto result = frame(k, true, cloud);
    objects.add(result, cloud, camera(k));
    cameras.push_back({result.timestamp, camera(k)});
  }
  dynvo::test::TempDir dir;
  // A file of an earlier run in the folder is not an object of this one.
  dynvo::test::writeText(dir.file("object_9_1.txt"), "1.0 0 0 0 0 0 0 1\n");
  dynvo::app::writeObjectsFolder(dir.path().string(), objects.tracks(), cameras);
  const auto folder = dynvo::app::readObjectsFolder(dir.path().string());
  ASSERT_EQ(folder.objects.size(), 1u);
  const auto& track = objects.tracks().front();
  const auto& read = folder.objects.front();
  EXPECT_EQ(read.id, 5);
  EXPECT_EQ(read.run, 1);
  EXPECT_EQ(read.frames_moving, track.frames_moving);
  EXPECT_NEAR(read.path_length, track.path_length, 1e-6); // "%.6f"
  EXPECT_GT(read.path_length, 0.07); // two steps of about 4 cm (it rests from frame 3)
  ASSERT_EQ(read.poses.size(), track.poses.size());
  for (std::size_t i = 0; i < read.poses.size(); ++i) // 9 decimals in the file
    EXPECT_LT(dynvo::test::translationError(read.poses[i].T_world_camera.matrix(),
                                            track.poses[i].T_world_camera.matrix()),
              1e-8);
  EXPECT_EQ(folder.camera.size(), cameras.size());

  // The summary line: id run first last seen moving mean_speed path_length.
  std::ifstream summary(dir.file("objects_summary.txt"));
  std::string line;
  while (std::getline(summary, line) && line[0] == '#') {
  }
  std::istringstream fields(line);
  int id = 0, run = 0;
  double first = 0, last = 0, speed = 0, length = 0;
  std::size_t seen = 0, moving = 0;
  ASSERT_TRUE(fields >> id >> run >> first >> last >> seen >> moving >> speed >>
              length);
  EXPECT_NEAR(first, track.poses.front().timestamp, 1e-6);
  EXPECT_NEAR(last, track.poses.back().timestamp, 1e-6);
  EXPECT_EQ(seen, track.poses.size());
  EXPECT_NEAR(speed, track.meanSpeed(), 1e-6);
}

TEST(ObjectsFolder, MissingSummaryNamesTheFile)
{
  dynvo::test::TempDir dir;
  try {
    dynvo::app::readObjectsFolder(dir.path().string());
    FAIL() << "no exception";
  }
  catch (const pcl::IOException& e) {
    EXPECT_NE(std::string(e.what()).find("objects_summary.txt"), std::string::npos)
        << e.what();
  }
}

} // namespace
