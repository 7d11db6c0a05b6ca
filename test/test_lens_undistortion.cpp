// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/common/lens_undistortion.h>

#include <gtest/gtest.h>

#include "support/lens_model.h"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace {

using dynvo::test::distortedPixel;

constexpr std::uint32_t WIDTH = 640, HEIGHT = 480;

Eigen::Vector2d
pinholePixel(const dynvo::CameraIntrinsics& c, double x, double y)
{
  return {c.fx * x + c.cx, c.fy * y + c.cy};
}

/// Points of the fr1 view: the centre, and towards the corners and edges, where the lens
/// moves a pixel by 8-20 px.
const double POINTS[][2] = {
    {0.0, 0.0}, {-0.5, -0.4}, {0.5, 0.3}, {-0.45, 0.35}, {0.55, 0.0}};

TEST(LensUndistortion, UndistortedImagesFollowThePinholeModel)
{
  const auto camera = dynvo::CameraIntrinsics::fromPreset("fr1");
  ASSERT_TRUE(camera.distorted());
  // A recording of a wall at 2 m, dark, with one bright 3x3 spot where the lens images each
  // point; depth only on the spots.
  dynvo::ColorImage color{WIDTH, HEIGHT,
                          std::vector<std::uint8_t>(WIDTH * HEIGHT * 3, 0)};
  dynvo::DepthImage depth{
      WIDTH, HEIGHT,
      std::vector<float>(WIDTH * HEIGHT, std::numeric_limits<float>::quiet_NaN())};
  for (const auto& [x, y] : POINTS) {
    const Eigen::Vector2d d = distortedPixel(camera, x, y);
    for (int dv = -1; dv <= 1; ++dv)
      for (int du = -1; du <= 1; ++du) {
        const auto i = static_cast<std::size_t>(std::lround(d.y()) + dv) * WIDTH +
                       static_cast<std::size_t>(std::lround(d.x()) + du);
        color.data[3 * i] = color.data[3 * i + 1] = color.data[3 * i + 2] = 255;
        depth.data[i] = 2.0f;
      }
  }
  const dynvo::LensUndistortion undistortion(camera, WIDTH, HEIGHT);
  undistortion.undistort(color, depth);
  for (const auto& [x, y] : POINTS) {
    // The spot's brightness-weighted centre lies where the pinhole model puts the point:
    // within 0.5 px (the spot was drawn at the distorted pixel rounded, 0.5 px off at most).
    const Eigen::Vector2d p = pinholePixel(camera, x, y);
    const Eigen::Vector2d d = distortedPixel(camera, x, y);
    double sum = 0.0, su = 0.0, sv = 0.0;
    for (int v = static_cast<int>(p.y()) - 6; v <= static_cast<int>(p.y()) + 6; ++v)
      for (int u = static_cast<int>(p.x()) - 6; u <= static_cast<int>(p.x()) + 6; ++u) {
        const double w = color.data[3 * (static_cast<std::size_t>(v) * WIDTH + u)];
        sum += w;
        su += w * u;
        sv += w * v;
      }
    ASSERT_GT(sum, 0.0) << "no spot near the pinhole pixel of (" << x << ", " << y
                        << ")";
    EXPECT_NEAR(su / sum, p.x(), 0.5) << x << ", " << y;
    EXPECT_NEAR(sv / sum, p.y(), 0.5) << x << ", " << y;
    // Depth takes the nearest pixel: the wall's 2 m exactly, nothing interpolated.
    const auto at = [&](const Eigen::Vector2d& q) {
      return depth.data[static_cast<std::size_t>(std::lround(q.y())) * WIDTH +
                        static_cast<std::size_t>(std::lround(q.x()))];
    };
    EXPECT_EQ(at(p), 2.0f) << x << ", " << y;
    // Off-centre, the lens moved the spot by more than its size: the distorted pixel is dark.
    if ((p - d).norm() > 4.0) {
      EXPECT_TRUE(std::isnan(at(d))) << x << ", " << y;
    }
  }
}

TEST(LensUndistortion, LabelsGoBackToTheRecordingsPixels)
{
  const auto camera = dynvo::CameraIntrinsics::fromPreset("fr1");
  const dynvo::LensUndistortion undistortion(camera, WIDTH, HEIGHT);
  // Labels of the undistorted geometry: a 5x5 patch of label k + 2 on point k's pinhole pixel.
  dynvo::LabelImage labels{WIDTH, HEIGHT, std::vector<std::uint8_t>(WIDTH * HEIGHT, 1)};
  std::uint8_t label = 2;
  for (const auto& [x, y] : POINTS) {
    const Eigen::Vector2d p = pinholePixel(camera, x, y);
    for (int dv = -2; dv <= 2; ++dv)
      for (int du = -2; du <= 2; ++du)
        labels.data[static_cast<std::size_t>(std::lround(p.y()) + dv) * WIDTH +
                    static_cast<std::size_t>(std::lround(p.x()) + du)] = label;
    ++label;
  }
  const dynvo::LabelImage recorded = undistortion.distort(labels);
  ASSERT_EQ(recorded.width, WIDTH);
  ASSERT_EQ(recorded.height, HEIGHT);
  label = 2;
  for (const auto& [x, y] : POINTS) {
    // Each patch is found where the lens images its point: a patch 5 px wide stays at least
    // 3 px wide after the lens (it magnifies by 0.93-1.07 here), so the distorted pixel
    // rounded lies inside it.
    const Eigen::Vector2d d = distortedPixel(camera, x, y);
    EXPECT_EQ(recorded.data[static_cast<std::size_t>(std::lround(d.y())) * WIDTH +
                            static_cast<std::size_t>(std::lround(d.x()))],
              label)
        << x << ", " << y;
    ++label;
  }
  // The lens barrels the image out, so every recorded pixel, corners included, lies within
  // the undistorted image (the reverse of UndistortedImagesFollowThePinholeModel's black
  // corners): all keep a label.
  EXPECT_EQ(recorded.data[0], 1);
  EXPECT_EQ(recorded.data[WIDTH * HEIGHT - 1], 1);
}

TEST(LensUndistortion, RefusesImagesOfAnotherSize)
{
  const dynvo::LensUndistortion undistortion(dynvo::CameraIntrinsics::fromPreset("fr1"),
                                             WIDTH, HEIGHT);
  dynvo::ColorImage color{4, 3, std::vector<std::uint8_t>(36, 0)};
  dynvo::DepthImage depth{4, 3, std::vector<float>(12, 1.0f)};
  try {
    undistortion.undistort(color, depth);
    FAIL() << "expected std::invalid_argument";
  }
  catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("4x3"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("640x480"), std::string::npos) << e.what();
  }
  EXPECT_THROW(undistortion.distort({4, 3, std::vector<std::uint8_t>(12, 0)}),
               std::invalid_argument);
  EXPECT_THROW(dynvo::LensUndistortion(dynvo::CameraIntrinsics{}, 0, 480),
               std::invalid_argument);
}

} // namespace
