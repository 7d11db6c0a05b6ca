// SPDX-License-Identifier: BSD-3-Clause
// dynvo_evaluate as users run it: output format, options and exit codes.
#include <dynvo/io/label_io.h>
#include <dynvo/io/trajectory_io.h>
#include <dynvo/io/tum_folder_source.h>

#include <gtest/gtest.h>

#include "support/shared_data.h"
#include "support/run_command.h"
#include "support/temp_dir.h"

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <filesystem>
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

/** A 4 x 3 sequence of 4 frames at 30 Hz with ground-truth labels, and a prediction.
 *
 * Pixel 8 (row 2, column 0) has no depth in any frame. Frames 0-2: truth and prediction
 * of LabelMetrics.CountsOneFrameOnValidPixelsOnly (IoU 3/5, 5 of 6 predicted-static
 * pixels static, 5 of 7 static pixels found, 10 of 11 labelled), the object predicted as
 * 2, then 3, then 3 (one id switch in two pairs). Frame 3: truth all static, predicted
 * static but for pixel 3 (0). Hence moving_iou 0.6, static_precision (15 + 10) / (18 +
 * 10), static_recall 25 / (21 + 11), labelled 40 / 44, bg_ok 1 / 4, id_switch_rate 1 / 2.
 */
class EvaluateLabels : public ::testing::Test {
protected:
  void SetUp() override
  {
    namespace fs = std::filesystem;
    for (const char* sub : {"seq/rgb", "seq/depth", "seq/labels", "pred"})
      fs::create_directories(dir_.path() / sub);
    const std::vector<std::uint8_t> moving_truth{0, 0, 0, 0, 0, 0, 1, 1, 0, 0, 1, 1};
    std::string rgb_list, depth_list;
    for (int k = 0; k < 4; ++k) {
      const double stamp = 1.0 + k / 30.0;
      const std::string name = dynvo::stampedPngName(stamp);
      const std::string depth_name = dynvo::stampedPngName(stamp + 0.001);
      rgb_list += dynvo::formatStamp(stamp) + " rgb/" + name + "\n";
      depth_list += dynvo::formatStamp(stamp + 0.001) + " depth/" + depth_name + "\n";
      ASSERT_TRUE(cv::imwrite(dir_.file("seq/rgb/" + name),
                              cv::Mat(3, 4, CV_8UC3, cv::Scalar(90, 120, 150))));
      cv::Mat depth(3, 4, CV_16UC1, cv::Scalar(5000));
      depth.at<std::uint16_t>(2, 0) = 0;
      ASSERT_TRUE(cv::imwrite(dir_.file("seq/depth/" + depth_name), depth));
      const std::uint8_t id = k == 0 ? 2 : 3;
      dynvo::writeLabelImage(
          dir_.file("seq/labels/" + name),
          labels(k < 3 ? moving_truth : std::vector<std::uint8_t>(12)));
      writePrediction(name, k < 3 ? labels({1, 1, 1, 0, 1, id, id, 1, 1, 1, id, id})
                                  : labels({1, 1, 1, 0, 1, 1, 1, 1, 1, 1, 1, 1}));
    }
    dynvo::test::writeText(dir_.file("seq/rgb.txt"),
                           "# timestamp filename\n" + rgb_list);
    dynvo::test::writeText(dir_.file("seq/depth.txt"), depth_list);
  }

  static dynvo::LabelImage labels(std::vector<std::uint8_t> data)
  {
    return {4, 3, std::move(data)};
  }

  void writePrediction(const std::string& name, const dynvo::LabelImage& image) const
  {
    dynvo::writeLabelImage(dir_.file("pred/" + name), image);
  }

  dynvo::test::CommandResult run(const std::string& options = "") const
  {
    return runCommand(app_ + " -labels " + dir_.file("pred") + " -truth " +
                      dir_.file("seq") + options);
  }

  TempDir dir_;
  const std::string app_ = DYNVO_EVALUATE_BIN;
};

