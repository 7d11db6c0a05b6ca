// SPDX-License-Identifier: BSD-3-Clause
// The Brown-Conrady lens model written out, to check OpenCV's maps against it.
#pragma once

#include <dynvo/common/camera.h>

#include <Eigen/Core>

namespace dynvo::test {

/// Where camera c's lens images the point of normalized coordinates (x, y) (px).
inline Eigen::Vector2d
distortedPixel(const CameraIntrinsics& c, double x, double y)
{
  const auto& [k1, k2, p1, p2, k3] = c.distortion;
  const double r2 = x * x + y * y;
  const double radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
  const double xd = x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x);
  const double yd = y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y;
  return {c.fx * xd + c.cx, c.fy * yd + c.cy};
}

} // namespace dynvo::test
