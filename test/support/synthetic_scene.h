// SPDX-License-Identifier: BSD-3-Clause
// The one synthetic scene generator of the tests: an exact ray caster of textured,
// oriented boxes (a flat rectangle is a box of zero thickness), with independently moving
// boxes and the ideal grid scene flow between two frames.
#pragma once

#include <dynvo/common/camera.h>
#include <dynvo/common/point_types.h>

#include <pcl/point_cloud.h>

#include <Eigen/Geometry>

#include <algorithm>
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

/// Grey level of a texture at surface coordinates (metres): features of 5-10 cm.
inline std::uint8_t
textureGrey(std::uint32_t seed, double s, double t)
{
  const float coarse = valueNoise(s / 0.10, t / 0.10, seed);
  const float fine = valueNoise(s / 0.05, t / 0.05, seed + 1000u);
  return static_cast<std::uint8_t>(30.0f + 130.0f * coarse + 65.0f * fine);
}

/// An oriented, textured box: |x_k| <= half_size_k in its own frame.
struct SceneBox {
  Eigen::Isometry3d T_world_box = Eigen::Isometry3d::Identity(); ///< box-to-world (m)
  Eigen::Vector3d half_size = Eigen::Vector3d::Ones();           ///< metres; 0 = flat
  std::uint32_t seed = 0; ///< texture seed (its +z/-z faces use it as is)
  bool moving = false;    ///< moved by the object motion of moveBoxes()/idealFlow()
};

/// A flat textured rectangle: z = 0, |x| <= half_width, |y| <= half_height in its frame.
inline SceneBox
texturedQuad(const Eigen::Isometry3d& T_world_quad,
             double half_width,
             double half_height,
             std::uint32_t seed,
             bool moving = false)
{
  return {T_world_quad, Eigen::Vector3d(half_width, half_height, 0.0), seed, moving};
}

/// The boxes after the moving ones moved by `object_motion` (world frame).
inline std::vector<SceneBox>
moveBoxes(std::vector<SceneBox> boxes, const Eigen::Isometry3d& object_motion)
{
  for (SceneBox& box : boxes)
    if (box.moving)
      box.T_world_box = object_motion * box.T_world_box;
  return boxes;
}

/// Ray parameter where o + s d enters the box |x_k| <= half_k (slab method), and the axis
/// of the face it enters through; +inf on a miss or when the entry lies behind the origin.
inline double
boxEntry(const Eigen::Vector3d& o,
         const Eigen::Vector3d& d,
         const Eigen::Vector3d& half,
         int& axis)
{
  const double inf = std::numeric_limits<double>::infinity();
  double enter = -inf, leave = inf;
  axis = 2;
  for (int k = 0; k < 3; ++k) {
    if (std::abs(d[k]) < 1e-12) {
      if (std::abs(o[k]) > half[k])
        return inf;
      continue;
    }
    const double s1 = (-half[k] - o[k]) / d[k];
    const double s2 = (half[k] - o[k]) / d[k];
    if (std::min(s1, s2) > enter) {
      enter = std::min(s1, s2);
      axis = k;
    }
    leave = std::min(leave, std::max(s1, s2));
  }
  return enter <= leave && enter > 0.0 ? enter : inf;
}

/// One rendered view: organized cloud plus the index of the box seen at each pixel
/// (-1 = none).
template <typename PointT> struct RenderedView {
  typename pcl::PointCloud<PointT>::Ptr cloud;
  std::vector<int> ids;
};

/** \brief Ray-casts the boxes from a camera (width x height image).
 *
 * Depth is exact: the camera z of the centre ray's first hit. The grey level (r = g = b)
 * is the mean over 2x2 sub-pixel rays, a box filter that keeps the image smooth at the
 * pixel scale as a real lens does; each face is textured in its own two coordinates.
 * Pixels that see no box are NaN points.
 */
