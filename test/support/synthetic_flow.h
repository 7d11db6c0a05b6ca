// SPDX-License-Identifier: BSD-3-Clause
// Synthetic grid scene flows with known rigid motions per region: flow-level input for the
// segmentation tests, built cell by cell without rendering (support/synthetic_scene.h renders
// images; this skips the flow estimation so that the segmentation is tested alone).
#pragma once

#include <dynvo/common/camera.h>
#include <dynvo/common/point_types.h>

#include "support/pose_compare.h"

#include <pcl/point_cloud.h>

#include <Eigen/Geometry>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

namespace dynvo::test {

/// A rectangle of grid cells [col0, col1) x [row0, row1) at depth z with its own motion.
struct FlowRegion {
  int col0 = 0, row0 = 0, col1 = 0, row1 = 0; ///< cell range (half open)
  double depth = 1.0; ///< metres (fronto-parallel, tilted below)
  Eigen::Matrix4d T_curr_prev = Eigen::Matrix4d::Identity(); ///< motion of the region
  int id = 0; ///< region id reported per cell
};

/// A synthetic flow grid with the ground-truth region id of every cell.
struct SyntheticFlow {
  pcl::PointCloud<PointFlow>::Ptr flow;
  std::vector<int>
      truth; ///< region id per cell (background id when no region covers it)
};

/** \brief Builds a cols x rows flow grid: the background (a tilted plane about 3 m away) moves
 * with T_background, and later regions are drawn over earlier ones. Each cell's current point
 * b_i is back-projected at its centre; a_i = T^-1 b_i; p_i is a_i's projection.
 * \param[in] noise_sigma Gaussian noise added to a_i per axis (metres)
 */
inline SyntheticFlow
makeSyntheticFlow(int cols,
                  int rows,
                  int cell_size,
                  const CameraIntrinsics& intrinsics,
                  const Eigen::Matrix4d& T_background,
                  const std::vector<FlowRegion>& regions,
                  double noise_sigma = 0.0,
                  std::uint32_t seed = 1)
{
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, noise_sigma > 0.0 ? noise_sigma : 1.0);
  SyntheticFlow out;
  out.flow.reset(new pcl::PointCloud<PointFlow>(static_cast<std::uint32_t>(cols),
                                                static_cast<std::uint32_t>(rows)));
  out.truth.assign(static_cast<std::size_t>(cols) * rows, 1);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      const std::size_t i = static_cast<std::size_t>(r) * cols + c;
      // Background: plane tilted about x so that depth grows towards the top.
      double z = 2.5 + 1.0 * (rows - r) / rows;
      Eigen::Matrix4d T = T_background;
      for (const FlowRegion& region : regions)
        if (c >= region.col0 && c < region.col1 && r >= region.row0 &&
            r < region.row1) {
          z = region.depth + 0.01 * (c - region.col0);
          T = region.T_curr_prev;
          out.truth[i] = region.id;
        }
      const float u = static_cast<float>(c * cell_size + cell_size / 2);
      const float v = static_cast<float>(r * cell_size + cell_size / 2);
      const Eigen::Vector3d b =
          intrinsics.backproject(u, v, static_cast<float>(z)).cast<double>();
      Eigen::Vector3d a =
          T.topLeftCorner<3, 3>().transpose() * (b - T.topRightCorner<3, 1>());
      if (noise_sigma > 0.0)
        a += Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
      const Eigen::Vector2f p = intrinsics.project(a.cast<float>());
      PointFlow& f = (*out.flow)(c, r);
      f.x = static_cast<float>(b.x());
      f.y = static_cast<float>(b.y());
      f.z = static_cast<float>(b.z());
      f.prev_x = static_cast<float>(a.x());
      f.prev_y = static_cast<float>(a.y());
      f.prev_z = static_cast<float>(a.z());
      f.u = u;
      f.v = v;
      f.prev_u = p.x();
      f.prev_v = p.y();
      f.weight = 1.0f;
      f.valid_2d = 1;
      f.valid_3d = 1;
    }
  return out;
}

/// The "default" preset (525, 525, 319.5, 239.5 at 640 px) scaled to `width` columns.
inline CameraIntrinsics
intrinsicsFor(int width)
{
  const double scale = width / 640.0;
  CameraIntrinsics K;
  K.fx = K.fy = 525.0 * scale;
  K.cx = 319.5 * scale;
  K.cy = 239.5 * scale;
  return K;
}

/// Organized cloud whose pixels take the depth of their cell's current point; every
/// seventh pixel has no depth.
template <typename PointT>
typename pcl::PointCloud<PointT>::Ptr
cloudFromFlow(const pcl::PointCloud<dynvo::PointFlow>& flow, int cell)
{
  typename pcl::PointCloud<PointT>::Ptr cloud(
      new pcl::PointCloud<PointT>(flow.width * cell, flow.height * cell));
  for (std::uint32_t v = 0; v < cloud->height; ++v)
    for (std::uint32_t u = 0; u < cloud->width; ++u) {
      PointT& p = (*cloud)(u, v);
      const float z = flow(u / cell, v / cell).z;
      p.x = p.y = 0.0f;
      p.z =
          (v * cloud->width + u) % 7 == 0 ? std::numeric_limits<float>::quiet_NaN() : z;
    }
  return cloud;
}

/// Intersection over union of two cell sets given as label maps.
template <typename A, typename B>
double
cellIoU(const std::vector<A>& x, A x_label, const std::vector<B>& y, B y_label)
{
  std::size_t both = 0, either = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const bool in_x = x[i] == x_label, in_y = y[i] == y_label;
    both += in_x && in_y;
    either += in_x || in_y;
  }
  return either == 0 ? 0.0 : static_cast<double>(both) / static_cast<double>(either);
}

} // namespace dynvo::test
