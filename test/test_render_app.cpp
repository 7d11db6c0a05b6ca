// SPDX-License-Identifier: BSD-3-Clause
// dynvo_render as users run it: the trajectory plot with the object paths of a run.
#include <dynvo/io/trajectory_io.h>
#include <dynvo/vis/display.h>
#include <dynvo/vis/label_renderer.h>

#include <gtest/gtest.h>

#include "support/run_command.h"
#include "support/synthetic_sequence.h"
#include "support/temp_dir.h"

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <cstdlib>

namespace {

using dynvo::test::runCommand;

/// Pixels within 40 levels (anti-aliased line edges) of a palette colour.
int
countColour(const cv::Mat& image, const std::array<std::uint8_t, 3>& rgb)
{
  int count = 0;
  for (int v = 0; v < image.rows; ++v)
    for (int u = 0; u < image.cols; ++u) {
      const cv::Vec3b& bgr = image.at<cv::Vec3b>(v, u);
      count += std::abs(bgr[2] - rgb[0]) + std::abs(bgr[1] - rgb[1]) +
                           std::abs(bgr[0] - rgb[2]) <=
                       40
                   ? 1
                   : 0;
    }
  return count;
}

TEST(RenderApp, TrajectoryPlotDrawsTheObjectPathsOfTheRun)
{
  std::string why;
  if (!dynvo::displayAvailable(&why))
    GTEST_SKIP() << "no display (" << why << "); run under xvfb-run -a";
  const dynvo::test::SyntheticSequence sequence("static_one", 6, 160, 120);
  const dynvo::test::TempDir dir;
  const auto run =
      runCommand(std::string(DYNVO_ODOMETRY_BIN) + " -tum_dir " + sequence.path() +
                 " -out " + dir.file("t.txt") + " -labels_dir " + dir.file("labels"));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  // An objects folder for the run: object 2 crosses 1 m in front of the camera.
  const auto camera = dynvo::readTrajectory(dir.file("t.txt"));
  dynvo::Trajectory object;
  for (std::size_t k = 0; k < camera.size(); ++k) {
    dynvo::StampedPose pose{camera[k].timestamp, Eigen::Isometry3d::Identity()};
    pose.T_world_camera.translation() = Eigen::Vector3d(-0.5 + 0.2 * k, 0.0, 2.0);
    object.push_back(pose);
  }
  std::filesystem::create_directory(dir.file("objects"));
  dynvo::writeTrajectory(dir.file("objects/camera.txt"), camera);
  dynvo::writeTrajectory(dir.file("objects/object_2_1.txt"), object);
  dynvo::test::writeText(dir.file("objects/objects_summary.txt"),
                         "2 1 0 0 6 5 0.5 1.0\n");
  const std::string render = std::string(DYNVO_RENDER_BIN) + " -tum_dir " +
                             sequence.path() + " -trajectory " + dir.file("t.txt") +
                             " -labels_dir " + dir.file("labels") + " -every 10";
  const auto colour = dynvo::LabelRenderer::labelColor(2);
  for (const bool with_objects : {false, true}) {
    const std::string out = dir.file(with_objects ? "with" : "without");
    const auto result = runCommand(
        render + " -out_dir " + out +
        (with_objects ? " -objects_dir " + dir.file("objects") : std::string()));
    ASSERT_EQ(result.exit_code, 0) << result.err;
    const cv::Mat plot = cv::imread(out + "/trajectory.png", cv::IMREAD_COLOR);
    ASSERT_FALSE(plot.empty());
    // A 2-px line over most of the chart's width is hundreds of pixels; without the
    // folder the plot has no curve of that colour.
    if (with_objects)
      EXPECT_GT(countColour(plot, colour), 200);
    else
      EXPECT_EQ(countColour(plot, colour), 0);
  }
  // The objects folder is an input of the render: no output may go into it.
  EXPECT_EQ(runCommand(render + " -out_dir " + dir.file("objects") + " -objects_dir " +
                       dir.file("objects"))
                .exit_code,
            2);
}

} // namespace
