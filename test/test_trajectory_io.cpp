// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/io/trajectory_io.h>

#include <pcl/exceptions.h>

#include <gtest/gtest.h>

#include "support/temp_dir.h"

#include <filesystem>

namespace {

using dynvo::test::TempDir;
using dynvo::test::writeText;

/// Expects readTrajectory to throw a message containing file:line and the problem.
void
expectReadError(const std::string& text, int line, const std::string& problem)
{
  TempDir dir;
  const std::string path = dir.file("bad.txt");
  writeText(path, text);
  try {
    dynvo::readTrajectory(path);
    FAIL() << "expected pcl::IOException for:\n" << text;
  }
  catch (const pcl::IOException& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(path + ":" + std::to_string(line) + ":"), std::string::npos)
        << message;
    EXPECT_NE(message.find(problem), std::string::npos) << message;
  }
}

TEST(TrajectoryIo, WriteThenReadRoundTrips)
{
  dynvo::Trajectory trajectory(3);
  for (int k = 0; k < 3; ++k) {
    trajectory[k].timestamp = 1305031102.175304 + 0.033 * k;
    trajectory[k].T_world_camera =
        Eigen::Translation3d(0.1 * k, -0.2, 1.5) *
        Eigen::AngleAxisd(0.3 * k, Eigen::Vector3d(1, 2, 3).normalized());
  }
  TempDir dir;
  dynvo::writeTrajectory(dir.file("t.txt"), trajectory);
  EXPECT_FALSE(std::filesystem::exists(dir.file("t.txt.partial")));
  const dynvo::Trajectory loaded = dynvo::readTrajectory(dir.file("t.txt"));
  ASSERT_EQ(loaded.size(), 3u);
  for (int k = 0; k < 3; ++k) {
    // Stamps are written with 6 decimals (microseconds), poses with 9.
    EXPECT_NEAR(loaded[k].timestamp, trajectory[k].timestamp, 1e-6);
    EXPECT_TRUE(loaded[k].T_world_camera.isApprox(trajectory[k].T_world_camera, 1e-8));
  }
}

TEST(TrajectoryIo, CommentsBlankLinesAndCommasAreAccepted)
{
  TempDir dir;
  writeText(dir.file("t.txt"),
            "# header\n\n1.0 0 0 0 0 0 0 1\n  \n2.0,1,2,3,0,0,0,1\n");
  const auto loaded = dynvo::readTrajectory(dir.file("t.txt"));
  ASSERT_EQ(loaded.size(), 2u);
  EXPECT_DOUBLE_EQ(loaded[1].T_world_camera.translation().z(), 3.0);
}

TEST(TrajectoryIo, QuaternionIsNormalisedWithinTolerance)
{
  TempDir dir;
  // Norm 1.0005 is within the 1e-3 tolerance (rounding in files written with few digits).
  writeText(dir.file("t.txt"), "1.0 0 0 0 0 0 0 1.0005\n");
  const auto loaded = dynvo::readTrajectory(dir.file("t.txt"));
  EXPECT_TRUE(
      loaded[0].T_world_camera.linear().isApprox(Eigen::Matrix3d::Identity(), 1e-12));
}

TEST(TrajectoryIo, EveryViolationNamesFileAndLine)
{
  expectReadError("1 0 0 0 0 0 0 1\n2 0 0 0 0 0 1\n", 2, "expected 8 numbers");
  expectReadError("# c\n1 0 0 0 0 0 0 1 5\n", 2, "expected 8 numbers");
  expectReadError("1 0 0 x 0 0 0 1\n", 1, "'x' is not a finite decimal number");
  expectReadError("1 0 0 nan 0 0 0 1\n", 1, "'nan' is not a finite decimal number");
  expectReadError("0x1p3 0 0 0 0 0 0 1\n", 1, "'0x1p3' is not a finite decimal number");
  // Squares of such values overflow the metrics (dynvo_evaluate printed inf).
  expectReadError("1 1e200 0 0 0 0 0 1\n", 1, "'1e200' is out of range");
  expectReadError("1 0 0 0 0 0 0 1\n\n1 0 0 0 0 0 0 1\n", 3, "does not increase");
  expectReadError("1 0 0 0 0 0 0 1\n0.5 0 0 0 0 0 0 1\n", 2, "does not increase");
  expectReadError("1 0 0 0 0 0 0 0.9\n", 1, "quaternion norm");
}

TEST(TrajectoryIo, MissingFileIsAnError)
{
  EXPECT_THROW(dynvo::readTrajectory("/nonexistent/trajectory.txt"), pcl::IOException);
}

TEST(TrajectoryIo, FormatKeepsQwNonNegative)
{
  dynvo::StampedPose pose;
  pose.timestamp = 3.5;
  // A rotation of 350 degrees: Eigen may produce qw < 0; the file must show qw >= 0.
  pose.T_world_camera.linear() =
      Eigen::AngleAxisd(350.0 * M_PI / 180.0, Eigen::Vector3d::UnitZ())
          .toRotationMatrix();
  const std::string line = dynvo::formatTumLine(pose);
  double t, x, y, z, qx, qy, qz, qw;
  ASSERT_EQ(std::sscanf(line.c_str(), "%lf %lf %lf %lf %lf %lf %lf %lf", &t, &x, &y, &z,
                        &qx, &qy, &qz, &qw),
            8);
  EXPECT_GE(qw, 0.0);
  EXPECT_DOUBLE_EQ(t, 3.5);
}

} // namespace
