// SPDX-License-Identifier: BSD-3-Clause
// The apps that run the modules share one pipeline and one flag set (issue 12 §2):
// dynvo_segment writes the labels of dynvo_odometry -labels_dir, and -config and the shared
// flags mean the same in dynvo_odometry, dynvo_segment and dynvo_scene_flow.
#include <dynvo/app/pipeline_args.h>
#include <dynvo/app/pipeline_config.h>
#include <dynvo/io/frame_source.h>
#include <dynvo/io/label_io.h>

#include <pcl/exceptions.h>

#include <gtest/gtest.h>

#include "support/run_command.h"
#include "support/synthetic_sequence.h"
#include "support/temp_dir.h"

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using dynvo::test::readText;
using dynvo::test::runCommand;
using dynvo::test::TempDir;

const std::string ODOMETRY = DYNVO_ODOMETRY_BIN;
const std::string SEGMENT = DYNVO_SEGMENT_BIN;
const std::string SCENE_FLOW = DYNVO_SCENE_FLOW_BIN;

/// The bytes of every file of a folder, by file name.
std::map<std::string, std::string>
folderContents(const std::string& folder)
{
  std::map<std::string, std::string> files;
  for (const auto& entry : fs::directory_iterator(folder))
    files[entry.path().filename().string()] = readText(entry.path().string());
  return files;
}

class PipelineApps : public ::testing::Test {
protected:
  static void SetUpTestSuite()
  {
    sequence_ = new dynvo::test::SyntheticSequence("static_two", FRAMES, WIDTH, HEIGHT);
  }

  static void TearDownTestSuite() { delete sequence_; }

  static std::string source() { return " -tum_dir " + sequence_->path() + " "; }

  /// Runs dynvo_segment and dynvo_odometry -labels_dir with the same flags and expects
  /// the same label PNGs, byte for byte, one per frame, with static pixels and objects.
  void expectSameLabels(const std::string& flags) const
  {
    const auto segment =
        runCommand(SEGMENT + source() + flags + " -out_dir " + dir_.file("segment") +
                   " -objects " + dir_.file("segment.txt"));
    ASSERT_EQ(segment.exit_code, 0) << segment.err;
    const auto odometry =
        runCommand(ODOMETRY + source() + flags + " -labels_dir " +
                   dir_.file("odometry") + " -objects " + dir_.file("odometry.txt"));
    ASSERT_EQ(odometry.exit_code, 0) << odometry.err;

    const auto segment_labels = folderContents(dir_.file("segment"));
    const auto odometry_labels = folderContents(dir_.file("odometry"));
    ASSERT_EQ(segment_labels.size(), static_cast<std::size_t>(FRAMES));
    ASSERT_EQ(odometry_labels.size(), segment_labels.size());
    std::size_t static_pixels = 0, object_pixels = 0;
    for (const auto& [name, bytes] : segment_labels) {
      ASSERT_EQ(odometry_labels.count(name), 1u) << name;
      EXPECT_TRUE(odometry_labels.at(name) == bytes) << name << " differs";
      const auto labels = dynvo::readLabelImage(dir_.file("segment") + "/" + name);
      static_pixels += std::count(labels.data.begin(), labels.data.end(), 1);
      object_pixels +=
          std::count_if(labels.data.begin(), labels.data.end(), [](std::uint8_t label) {
            return label > 1;
          });
    }
    // static_two: a static camera before a room that two boxes move through, covering
    // well under half of the image. Frame 0 has no flow (all 0), and cells without flow or
    // in segments too small to keep stay 0 (more of them with small cells), so a fifth of
    // the pixels of frames 1.. being static is a loose lower bound; the boxes are objects
    // (320 x 240: at 160 x 120 they were measured in two frames only, under the 3 frames
    // after which an object is output).
    EXPECT_GT(static_pixels, static_cast<std::size_t>(FRAMES - 1) * WIDTH * HEIGHT / 5);
    EXPECT_GT(object_pixels, 0u);
    // The object motions are the same lines too.
    EXPECT_EQ(readText(dir_.file("segment.txt")), readText(dir_.file("odometry.txt")));
  }

  static constexpr int FRAMES = 12;
  static constexpr int WIDTH = 320;
  static constexpr int HEIGHT = 240;
  static dynvo::test::SyntheticSequence* sequence_;
  TempDir dir_;
};

dynvo::test::SyntheticSequence* PipelineApps::sequence_ = nullptr;

TEST_F(PipelineApps, SegmentWritesTheLabelsOfOdometryWithDefaults)
{
  expectSameLabels("");
}