TEST_F(EvaluateLabels, PrintsTheHandCountedScores)
{
  const auto result = run();
  ASSERT_EQ(result.exit_code, 0) << result.err;
  // 25 / 28 = 0.892857, 25 / 32 = 0.78125, 40 / 44 = 0.909091.
  EXPECT_EQ(result.out, "moving_iou=0.600000 static_precision=0.892857 "
                        "static_recall=0.781250 labelled=0.909091 bg_ok=0.250000 "
                        "id_switch_rate=0.500000 frames=4\n");
  EXPECT_EQ(result.err, "");

  const auto json = run(" -json");
  ASSERT_EQ(json.exit_code, 0) << json.err;
  EXPECT_EQ(json.out, "{\"moving_iou\": 0.600000, \"static_precision\": 0.892857, "
                      "\"static_recall\": 0.781250, \"labelled\": 0.909091, "
                      "\"bg_ok\": 0.250000, \"id_switch_rate\": 0.500000, "
                      "\"frames\": 4}\n");
}

TEST_F(EvaluateLabels, PairsByNearestStampWithinFiveMillisecondsAndWarnsAboutTheRest)
{
  namespace fs = std::filesystem;
  // 1.7 ms off: still frame 1. Frame 3's prediction 10 ms off: not paired.
  fs::rename(dir_.file("pred/1.033333.png"), dir_.file("pred/1.035000.png"));
  fs::rename(dir_.file("pred/1.100000.png"), dir_.file("pred/1.110000.png"));
  const auto result = run();
  ASSERT_EQ(result.exit_code, 0) << result.err;
  // Without the static frame 3: precision 15 / 18, recall 15 / 21, labelled 30 / 33,
  // no frame with a good background.
  EXPECT_EQ(result.out, "moving_iou=0.600000 static_precision=0.833333 "
                        "static_recall=0.714286 labelled=0.909091 bg_ok=0.000000 "
                        "id_switch_rate=0.500000 frames=3\n");
  EXPECT_NE(result.err.find("1 of 4 frames"), std::string::npos) << result.err;
}

TEST_F(EvaluateLabels, WithoutTruthLabelsReportsTheMovingShareOfAStaticRecording)
{
  std::filesystem::remove_all(dir_.file("seq/labels"));
  const auto result = run();
  ASSERT_EQ(result.exit_code, 0) << result.err;
  // 4 moving-labelled pixels in each of frames 0-2 among 40 labelled pixels.
  EXPECT_EQ(result.out, "moving_share=0.300000 labelled=0.909091 frames=4\n");
  const auto json = run(" -json");
  EXPECT_EQ(json.out,
            "{\"moving_share\": 0.300000, \"labelled\": 0.909091, \"frames\": 4}\n");
}

TEST(EvaluateLabelsRealData, AllStaticPredictionOnTumFr1XyzHasNoMovingShare)
{
  const auto sequence =
      std::filesystem::path(dynvo::test::sharedDataPath("tum_fr1_xyz_200"));
  DYNVO_REQUIRE_SHARED_DATA((sequence / "rgb.txt").string());
  // The first 5 frames predicted static everywhere, named as dynvo_odometry names them.
  TempDir dir;
  const dynvo::TumFolderSource source(sequence.string(), {});
  for (std::size_t i = 0; i < 5; ++i)
    dynvo::writeLabelImage(
        dir.file(dynvo::stampedPngName(source.entries()[i].rgb_stamp)),
        {640, 480, std::vector<std::uint8_t>(640 * 480, 1)});
  const auto result = runCommand(std::string(DYNVO_EVALUATE_BIN) + " -labels " +
                                 dir.path().string() + " -truth " + sequence.string());
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_EQ(result.out, "moving_share=0.000000 labelled=1.000000 frames=5\n");
  EXPECT_NE(result.err.find("195 of 200 frames"), std::string::npos) << result.err;
}

