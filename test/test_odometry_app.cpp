// SPDX-License-Identifier: BSD-3-Clause
// dynvo_odometry as users run it: outputs, closing lines, determinism and bad input.
#include <dynvo/app/object_trajectories.h>
#include <dynvo/app/pipeline_config.h>
#include <dynvo/app/run_report.h>
#include <dynvo/eval/trajectory_metrics.h>
#include <dynvo/io/image_io.h>
#include <dynvo/io/label_io.h>
#include <dynvo/io/trajectory_io.h>

#include <pcl/io/pcd_io.h>
#include <pcl/point_types.h>

#include <gtest/gtest.h>

#include "support/run_command.h"
#include "support/synthetic_sequence.h"
#include "support/temp_dir.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>

namespace {

namespace fs = std::filesystem;
using dynvo::test::runCommand;
using dynvo::test::TempDir;

class OdometryApp : public ::testing::Test {
protected:
  static void SetUpTestSuite()
  {
    sequence_ = new dynvo::test::SyntheticSequence("static_one", FRAMES, 640, 480);
  }

  static void TearDownTestSuite() { delete sequence_; }

  /// Copies the sequence to out_/seq and returns the images of one of its folders ("rgb",
  /// "depth") in frame order, for a test to spoil one.
  std::vector<fs::path> copySequence(const std::string& folder) const
  {
    fs::copy(sequence_->path(), out_.file("seq"), fs::copy_options::recursive);
    std::vector<fs::path> images;
    for (const auto& entry : fs::directory_iterator(out_.file("seq") + "/" + folder))
      images.push_back(entry.path());
    std::sort(images.begin(), images.end());
    return images;
  }

  std::string run(const std::string& flags) const
  {
    return app_ + " -tum_dir " + sequence_->path() + " " + flags;
  }