TEST_F(PipelineApps, SegmentWritesTheLabelsOfOdometryWithFlagsAndConfig)
{
  // Every shared kind of flag, and a file that moves the pipeline off its defaults.
  dynvo::app::PipelineOptions changed;
  changed.segmentation.inlier_threshold = 4e-5f;
  changed.inlier_noise.inlier_noise_factor = 0.0f;
  dynvo::app::writePipelineConfig(dir_.file("c.yaml"), changed);
  expectSameLabels("-config " + dir_.file("c.yaml") +
                   " -seed 7 -threads 2 -no_tracking -backend icp -max_frames 12");
}

TEST_F(PipelineApps, ConfigMeansTheSameInEveryApp)
{
  // A grid of 8 px cells instead of 16: dynvo_scene_flow's PCD has 40x30 cells.
  dynvo::app::PipelineOptions changed;
  changed.scene_flow.cell_size = 8;
  dynvo::app::writePipelineConfig(dir_.file("c.yaml"), changed);
  const std::string config = " -config " + dir_.file("c.yaml");
  const auto flow = runCommand(SCENE_FLOW + source() + config + " -frame 3 -out " +
                               dir_.file("f.pcd"));
  ASSERT_EQ(flow.exit_code, 0) << flow.err;
  EXPECT_NE(readText(dir_.file("f.pcd")).find("\nWIDTH 40\nHEIGHT 30\n"),
            std::string::npos);
  expectSameLabels(config);

  // Each app writes back the same configuration from the same file and shared flags.
  const std::string flags = config + " -threads 3 -cell_size 10";
  for (const auto& [app, name] : std::vector<std::pair<std::string, std::string>>{
           {ODOMETRY, "odometry.yaml"},
           {SEGMENT, "segment.yaml"},
           {SCENE_FLOW, "scene_flow.yaml"}}) {
    const auto written = runCommand(app + flags + " -write_config " + dir_.file(name));
    ASSERT_EQ(written.exit_code, 0) << app << "\n" << written.err;
  }
  const std::string odometry = readText(dir_.file("odometry.yaml"));
  EXPECT_NE(odometry.find("cell_size: 10"), std::string::npos) << odometry;
  EXPECT_NE(odometry.find("threads: 3"), std::string::npos) << odometry;
  EXPECT_EQ(readText(dir_.file("segment.yaml")), odometry);
  EXPECT_EQ(readText(dir_.file("scene_flow.yaml")), odometry);
}

TEST_F(PipelineApps, SharedFlagsHaveOneHelpLineAndDefault)
{
  const auto helpLines = [](const std::string& app) {
    const auto result = runCommand(app + " -h");
    EXPECT_EQ(result.exit_code, 0) << result.err;
    std::map<std::string, std::string> lines; // by flag
    std::istringstream in(result.out);
    for (std::string line; std::getline(in, line);)
      if (line.rfind("  -", 0) == 0)
        lines[line.substr(2, line.find(' ', 2) - 2)] = line;
    return lines;
  };
  const auto odometry = helpLines(ODOMETRY);
  const auto segment = helpLines(SEGMENT);
  const auto scene_flow = helpLines(SCENE_FLOW);
  ASSERT_EQ(odometry.count("-threads"), 1u);
  EXPECT_NE(odometry.at("-threads").find("(default 1;"), std::string::npos)
      << odometry.at("-threads");
  for (const char* flag :
       {"-tum_dir", "-camera", "-config", "-write_config", "-threads", "-cell_size",
        "-window_size", "-max_pyramid_level", "-fb_check", "-v", "-q"}) {
    ASSERT_EQ(odometry.count(flag), 1u) << flag;
    EXPECT_EQ(segment.at(flag), odometry.at(flag));
    EXPECT_EQ(scene_flow.at(flag), odometry.at(flag));
  }
  for (const char* flag : {"-seed", "-no_tracking", "-no_segmentation", "-backend",
                           "-max_frames", "-objects"}) {
    ASSERT_EQ(odometry.count(flag), 1u) << flag;
    EXPECT_EQ(segment.at(flag), odometry.at(flag));
    EXPECT_EQ(scene_flow.count(flag), 0u) << flag << ": not a scene flow parameter";
  }
}

/// The flags on the library side: what each one sets, and its checks.
dynvo::app::PipelineOptions
optionsOf(const std::vector<const char*>& flags)
{
  std::vector<const char*> argv{"app"};
  argv.insert(argv.end(), flags.begin(), flags.end());
  const dynvo::app::Arguments args(
      static_cast<int>(argv.size()), argv.data(),
      dynvo::app::appOptions(dynvo::app::PipelineStages::all, {}));
  return dynvo::app::pipelineOptionsFromArguments(args);
}