TEST_F(EvaluateLabels, BadInputExitsOneNamingTheFile)
{
  const auto expectFailure = [&](const std::string& file, const std::string& problem) {
    const auto result = run();
    EXPECT_EQ(result.exit_code, 1) << result.out;
    EXPECT_NE(result.err.find(file), std::string::npos) << result.err;
    EXPECT_NE(result.err.find(problem), std::string::npos) << result.err;
  };
  const std::string frame1 = "1.033333.png";

  // A prediction of another size than the truth names both files.
  writePrediction(frame1, {5, 3, std::vector<std::uint8_t>(15, 1)});
  expectFailure(dir_.file("pred/" + frame1), "is 4x3");
  expectFailure(dir_.file("seq/labels/" + frame1), "label image is 5x3");

  ASSERT_TRUE(cv::imwrite(dir_.file("pred/" + frame1), cv::Mat(3, 4, CV_8UC3)));
  expectFailure(dir_.file("pred/" + frame1), "must be 8-bit single channel");
  dynvo::test::writeText(dir_.file("pred/" + frame1), "not a png");
  expectFailure(dir_.file("pred/" + frame1), "cannot read label image");
  writePrediction(frame1, labels(std::vector<std::uint8_t>(12, 1)));

  std::filesystem::remove(dir_.file("seq/labels/" + frame1));
  expectFailure(dir_.file("seq/labels/" + frame1), "cannot read label image");

  dynvo::test::writeText(dir_.file("pred/legend.png"), "");
  expectFailure(dir_.file("pred/legend.png"), "not a timestamp");
  std::filesystem::remove_all(dir_.file("pred"));
  expectFailure(dir_.file("pred"), "not a directory");
  std::filesystem::create_directories(dir_.file("pred"));
  expectFailure(dir_.file("pred"), "no label PNGs");
  writePrediction("5.000000.png", labels(std::vector<std::uint8_t>(12, 1)));
  expectFailure(dir_.file("pred"), "no label PNG is within 0.005000 s");

  std::filesystem::remove(dir_.file("seq/depth.txt"));
  expectFailure(dir_.file("seq/depth.txt"), "cannot open");
}

TEST_F(EvaluateLabels, UsageErrorsExitTwo)
{
  const std::string pred = " -labels " + dir_.file("pred");
  const std::string truth = " -truth " + dir_.file("seq");
  EXPECT_EQ(runCommand(app_ + pred).exit_code, 2);
  EXPECT_EQ(runCommand(app_ + truth).exit_code, 2);
  EXPECT_EQ(runCommand(app_ + pred + truth + " extra.txt").exit_code, 2);
  EXPECT_EQ(runCommand(app_ + pred + truth + " -delta 2").exit_code, 2);
  EXPECT_EQ(runCommand(app_ + " a.txt b.txt" + truth).exit_code, 2);
  const auto help = runCommand(app_ + " -h");
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_NE(help.out.find("-labels PRED_DIR -truth SEQ_DIR"), std::string::npos);
}

/// A synthetic sequence's truth (groundtruth.txt, objects.txt) and a hand-made objects
/// folder: the estimate is the truth in another world (A: the camera at frame 0) with
/// other object frames, so its object 4 tracks true object 2 exactly.
class EvaluateObjects : public ::testing::Test {
protected:
  static Eigen::Isometry3d trueObject(int id, double t)
  {
    return Eigen::Translation3d(id == 1 ? -1.0 : 0.2 + 0.3 * t, 0.1 * id,
                                2.0 + 0.1 * t) *
           Eigen::AngleAxisd(0.5 * t * id, Eigen::Vector3d(0.2, 1.0, 0.1).normalized());
  }