  static constexpr int FRAMES = 35; // over 1 s at 30 Hz, so that RPE has pairs
  static dynvo::test::SyntheticSequence* sequence_;
  TempDir out_;
  const std::string app_ = DYNVO_ODOMETRY_BIN;
};

dynvo::test::SyntheticSequence* OdometryApp::sequence_ = nullptr;

TEST_F(OdometryApp, WritesTrajectoryLabelsObjectsAndClosingLines)
{
  const auto result =
      runCommand(run("-out " + out_.file("t.txt") + " -labels_dir " +
                     out_.file("labels") + " -objects " + out_.file("o.txt")));
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const auto trajectory = dynvo::readTrajectory(out_.file("t.txt"));
  ASSERT_EQ(trajectory.size(), static_cast<std::size_t>(FRAMES));
  EXPECT_TRUE(trajectory[0].T_world_camera.isApprox(Eigen::Isometry3d::Identity()));
  // One label image per frame, named by the colour stamp, the size of the input.
  std::size_t images = 0;
  for (const auto& entry : fs::directory_iterator(out_.file("labels"))) {
    const auto labels = dynvo::readLabelImage(entry.path().string());
    EXPECT_EQ(labels.width, 640u);
    EXPECT_EQ(labels.height, 480u);
    ++images;
  }
  EXPECT_EQ(images, static_cast<std::size_t>(FRAMES));
  EXPECT_TRUE(fs::exists(out_.file("labels") + "/" +
                         dynvo::stampedPngName(trajectory[3].timestamp)));
  EXPECT_TRUE(fs::exists(out_.file("o.txt")));
  EXPECT_FALSE(fs::exists(out_.file("o.txt.partial")));
  // The folder has a ground truth, so the evaluate line comes before the summary line.
  EXPECT_TRUE(std::regex_search(result.out,
                                std::regex("rpe_trans_rmse=[0-9.]+ .*pairs=[0-9]+\n")))
      << result.out;
  EXPECT_TRUE(std::regex_search(
      result.out, std::regex("frames=35 lost=[0-9]+ median_ms=[0-9.]+ mean_ms=[0-9.]+ "
                             "fps=[0-9.]+\n$")))
      << result.out;
}

TEST_F(OdometryApp, SameSeedSameBytesWithOneAndTwoThreads)
{
  // A moving camera (the fixture's camera stands still, where a run that lost every frame
  // would write identity poses with any thread count).
  const int frames = 10;
  const dynvo::test::SyntheticSequence moving("moving_static", frames, 640, 480);
  const std::string app = app_ + " -tum_dir " + moving.path();
  for (const char* threads : {"1", "2"}) {
    const auto result = runCommand(app + " -threads " + threads + " -out " +
                                   out_.file(std::string("t") + threads + ".txt"));
    ASSERT_EQ(result.exit_code, 0) << result.err;
    EXPECT_NE(result.out.find("frames=10 lost=0 "), std::string::npos) << result.out;
  }
  const auto one = dynvo::readTrajectory(out_.file("t1.txt"));
  ASSERT_EQ(one.size(), static_cast<std::size_t>(frames));
  // moving_static's camera moves about 0.1-0.3 m/s: over 0.3 s, centimetres.
  EXPECT_GT(one.back().T_world_camera.translation().norm(), 0.005);
  EXPECT_EQ(dynvo::test::readText(out_.file("t1.txt")),
            dynvo::test::readText(out_.file("t2.txt")));
}

TEST_F(OdometryApp, ConfigRoundTripsAndUnknownKeysAreRejected)
{
  ASSERT_EQ(
      runCommand(app_ + " -tum_dir x -write_config " + out_.file("c.yaml")).exit_code,
      0);
  const auto reread = runCommand(run("-max_frames 3 -config " + out_.file("c.yaml")));
  EXPECT_EQ(reread.exit_code, 0) << reread.err;
  EXPECT_NE(reread.out.find("frames=3 "), std::string::npos) << reread.out;

  dynvo::test::writeText(out_.file("bad.yaml"),
                         "%YAML:1.0\nsegmentation:\n  max_hypothesis: 3\n");
  const auto bad = runCommand(run("-config " + out_.file("bad.yaml")));
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_NE(bad.err.find("segmentation.max_hypothesis: unknown key"), std::string::npos)
      << bad.err;
}

TEST_F(OdometryApp, WrittenConfigReproducesTheRunForEveryField)
{
  // Flags and a file with every key of every table off its default: -write_config must
  // capture all of it, so that -config alone gives the same trajectory, byte for byte.
  dynvo::app::PipelineOptions changed;
  for (const auto& field : dynvo::app::pipelineConfigTable().fields()) {
    const double value = field.get(changed);
    const double other =
        field.kind == dynvo::FieldKind::choice
            ? std::fmod(value + 1.0, static_cast<double>(field.choices.size()))
            : (field.kind == dynvo::FieldKind::boolean ? 1.0 - value : value);
    field.set(changed, other);
  }
  changed.segmentation.max_hypotheses = 15; // and numbers, within the cross-field rules
  changed.registration.trim_rounds = 3;
  changed.scene_flow.depth.max_hole_width = 3;
  dynvo::app::writePipelineConfig(out_.file("changed.yaml"), changed);
  const auto succeeds = [this](const std::string& flags) {
    const auto result = runCommand(run(flags));
    EXPECT_EQ(result.exit_code, 0) << flags << "\n" << result.err;
    return result.exit_code == 0;
  };
  const std::string flags =
      "-max_frames 8 -seed 5 -threads 2 -config " + out_.file("changed.yaml");
  ASSERT_TRUE(succeeds(flags + " -out " + out_.file("a.txt")));
  ASSERT_TRUE(succeeds(flags + " -write_config " + out_.file("b.yaml")));
  const std::string reread = "-max_frames 8 -config " + out_.file("b.yaml");
  ASSERT_TRUE(succeeds(reread + " -out " + out_.file("b.txt")));
  EXPECT_EQ(dynvo::test::readText(out_.file("a.txt")),
            dynvo::test::readText(out_.file("b.txt")));
  EXPECT_FALSE(dynvo::test::readText(out_.file("a.txt")).empty());
  // Reading the written file and writing it again changes nothing.
  ASSERT_TRUE(succeeds(reread + " -write_config " + out_.file("c.yaml")));
  EXPECT_EQ(dynvo::test::readText(out_.file("b.yaml")),
            dynvo::test::readText(out_.file("c.yaml")));
}

TEST_F(OdometryApp, CorruptFrameStopsTheRunButKeepsWhatWasComputed)
{
  // Copy the sequence and corrupt the colour image of frame 6.
  const std::vector<fs::path> colour = copySequence("rgb");
  dynvo::test::writeText(colour[6].string(), "not a png");
  const auto result = runCommand(app_ + " -tum_dir " + out_.file("seq") + " -out " +
                                 out_.file("t.txt"));
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.err.find(colour[6].filename().string()), std::string::npos)
      << result.err;
  EXPECT_EQ(dynvo::readTrajectory(out_.file("t.txt")).size(), 6u);
}

