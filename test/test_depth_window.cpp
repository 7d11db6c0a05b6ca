// SPDX-License-Identifier: BSD-3-Clause
// The scene flow's depth window on synthetic frames with and without the Kinect-like noise.
#include <dynvo/io/frame.h>
#include <dynvo/scene_flow/grid_scene_flow_estimation.h>
#include <dynvo/synth/scene_synthesizer.h>

#include <pcl/point_types.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

namespace {

/// Median over the valid_3d cells of |T_curr_prev a_i - b_i| (metres) for frames k-1, k of
/// the static-room scenario (every cell is static, so the true motion is the camera's).
double
medianFlowError(bool noise, int depth_window_radius)
{
  dynvo::SynthOptions options;
  options.scenario = "moving_static";
  options.frames = 12;
  options.noise = noise;
  const dynvo::SceneSynthesizer synth(options);
  const dynvo::SynthFrame previous = synth.render(10);
  const dynvo::SynthFrame current = synth.render(11);
  dynvo::GridSceneFlowEstimation<pcl::PointXYZRGB> estimation;
  estimation.setCameraIntrinsics(synth.intrinsics());
  estimation.setDepthWindowRadius(depth_window_radius);
  estimation.setPreviousCloud(
      dynvo::makeOrganizedCloud(previous.color, previous.depth, synth.intrinsics()));
  estimation.setInputCloud(
      dynvo::makeOrganizedCloud(current.color, current.depth, synth.intrinsics()));
  pcl::PointCloud<dynvo::PointFlow> flow;
  estimation.compute(flow);
  const Eigen::Isometry3f T_curr_prev =
      (current.T_world_camera.inverse() * previous.T_world_camera).cast<float>();
  std::vector<double> errors;
  for (const dynvo::PointFlow& f : flow)
    if (f.valid_3d)
      errors.push_back((T_curr_prev * Eigen::Vector3f(f.prev_x, f.prev_y, f.prev_z) -
                        f.getVector3fMap())
                           .norm());
  EXPECT_GT(errors.size(), 900u)
      << "most of the 1200 cells see textured, measured walls";
  std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
  return errors[errors.size() / 2];
}

TEST(DepthWindow, AveragesTheSensorNoiseAway)
{
  // Walls at 1-2.2 m with sigma = 1.2e-3 z^2 per pixel plus disparity quantisation: one pixel
  // per end leaves several millimetres. The window fits about 40 agreeing samples, so the
  // noise should drop by well over half (measured: pcl_modules/scene_flow/NOTES.md).
  const double single = medianFlowError(true, 0);
  const double window = medianFlowError(true, 6);
  EXPECT_GT(single, 0.002);
  EXPECT_LT(window, 0.4 * single);
}

TEST(DepthWindow, IsExactOnNoiseFreePlanes)
{
  // The room is made of planes, on which inverse depth is linear in the pixel coordinates:
  // the fit reproduces the exact depth, so only the LK error (a few hundredths of a pixel)
  // remains, as with the single pixel.
  const double single = medianFlowError(false, 0);
  const double window = medianFlowError(false, 6);
  EXPECT_LT(window, 0.0003);
  EXPECT_LT(window, single + 0.0001);
}

TEST(DepthWindow, RadiusOutOfRangeThrowsAndKeepsTheOldValue)
{
  dynvo::GridSceneFlowEstimation<pcl::PointXYZRGB> estimation;
  estimation.setDepthWindowRadius(3);
  EXPECT_THROW(estimation.setDepthWindowRadius(-1), std::invalid_argument);
  EXPECT_THROW(estimation.setDepthWindowRadius(16), std::invalid_argument);
  EXPECT_EQ(estimation.getDepthWindowRadius(), 3);
}

} // namespace
