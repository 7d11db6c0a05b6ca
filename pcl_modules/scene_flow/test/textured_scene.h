// SPDX-License-Identifier: BSD-3-Clause
// A tiny exact ray caster of textured rectangles, for scene flow tests with known motion.
#pragma once

#include <dynvo/common/camera.h>

#include <pcl/point_cloud.h>

#include <Eigen/Geometry>

#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace dynvo::test {

/// Smooth hash-based value noise in [0, 1] at lattice spacing 1 (C1 continuous).
inline float
valueNoise(double s, double t, std::uint32_t seed)
{
  const auto lattice = [seed](std::int64_t i, std::int64_t j) {
    std::uint32_t h = static_cast<std::uint32_t>(i * 73856093) ^
                      static_cast<std::uint32_t>(j * 19349663) ^ (seed * 83492791u);
    h ^= h >> 13;
    h *= 0x5bd1e995u;
    h ^= h >> 15;
    return static_cast<float>(h & 0xffffu) / 65535.0f;
  };
  const double fs = std::floor(s), ft = std::floor(t);
  const auto i = static_cast<std::int64_t>(fs), j = static_cast<std::int64_t>(ft);
  const auto smooth = [](double x) {
    return static_cast<float>(x * x * (3.0 - 2.0 * x));
  };
  const float a = smooth(s - fs), b = smooth(t - ft);
  const float top = lattice(i, j) + a * (lattice(i + 1, j) - lattice(i, j));
  const float bottom =
      lattice(i, j + 1) + a * (lattice(i + 1, j + 1) - lattice(i, j + 1));
  return top + b * (bottom - top);
}

/// A textured rectangle: z = 0 and |x| <= half_width, |y| <= half_height in its own frame.
struct TexturedQuad {
  Eigen::Isometry3d T_world_quad =
      Eigen::Isometry3d::Identity(); ///< quad-to-world (metres)
  double half_width = 1.0;           ///< metres
  double half_height = 1.0;          ///< metres
  std::uint32_t seed = 0;            ///< texture seed
  int id = 0;                        ///< reported per pixel by render()
};

/// Grey level of the texture at quad coordinates (metres): features of 5-10 cm.
inline std::uint8_t
textureGrey(const TexturedQuad& quad, double x, double y)
{
  const float coarse = valueNoise(x / 0.10, y / 0.10, quad.seed);
  const float fine = valueNoise(x / 0.05, y / 0.05, quad.seed + 1000u);
  return static_cast<std::uint8_t>(30.0f + 130.0f * coarse + 65.0f * fine);
}

/// One rendered view: organized cloud plus the id of the quad seen at each pixel (-1 = none).
template <typename PointT> struct RenderedView {
  typename pcl::PointCloud<PointT>::Ptr cloud;
  std::vector<int> ids;
};

/** \brief Ray-casts the quads from a camera. Depth is exact (centre ray of each pixel); the
 * grey level is the mean over 2x2 sub-pixel rays, a box filter that keeps the image smooth at
 * the pixel scale as a real lens does. Pixels that see no quad are NaN points.
 */
template <typename PointT>
RenderedView<PointT>
render(const std::vector<TexturedQuad>& quads,
       const Eigen::Isometry3d& T_world_camera,
       const CameraIntrinsics& intrinsics,
       std::uint32_t width,
       std::uint32_t height)
{
  const double inf = std::numeric_limits<double>::infinity();
  const Eigen::Vector3d origin = T_world_camera.translation();
  std::vector<Eigen::Isometry3d> T_quad_world;
  for (const TexturedQuad& quad : quads)
    T_quad_world.push_back(quad.T_world_quad.inverse());
  // Hit of the ray through pixel (u, v): camera depth and the quad's texture coordinates.
  const auto cast = [&](double u, double v, int& id, Eigen::Vector2d& st) {
    const Eigen::Vector3d ray_camera((u - intrinsics.cx) / intrinsics.fx,
                                     (v - intrinsics.cy) / intrinsics.fy, 1.0);
    const Eigen::Vector3d ray = T_world_camera.linear() * ray_camera;
    double best = inf;
    id = -1;
    for (std::size_t q = 0; q < quads.size(); ++q) {
      const Eigen::Vector3d o = T_quad_world[q] * origin;
      const Eigen::Vector3d d = T_quad_world[q].linear() * ray;
      if (std::abs(d.z()) < 1e-12)
        continue;
      const double t = -o.z() / d.z(); // camera depth, since ray_camera.z() == 1
      const Eigen::Vector3d hit = o + t * d;
      if (t > 0.0 && t < best && std::abs(hit.x()) <= quads[q].half_width &&
          std::abs(hit.y()) <= quads[q].half_height) {
        best = t;
        id = static_cast<int>(q);
        st = hit.head<2>();
      }
    }
    return best;
  };
  RenderedView<PointT> view;
  view.cloud.reset(new pcl::PointCloud<PointT>(width, height));
  view.cloud->is_dense = false;
  view.ids.assign(static_cast<std::size_t>(width) * height, -1);
  for (std::uint32_t v = 0; v < height; ++v) {
    for (std::uint32_t u = 0; u < width; ++u) {
      PointT& p = (*view.cloud)(u, v);
      Eigen::Vector2d st;
      int id = -1;
      const double z = cast(u, v, id, st);
      view.ids[static_cast<std::size_t>(v) * width + u] = id;
      if (id >= 0)
        p.getVector3fMap() = intrinsics.backproject(
            static_cast<float>(u), static_cast<float>(v), static_cast<float>(z));
      else
        p.x = p.y = p.z = std::numeric_limits<float>::quiet_NaN();
      int sum = 0;
      for (const double du : {-0.25, 0.25})
        for (const double dv : {-0.25, 0.25}) {
          int sub_id = -1;
          cast(u + du, v + dv, sub_id, st);
          sum += sub_id >= 0 ? textureGrey(quads[sub_id], st.x(), st.y()) : 0;
        }
      p.r = p.g = p.b = static_cast<std::uint8_t>((sum + 2) / 4);
    }
  }
  return view;
}

} // namespace dynvo::test