TEST_F(OdometryApp, FramesReportSaysWhichFramesWereLostAndWhy)
{
  // Frame 10 of a copy has no depth at all: no static cell can be measured into it or out
  // of it, so it is lost for want of static cells; every other frame of this static camera
  // is registered, the one after against the keyframe kept before the empty frame.
  const std::vector<fs::path> depth = copySequence("depth");
  auto empty = dynvo::readRawDepthImage(depth[10].string());
  std::fill(empty.data.begin(), empty.data.end(), 0);
  dynvo::writeRawDepthImage(depth[10].string(), empty);
  const auto result =
      runCommand(app_ + " -tum_dir " + out_.file("seq") + " -out " +
                 out_.file("t.txt") + " -frames_report " + out_.file("frames.tsv"));
  ASSERT_EQ(result.exit_code, 0) << result.err;
  std::istringstream report(dynvo::test::readText(out_.file("frames.tsv")));
  std::string line;
  ASSERT_TRUE(std::getline(report, line));
  EXPECT_EQ(line,
            "# stamp\tlost\treason\tstatic_cells\tresidual_m2\tkeyframe\t"
            "moving_share\tscene_flow_ms\tsegmentation_ms\tregistration_ms\ttotal_ms");
  const auto trajectory = dynvo::readTrajectory(out_.file("t.txt"));
  std::vector<std::vector<std::string>> rows;
  while (std::getline(report, line)) {
    std::vector<std::string> columns;
    std::istringstream fields(line);
    for (std::string field; std::getline(fields, field, '\t');)
      columns.push_back(field);
    ASSERT_EQ(columns.size(), 11u) << line;
    rows.push_back(columns);
  }
  ASSERT_EQ(rows.size(), static_cast<std::size_t>(FRAMES));
  for (std::size_t k = 0; k < rows.size(); ++k) {
    EXPECT_NEAR(std::stod(rows[k][0]), trajectory[k].timestamp, 1e-6) << "frame " << k;
    const bool lost = k == 10;
    EXPECT_EQ(rows[k][1], lost ? "1" : "0") << "frame " << k;
    EXPECT_EQ(rows[k][2], lost ? "too_few_static_cells" : "none") << "frame " << k;
    // A registered frame rests on hundreds of the 1200 cells (a 640x480 grid of 16 px),
    // with a residual of millimetres squared; frame 0 has no fit, frame 1 becomes the
    // first keyframe and is measured frame to frame.
    if (k > 0 && !lost) {
      EXPECT_GT(std::stoul(rows[k][3]), 100u) << "frame " << k;
      EXPECT_GT(std::stod(rows[k][4]), 0.0) << "frame " << k;
      EXPECT_LT(std::stod(rows[k][4]), 1e-4) << "frame " << k;
      EXPECT_GE(std::stol(rows[k][5]), k > 1 ? 1 : -1) << "frame " << k;
    }
    const double share = std::stod(rows[k][6]);
    EXPECT_GE(share, 0.0);
    EXPECT_LE(share, 1.0);
    for (int column = 7; column < 11; ++column)
      EXPECT_GE(std::stod(rows[k][column]), 0.0) << "frame " << k;
  }
  // Frame 11 has no flow into the empty frame: its pose comes from a keyframe before it.
  EXPECT_GE(std::stol(rows[11][5]), 1);
  EXPECT_LE(std::stol(rows[11][5]), 9);
  EXPECT_FALSE(fs::exists(out_.file("frames.tsv.partial")));
}

TEST(FramesReport, ARecoveredFrameIsNotLostAndSaysHowItWasMeasured)
{
  dynvo::app::FrameResult result;
  result.timestamp = 12.5;
  result.recovered = true;
  const std::string line = dynvo::app::formatFrameReportLine(result);
  EXPECT_EQ(line.substr(0, line.find('\t', line.find('\t', line.find('\t') + 1) + 1)),
            "12.500000\t0\trecovered_dense")
      << line;
}

