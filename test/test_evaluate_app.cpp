// SPDX-License-Identifier: BSD-3-Clause
// dynvo_evaluate as users run it: output format, options and exit codes.
#include <dynvo/io/trajectory_io.h>

#include <gtest/gtest.h>

#include "support/run_command.h"
#include "support/temp_dir.h"

#include <regex>

namespace {

using dynvo::test::runCommand;
using dynvo::test::TempDir;

class EvaluateApp : public ::testing::Test {
protected:
  void SetUp() override
  {
    // 4 s at 30 Hz; the estimate drifts 3 cm/s along x relative to the ground truth.
    dynvo::Trajectory gt, est;
    for (int k = 0; k <= 120; ++k) {
      dynvo::StampedPose pose;
      pose.timestamp = 10.0 + k / 30.0;
      pose.T_world_camera.translation() = Eigen::Vector3d(0.0, 0.1 * k / 30.0, 0.0);
      gt.push_back(pose);
      pose.T_world_camera.translation().x() = 0.03 * k / 30.0;
      est.push_back(pose);
    }
    dynvo::writeTrajectory(gt_ = dir_.file("gt.txt"), gt);
    dynvo::writeTrajectory(est_ = dir_.file("est.txt"), est);
  }

  TempDir dir_;
  std::string gt_, est_;
  const std::string app_ = DYNVO_EVALUATE_BIN;
};

TEST_F(EvaluateApp, PrintsOneLineWithEveryMetric)
{
  const auto result = runCommand(app_ + " " + gt_ + " " + est_);
  ASSERT_EQ(result.exit_code, 0) << result.err;
  std::smatch m;
  const std::regex line("rpe_trans_rmse=([0-9.]+) rpe_trans_mean=([0-9.]+) "
                        "rpe_rot_rmse=([0-9.]+) ate_rmse=([0-9.]+) pairs=([0-9]+)\n");
  ASSERT_TRUE(std::regex_match(result.out, m, line)) << result.out;
  // 3 cm/s of drift over the 1 s delta; the value is printed with 6 decimals.
  EXPECT_NEAR(std::stod(m[1]), 0.03, 1e-6);
  EXPECT_NEAR(std::stod(m[2]), 0.03, 1e-6);
  EXPECT_NEAR(std::stod(m[3]), 0.0, 1e-6);
  // 121 poses: pose i pairs with i + 30 unless that is the last pose.
  EXPECT_EQ(m[5], "90");
}

TEST_F(EvaluateApp, JsonAndDeltaOptions)
{
  const auto json =
      runCommand(app_ + " " + gt_ + " " + est_ + " -json -delta 15 -delta_unit f");
  ASSERT_EQ(json.exit_code, 0) << json.err;
  // Half a second of drift at 3 cm/s.
  EXPECT_NE(json.out.find("\"rpe_trans_rmse\": 0.015000"), std::string::npos)
      << json.out;
  EXPECT_NE(json.out.find("\"pairs\": 105"), std::string::npos) << json.out;
}

TEST_F(EvaluateApp, BadInputExitsNonZeroNamingTheProblem)
{
  const auto missing = runCommand(app_ + " " + gt_ + " " + dir_.file("none.txt"));
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.err.find("none.txt"), std::string::npos) << missing.err;

  dynvo::test::writeText(dir_.file("bad.txt"), "1 2 3\n");
  const auto corrupt = runCommand(app_ + " " + gt_ + " " + dir_.file("bad.txt"));
  EXPECT_EQ(corrupt.exit_code, 1);
  EXPECT_NE(corrupt.err.find("bad.txt:1: expected 8 numbers"), std::string::npos)
      << corrupt.err;

  EXPECT_EQ(runCommand(app_ + " " + gt_ + " " + est_ + " -bogus").exit_code, 2);
  EXPECT_EQ(runCommand(app_ + " " + gt_).exit_code, 2);
  EXPECT_EQ(runCommand(app_ + " " + gt_ + " " + est_ + " -delta_unit m").exit_code, 2);
  EXPECT_EQ(runCommand(app_ + " " + gt_ + " " + est_ + " -delta abc").exit_code, 2);
  EXPECT_EQ(runCommand(app_ + " -h").exit_code, 0);
}

} // namespace