template <typename PointT>
RenderedView<PointT>
render(const std::vector<SceneBox>& boxes,
       const Eigen::Isometry3d& T_world_camera,
       const CameraIntrinsics& intrinsics,
       std::uint32_t width,
       std::uint32_t height)
{
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<Eigen::Isometry3d> T_box_camera;
  for (const SceneBox& box : boxes)
    T_box_camera.push_back(box.T_world_box.inverse() * T_world_camera);
  // First hit of the ray through pixel (u, v): camera depth, box index and the surface
  // coordinates of the face hit (texture seed included).
  const auto cast = [&](double u, double v, int& id, Eigen::Vector2d& st,
                        std::uint32_t& seed) {
    const Eigen::Vector3d ray((u - intrinsics.cx) / intrinsics.fx,
                              (v - intrinsics.cy) / intrinsics.fy, 1.0);
    double best = inf;
    id = -1;
    for (std::size_t b = 0; b < boxes.size(); ++b) {
      const Eigen::Vector3d o = T_box_camera[b].translation();
      const Eigen::Vector3d d = T_box_camera[b].linear() * ray;
      int axis = 2;
      const double s = boxEntry(o, d, boxes[b].half_size, axis); // camera depth
      if (s < best) {
        best = s;
        id = static_cast<int>(b);
        const Eigen::Vector3d hit = o + s * d;
        st = axis == 2   ? Eigen::Vector2d(hit.x(), hit.y())
             : axis == 1 ? Eigen::Vector2d(hit.x(), hit.z())
                         : Eigen::Vector2d(hit.y(), hit.z());
        seed = boxes[b].seed + (axis == 2 ? 0u : 7919u * (axis + 1));
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
      std::uint32_t seed = 0;
      int id = -1;
      const double z = cast(u, v, id, st, seed);
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
          cast(u + du, v + dv, sub_id, st, seed);
          sum += sub_id >= 0 ? textureGrey(seed, st.x(), st.y()) : 0;
        }
      p.r = p.g = p.b = static_cast<std::uint8_t>((sum + 2) / 4);
    }
  }
  return view;
}

/** \brief Ideal grid scene flow on the current grid (cell_size px cells centred on
 * cell_size * (col, row) + cell_size / 2, as GridSceneFlowEstimation writes it).
 *
 * b_i is the current point at the cell centre; a_i the same surface point in the previous
 * camera frame: moved back by object_motion when its box moves.
 * \param[in] current the current view, rendered from moveBoxes(boxes, object_motion)
 * \param[in] boxes the boxes in their previous poses (as given to moveBoxes)
 * \param[in] T_prev_curr current camera to previous camera
 * \param[in] object_motion world-frame motion of the moving boxes
 * \param[out] static_cell when not null, per cell: 1 when its centre sees a static box
 */
template <typename PointT>
pcl::PointCloud<PointFlow>
idealFlow(const RenderedView<PointT>& current,
          const std::vector<SceneBox>& boxes,
          const Eigen::Isometry3d& T_prev_curr,
          const Eigen::Isometry3d& T_world_prev,
          const Eigen::Isometry3d& object_motion,
          const CameraIntrinsics& intrinsics,
          std::uint32_t cell_size,
          std::vector<std::uint8_t>* static_cell = nullptr)
{
  const std::uint32_t width = current.cloud->width;
  const std::uint32_t cols = width / cell_size,
                      rows = current.cloud->height / cell_size;
  pcl::PointCloud<PointFlow> grid(cols, rows);
  if (static_cell)
    static_cell->assign(grid.size(), 0);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  // A moving point, in the previous camera: back through the object motion (world frame).
  const Eigen::Isometry3d T_unmove =
      T_world_prev.inverse() * object_motion.inverse() * T_world_prev;
  for (std::uint32_t row = 0; row < rows; ++row)
    for (std::uint32_t col = 0; col < cols; ++col) {
      const std::uint32_t u = col * cell_size + cell_size / 2;
      const std::uint32_t v = row * cell_size + cell_size / 2;
      PointFlow& f = grid(col, row);
      f.u = static_cast<float>(u);
      f.v = static_cast<float>(v);
      const int box = current.ids[std::size_t{v} * width + u];
      if (box < 0) {
        f.x = f.y = f.z = f.prev_x = f.prev_y = f.prev_z = f.prev_u = f.prev_v = nan;
        f.weight = 0.0f;
        f.valid_2d = f.valid_3d = 0;
        continue;
      }
      const Eigen::Vector3d b =
          (*current.cloud)(u, v).getVector3fMap().template cast<double>();
      Eigen::Vector3d a = T_prev_curr * b;
      if (boxes[box].moving)
        a = T_unmove * a;
      else if (static_cell)
        (*static_cell)[std::size_t{row} * cols + col] = 1;
      f.getVector3fMap() = b.cast<float>();
      f.prev_x = static_cast<float>(a.x());
      f.prev_y = static_cast<float>(a.y());
      f.prev_z = static_cast<float>(a.z());
      const Eigen::Vector2f p = intrinsics.project(a.cast<float>());
      f.prev_u = p.x();
      f.prev_v = p.y();
      f.weight = 1.0f;
      f.valid_2d = f.valid_3d = 1;
    }
  return grid;
}

} // namespace dynvo::test