TEST_F(OdometryApp, CloudsAreLabelledPcdsOfEveryNthFrame)
{
  const auto result = runCommand(
      run("-max_frames 12 -labels_dir " + out_.file("labels") + " -clouds_dir " +
          out_.file("clouds") + " -clouds_every 5 -out " + out_.file("t.txt")));
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const auto trajectory = dynvo::readTrajectory(out_.file("t.txt"));
  ASSERT_EQ(trajectory.size(), 12u);
  std::size_t clouds = 0;
  for (const auto& entry : fs::directory_iterator(out_.file("clouds"))) {
    EXPECT_EQ(entry.path().extension(), ".pcd") << entry.path();
    ++clouds;
  }
  EXPECT_EQ(clouds, 3u); // frames 0, 5 and 10
  const std::string stamp = dynvo::formatStamp(trajectory[5].timestamp);
  const std::string file = out_.file("clouds") + "/" + stamp + ".pcd";
  EXPECT_NE(dynvo::test::readText(file).find("\nDATA binary_compressed\n"),
            std::string::npos);
  pcl::PointCloud<pcl::PointXYZRGBL> cloud;
  ASSERT_EQ(pcl::io::loadPCDFile(file, cloud), 0);
  EXPECT_EQ(cloud.width, 640u);
  EXPECT_EQ(cloud.height, 480u);
  EXPECT_TRUE(cloud.isOrganized());
  // Every point carries the label of its pixel in the frame's PNG, byte for byte.
  const auto labels =
      dynvo::readLabelImage(out_.file("labels") + "/" + stamp + ".png").data;
  ASSERT_EQ(labels.size(), cloud.size());
  std::size_t mismatched = 0, labelled = 0, finite_unlabelled = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    mismatched += cloud[i].label != labels[i] ? 1 : 0;
    labelled += labels[i] != 0 ? 1 : 0;
    // The cloud is the input frame: a pixel with a label has depth.
    finite_unlabelled += labels[i] != 0 && !std::isfinite(cloud[i].z) ? 1 : 0;
  }
  EXPECT_EQ(mismatched, 0u);
  EXPECT_GT(labelled,
            cloud.size() / 2); // the README: about 90 % labelled on static_one
  EXPECT_EQ(finite_unlabelled, 0u);
}

/// The value of `key=` in the printed lines as a number (NaN when absent or "nan").
double
printedValue(const std::string& out, const std::string& key)
{
  std::smatch match;
  if (!std::regex_search(out, match, std::regex("(^|[ \n])" + key + "=([^ \n]+)")))
    return std::nan("");
  return std::stod(match[2].str());
}

TEST_F(OdometryApp, BenchReferencePrintsItsFiguresAfterTheClosingLines)
{
  const auto result =
      runCommand(run("-out " + out_.file("t.txt") + " -bench_reference cv_rgbd"));
  ASSERT_EQ(result.exit_code, 0) << result.err;
  // The pipeline's closing line, then the reference's accuracy and its summary, last; the
  // reference ran on every frame of the run.
  ASSERT_TRUE(std::regex_search(
      result.out,
      std::regex(
          "\nframes=35 lost=[0-9]+ median_ms=[0-9.]+ mean_ms=[0-9.]+ fps=[0-9.]+\n"
          "reference_rpe_trans_rmse=[^ ]+ reference_rpe_trans_mean=[^ ]+ "
          "reference_rpe_rot_rmse=[^ ]+ reference_ate_rmse=[^ ]+ "
          "reference_pairs=[0-9]+\n"
          "reference=cv_rgbd frames=35 lost=[0-9]+ median_ms=[^ ]+ "
          "speed_ratio=[^ ]+\n$")))
      << result.out;
  const double pipeline_ms = printedValue(result.out, "median_ms");
  const std::string reference_line = result.out.substr(result.out.rfind("reference="));
  const double reference_ms = printedValue(reference_line, "median_ms");
  const double ratio = printedValue(reference_line, "speed_ratio");
  ASSERT_GT(pipeline_ms, 0.0);
  ASSERT_GT(reference_ms,
            0.0); // a VGA conversion plus OpenCV's pyramids take milliseconds
  ASSERT_TRUE(std::isfinite(ratio));
  // The ratio is the pipeline's median over the reference's; both medians are printed to
  // 0.01 ms of several ms and the ratio to 0.001, hence the slack.
  EXPECT_NEAR(ratio, pipeline_ms / reference_ms, 0.002) << result.out;
  EXPECT_GT(printedValue(result.out, "reference_pairs"), 0.0);
  EXPECT_TRUE(std::isfinite(printedValue(result.out, "reference_rpe_trans_rmse")))
      << result.out;
}