  void SetUp() override
  {
    std::filesystem::create_directories(dir_.file("seq"));
    std::filesystem::create_directories(dir_.file("objects"));
    dynvo::Trajectory camera_truth, camera_estimate, object_4, far_away;
    std::string objects = "# timestamp id tx ty tz qx qy qz qw moving\n";
    const Eigen::Isometry3d A(Eigen::Translation3d(0.1, -0.2, 0.3) *
                              Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitY()));
    const Eigen::Isometry3d B(Eigen::Translation3d(0.05, -0.1, -0.2) *
                              Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitX()));
    for (int k = 0; k < 60; ++k) { // 2 s at 30 Hz
      const double t = 1.0 + k / 30.0;
      const Eigen::Isometry3d camera =
          A * Eigen::Translation3d(0.05 * k / 30.0, 0.0, 0.0);
      camera_truth.push_back({t, camera});
      camera_estimate.push_back({t, A.inverse() * camera});
      for (int id : {1, 2}) {
        std::string line = dynvo::formatTumLine({t, trueObject(id, t)});
        line.insert(line.find(' '), " " + std::to_string(id));
        objects += line + " 1\n";
      }
      if (k >= 5)
        object_4.push_back({t, A.inverse() * trueObject(2, t) * B});
      if (k >= 10 && k < 20) // 3 m from every object, tracked under 1 s
        far_away.push_back({t, Eigen::Isometry3d(Eigen::Translation3d(0.0, 0.0, 5.0))});
    }
    dynvo::writeTrajectory(dir_.file("seq/groundtruth.txt"), camera_truth);
    dynvo::test::writeText(dir_.file("seq/objects.txt"), objects);
    dynvo::writeTrajectory(dir_.file("objects/camera.txt"), camera_estimate);
    dynvo::writeTrajectory(dir_.file("objects/object_4_1.txt"), object_4);
    dynvo::writeTrajectory(dir_.file("objects/object_7_2.txt"), far_away);
    dynvo::test::writeText(
        dir_.file("objects/objects_summary.txt"),
        "# id run first_stamp last_stamp frames_seen frames_moving "
        "mean_speed path_length\n4 1 0 0 55 0 0 0\n7 2 0 0 10 0 0 0\n");
  }

  TempDir dir_;
  const std::string app_ = DYNVO_EVALUATE_BIN;
};

TEST_F(EvaluateObjects, ScoresEachObjectAgainstTheNearestTrueObject)
{
  const auto result = runCommand(app_ + " -objects_dir " + dir_.file("objects") +
                                 " -truth " + dir_.file("seq"));
  ASSERT_EQ(result.exit_code, 0) << result.err;
  // Object 4 is true object 2 seen from another world with another object frame: zero
  // error (the files hold 9 decimals). Its origin is B's offset (0.23 m) from the true
  // object's. 55 frames over 1.8 s: the 1 s pairs of its first 24 frames.
  EXPECT_TRUE(std::regex_search(
      result.out,
      std::regex(
          "object=4 run=1 truth=2 frames=55 seconds=1.8[0-9]* distance=0.229[0-9]* "
          "rpe_trans_rmse=0.00000[0-9] pairs=24\n")))
      << result.out;
  EXPECT_NE(result.out.find("object=7 run=2 truth=none frames=10 "), std::string::npos)
      << result.out;
  EXPECT_TRUE(std::regex_search(
      result.out, std::regex("objects=2 scored=1 max_rpe_trans_rmse=0.00000[0-9]\n")))
      << result.out;
  const auto json = runCommand(app_ + " -json -objects_dir " + dir_.file("objects") +
                               " -truth " + dir_.file("seq"));
  ASSERT_EQ(json.exit_code, 0) << json.err;
  EXPECT_NE(json.out.find("\"object\": 7, \"run\": 2, \"truth\": null"),
            std::string::npos)
      << json.out;
  EXPECT_NE(json.out.find("\"scored\": 1"), std::string::npos) << json.out;
}

TEST_F(EvaluateObjects, UsageAndInputErrors)
{
  const std::string objects = " -objects_dir " + dir_.file("objects");
  const std::string truth = " -truth " + dir_.file("seq");
  EXPECT_EQ(runCommand(app_ + objects).exit_code, 2);
  EXPECT_EQ(runCommand(app_ + objects + truth + " -delta 2").exit_code, 2);
  EXPECT_EQ(runCommand(app_ + objects + truth + " -labels " + dir_.file("x")).exit_code,
            2);
  std::filesystem::remove(dir_.file("seq/objects.txt"));
  const auto missing = runCommand(app_ + objects + truth);
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.err.find("objects.txt"), std::string::npos) << missing.err;
}

} // namespace
