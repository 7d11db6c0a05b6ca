// SPDX-License-Identifier: BSD-3-Clause
// dynvo_odometry as users run it: outputs, closing lines, determinism and bad input.
#include <dynvo/app/pipeline_config.h>
#include <dynvo/io/label_io.h>
#include <dynvo/io/trajectory_io.h>

#include <gtest/gtest.h>

#include "support/run_command.h"
#include "support/synthetic_sequence.h"
#include "support/temp_dir.h"

#include <cmath>
#include <filesystem>
#include <fstream>
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
  fs::copy(sequence_->path(), out_.file("seq"), fs::copy_options::recursive);
  std::vector<fs::path> colour;
  for (const auto& entry : fs::directory_iterator(out_.file("seq") + "/rgb"))
    colour.push_back(entry.path());
  std::sort(colour.begin(), colour.end());
  dynvo::test::writeText(colour[6].string(), "not a png");
  const auto result = runCommand(app_ + " -tum_dir " + out_.file("seq") + " -out " +
                                 out_.file("t.txt"));
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.err.find(colour[6].filename().string()), std::string::npos)
      << result.err;
  EXPECT_EQ(dynvo::readTrajectory(out_.file("t.txt")).size(), 6u);
}

TEST_F(OdometryApp, BadFlagsAndMissingInput)
{
  EXPECT_EQ(runCommand(run("-bogus")).exit_code, 2);
  EXPECT_EQ(runCommand(run("-refine lm")).exit_code, 2);
  EXPECT_EQ(runCommand(run("-threads 0")).exit_code, 2);
  EXPECT_EQ(runCommand(app_ + " -out x.txt").exit_code, 2); // no source
  const auto missing = runCommand(app_ + " -tum_dir " + out_.file("none"));
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.err.find("none: not a directory"), std::string::npos)
      << missing.err;
  EXPECT_EQ(runCommand(app_ + " -h").exit_code, 0);
}

} // namespace