TEST_F(OdometryApp, BenchReferenceFollowsAMovingCamera)
{
  // The static room seen by a moving camera: OpenCV's dense odometry has every pixel of a
  // rigid scene, so it must follow the camera. A reference composed the wrong way, or one
  // that never moves, is off by the camera's whole motion or twice it: its RPE is at least
  // that of poses standing still, the camera's own speed (about 0.1-0.3 m/s here). OpenCV's
  // floor on these noisy synthetic rooms is a few cm/s, so half of that speed separates the
  // two with room on both sides.
  const int frames = 35; // over 1 s at 30 Hz, so that RPE has pairs
  const dynvo::test::SyntheticSequence moving("moving_static", frames, 640, 480);
  const auto result = runCommand(app_ + " -tum_dir " + moving.path() + " -out " +
                                 out_.file("t.txt") + " -bench_reference cv_rgbd");
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const auto groundtruth = dynvo::readTrajectory(moving.path() + "/groundtruth.txt");
  dynvo::Trajectory standing = dynvo::readTrajectory(out_.file("t.txt"));
  ASSERT_EQ(standing.size(), static_cast<std::size_t>(frames));
  for (auto& pose : standing)
    pose.T_world_camera = Eigen::Isometry3d::Identity();
  const double still = dynvo::computeRpe(groundtruth, standing).trans_rmse;
  ASSERT_GT(still, 0.05) << "the camera must move for this test to mean anything";
  const double reference = printedValue(result.out, "reference_rpe_trans_rmse");
  EXPECT_LT(reference, 0.5 * still) << result.out;
  // Every frame of a textured rigid scene gives OpenCV enough pixels.
  EXPECT_NE(result.out.find("reference=cv_rgbd frames=35 lost=0 "), std::string::npos)
      << result.out;
}

/// Runs of consecutive frames per id in an objects file: id -> (first, last frame
/// index).
std::multimap<int, std::pair<std::size_t, std::size_t>>
objectRuns(const std::string& objects_file, const dynvo::Trajectory& trajectory)
{
  std::map<double, std::size_t> frame_of;
  for (std::size_t k = 0; k < trajectory.size(); ++k)
    frame_of[std::round(trajectory[k].timestamp * 1e6)] = k;
  std::map<int, std::vector<std::size_t>> frames;
  std::ifstream in(objects_file);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#')
      continue;
    std::istringstream fields(line);
    double stamp = 0.0;
    int id = 0;
    fields >> stamp >> id;
    frames[id].push_back(frame_of.at(std::round(stamp * 1e6)));
  }
  std::multimap<int, std::pair<std::size_t, std::size_t>> runs;
  for (const auto& [id, list] : frames)
    for (std::size_t i = 0; i < list.size(); ++i)
      if (i == 0 || list[i] != list[i - 1] + 1)
        runs.insert({id, {list[i], list[i]}});
      else
        std::prev(runs.end())->second.second = list[i];
  return runs;
}