TEST(PipelineFlags, EachFlagSetsItsKeysAndNothingElse)
{
  const dynvo::app::PipelineOptions defaults;
  const auto none = optionsOf({});
  for (const auto& field : dynvo::app::pipelineConfigTable().fields())
    EXPECT_EQ(field.get(none), field.get(defaults)) << field.name;

  const auto given = optionsOf({"-threads", "4", "-cell_size", "8", "-window_size",
                                "15", "-max_pyramid_level", "2", "-fb_check", "local",
                                "-seed", "9", "-no_tracking", "-no_segmentation",
                                "-backend", "gicp", "-camera", "fr1"});
  EXPECT_EQ(given.threads, 4u);
  EXPECT_EQ(given.scene_flow.cell_size, 8);
  EXPECT_EQ(given.scene_flow.window_size, 15);
  EXPECT_EQ(given.scene_flow.max_pyramid_level, 2);
  EXPECT_EQ(given.scene_flow.forward_backward_check,
            dynvo::ForwardBackwardCheck::local);
  EXPECT_EQ(given.segmentation.seed, 9u);
  EXPECT_FALSE(given.segmentation.tracking);
  EXPECT_FALSE(given.use_segmentation);
  EXPECT_EQ(given.backend.backend, dynvo::RegistrationBackend::gicp);
  EXPECT_FLOAT_EQ(given.intrinsics.fx, dynvo::CameraIntrinsics::fromPreset("fr1").fx);
}

TEST(PipelineFlags, ValuesOutOfRangeAreUsageErrors)
{
  const auto message = [](const std::vector<const char*>& flags) {
    try {
      optionsOf(flags);
    }
    catch (const dynvo::app::UsageError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(message({"-threads", "0"}), "-threads must be >= 1, got 0");
  EXPECT_EQ(message({"-seed", "4294967296"}),
            "-seed must be in [0, 4294967295], got 4294967296");
  EXPECT_EQ(message({"-cell_size", "1"}), "-cell_size must be >= 2, got 1");
  EXPECT_EQ(message({"-cell_size", "3000000000"}),
            "-cell_size must be a whole number >= 2, got 3e+09");
  EXPECT_EQ(message({"-backend", "lm"}),
            "-backend must be flow|cv_rgbd|icp|gicp|direct, got 'lm'");
  EXPECT_EQ(message({"-window_size", "x"}),
            "option '-window_size' expects an integer, got 'x'");
}

/// Frames named frame_0, frame_1, ... of which `frames` exist; reading frame `broken` throws.
class NumberedSource : public dynvo::FrameSource {
public:
  NumberedSource(int frames, int broken)
      : frames_(frames)
      , broken_(broken)
  {
  }

  bool next(dynvo::Frame& frame) override
  {
    const int k = reads_++;
    if (k == broken_)
      throw pcl::IOException("frame_" + std::to_string(k) + ": cannot be read");
    if (k >= frames_)
      return false;
    frame.name = "frame_" + std::to_string(k);
    frame.timestamp = k;
    return true;
  }

  std::size_t size() const override { return static_cast<std::size_t>(frames_); }

  int reads() const { return reads_; }

private:
  int frames_, broken_;
  std::atomic<int> reads_{0};
};

TEST(FrameLoop, ReadingAheadChangesNothingButWhenFramesAreRead)
{
  // The same frames in the same order, the same stop on a broken file and at max_frames,
  // and no read beyond max_frames (a frame not asked for may be missing or broken).
  for (const bool ahead : {false, true}) {
    SCOPED_TRACE(ahead ? "read ahead" : "read in turn");
    const auto run = [ahead](NumberedSource& source, std::size_t max_frames) {
      std::vector<std::string> seen;
      const dynvo::app::FrameLoopEnd end = dynvo::app::processFrames(
          source, max_frames,
          [&seen](const dynvo::Frame& frame) {
            seen.push_back(frame.name);
          },
          ahead);
      EXPECT_EQ(end.frames, seen.size());
      return std::make_pair(seen, end.error);
    };
    NumberedSource whole(5, -1);
    const auto [all, no_error] = run(whole, 0);
    EXPECT_EQ(all, (std::vector<std::string>{"frame_0", "frame_1", "frame_2", "frame_3",
                                             "frame_4"}));
    EXPECT_EQ(no_error, "");

    NumberedSource broken(5, 3);
    const auto [before, error] = run(broken, 0);
    EXPECT_EQ(before.size(), 3u);
    EXPECT_NE(error.find("frame_3: cannot be read"), std::string::npos) << error;

    NumberedSource limited(5, 3);
    const auto [first, limit_error] = run(limited, 3);
    EXPECT_EQ(first.size(), 3u);
    EXPECT_EQ(limit_error, "");
    EXPECT_EQ(limited.reads(), 3);
  }
}

} // namespace