TEST_F(OdometryApp, ObjectTrajectoriesFollowTheMotionsOfTheObjectsFile)
{
  const auto result =
      runCommand(run("-out " + out_.file("t.txt") + " -objects " + out_.file("o.txt") +
                     " -objects_dir " + out_.file("objects")));
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const auto trajectory = dynvo::readTrajectory(out_.file("t.txt"));
  const auto folder = dynvo::app::readObjectsFolder(out_.file("objects"));
  // camera.txt is the run's trajectory.
  EXPECT_EQ(dynvo::test::readText(out_.file("objects") + "/camera.txt"),
            dynvo::test::readText(out_.file("t.txt")));
  // One track per run of consecutive frames of an id in the -objects file.
  const auto runs = objectRuns(out_.file("o.txt"), trajectory);
  ASSERT_FALSE(folder.objects.empty());
  ASSERT_EQ(folder.objects.size(), runs.size());
  for (const auto& track : folder.objects) {
    auto range = runs.equal_range(track.id);
    ASSERT_GE(std::distance(range.first, range.second), track.run) << track.id;
    const auto [first, last] = std::next(range.first, track.run - 1)->second;
    ASSERT_EQ(track.poses.size(), last - first + 1) << track.id;
    EXPECT_NEAR(track.poses.front().timestamp, trajectory[first].timestamp, 1e-6);
    EXPECT_NEAR(track.poses.back().timestamp, trajectory[last].timestamp, 1e-6);
    // The object frame has the camera's axes at the run's first frame.
    EXPECT_TRUE(track.poses.front().T_world_camera.linear().isApprox(
        trajectory[first].T_world_camera.linear(), 1e-6));
    // Its origin, a centroid of the frame's points, lies within the sensor's range
    // (0.5-4.5 m in front of the camera).
    const double z = (trajectory[first].T_world_camera.inverse() *
                      track.poses.front().T_world_camera)
                         .translation()
                         .z();
    EXPECT_GT(z, 0.5);
    EXPECT_LT(z, 4.5);
  }
  // Each later pose is T_world_curr * T_curr_prev * inv(T_world_prev) * the previous
  // one, with the motions of the -objects file (translations to 1 um, quaternions to
  // 1e-9: over 4 m of lever arm below 1e-5 m per step).
  std::map<std::pair<double, int>, Eigen::Isometry3d> motions;
  std::ifstream in(out_.file("o.txt"));
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#')
      continue;
    std::istringstream fields(line);
    double stamp, pixels, tx, ty, tz, qx, qy, qz, qw;
    int id;
    fields >> stamp >> id >> pixels >> tx >> ty >> tz >> qx >> qy >> qz >> qw;
    Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();
    motion.linear() =
        Eigen::Quaterniond(qw, qx, qy, qz).normalized().toRotationMatrix();
    motion.translation() = Eigen::Vector3d(tx, ty, tz);
    motions[{std::round(stamp * 1e6), id}] = motion;
  }
  std::size_t steps = 0;
  for (const auto& track : folder.objects) {
    const std::size_t first =
        std::next(runs.equal_range(track.id).first, track.run - 1)->second.first;
    for (std::size_t i = 1; i < track.poses.size(); ++i) {
      const std::size_t k = first + i;
      const Eigen::Isometry3d expected =
          trajectory[k].T_world_camera *
          motions.at({std::round(trajectory[k].timestamp * 1e6), track.id}) *
          trajectory[k - 1].T_world_camera.inverse() *
          track.poses[i - 1].T_world_camera;
      EXPECT_LT(
          (expected.translation() - track.poses[i].T_world_camera.translation()).norm(),
          1e-5);
      ++steps;
    }
  }
  EXPECT_GT(steps, 0u);
}

TEST_F(OdometryApp, BadFlagsAndMissingInput)
{
  EXPECT_EQ(runCommand(run("-bogus")).exit_code, 2);
  const auto backend = runCommand(run("-backend lm"));
  EXPECT_EQ(backend.exit_code, 2);
  EXPECT_NE(backend.err.find("-backend must be flow|cv_rgbd|icp|gicp|direct, got 'lm'"),
            std::string::npos)
      << backend.err;
  const auto reference = runCommand(run("-bench_reference orb"));
  EXPECT_EQ(reference.exit_code, 2);
  EXPECT_NE(reference.err.find("-bench_reference must be cv_rgbd, got 'orb'"),
            std::string::npos)
      << reference.err;
  EXPECT_EQ(runCommand(run("-bench_reference")).exit_code, 2); // no value
  EXPECT_EQ(runCommand(run("-threads 0")).exit_code, 2);
  for (const char* distortion :
       {"0.1,0,0,0", "0.1,0,0,0,0,0", "0.1,,0,0,0", "0.1,0,0,0,x"}) {
    const auto lens = runCommand(run(std::string("-distortion ") + distortion));
    EXPECT_EQ(lens.exit_code, 2) << distortion;
    EXPECT_NE(lens.err.find("'-distortion' expects 5 comma-separated numbers, got '" +
                            std::string(distortion) + "'"),
              std::string::npos)
        << lens.err;
  }
  const auto every =
      runCommand(run("-clouds_dir " + out_.file("c") + " -clouds_every 0"));
  EXPECT_EQ(every.exit_code, 2);
  EXPECT_NE(every.err.find("-clouds_every"), std::string::npos) << every.err;
  EXPECT_EQ(runCommand(run("-clouds_every 2")).exit_code, 2); // without -clouds_dir
  EXPECT_FALSE(fs::exists(out_.file("c")));
  EXPECT_EQ(runCommand(run("-objects_dir " + sequence_->path() + "/rgb")).exit_code, 2);
  EXPECT_EQ(runCommand(app_ + " -out x.txt").exit_code, 2); // no source
  const auto missing = runCommand(app_ + " -tum_dir " + out_.file("none"));
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.err.find("none: not a directory"), std::string::npos)
      << missing.err;
  EXPECT_EQ(runCommand(app_ + " -h").exit_code, 0);
}

} // namespace
