// SPDX-License-Identifier: BSD-3-Clause
// An exact ray caster of boxes and an ideal grid scene flow, for registration tests with a
// known camera motion and one independently moving box.
#pragma once

#include <dynvo/common/camera.h>
#include <dynvo/common/point_types.h>

#include <pcl/PointIndices.h>
#include <pcl/point_cloud.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace dynvo::test {

/// An oriented box: |x_k| <= half_size_k in its own frame.
struct Box {
  Eigen::Isometry3d T_world_box =
      Eigen::Isometry3d::Identity();                   ///< box-to-world (metres)
  Eigen::Vector3d half_size = Eigen::Vector3d::Ones(); ///< metres
  bool moving = false; ///< moves by BoxScene::object_motion between the frames
};

/// Organized cloud plus the index of the box seen at each pixel (-1 = nothing).
template <typename PointT> struct RenderedFrame {
  typename pcl::PointCloud<PointT>::Ptr cloud;
  std::vector<int> box;
};

inline Eigen::Isometry3d
rigid(const Eigen::Vector3d& axis, double angle_deg, const Eigen::Vector3d& translation)
{
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() =
      Eigen::AngleAxisd(angle_deg * M_PI / 180.0, axis.normalized()).toRotationMatrix();
  T.translation() = translation;
  return T;
}

/// Ray parameter where o + s d enters the box |x_k| <= half_k (slab method); +inf on a miss or
/// when the entry lies behind the origin.
inline double
hitDepth(const Eigen::Vector3d& o,
         const Eigen::Vector3d& d,
         const Eigen::Vector3d& half)
{
  double enter = -std::numeric_limits<double>::infinity();
  double leave = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 3; ++k) {
    if (std::abs(d[k]) < 1e-12) {
      if (std::abs(o[k]) > half[k])
        return std::numeric_limits<double>::infinity();
      continue;
    }
    const double s1 = (-half[k] - o[k]) / d[k];
    const double s2 = (half[k] - o[k]) / d[k];
    enter = std::max(enter, std::min(s1, s2));
    leave = std::min(leave, std::max(s1, s2));
  }
  return enter <= leave && enter > 0.0 ? enter
                                       : std::numeric_limits<double>::infinity();
}

/** \brief A room corner (back wall, floor, left wall), a static tilted box and a moving box.
 * The world frame is the previous camera frame; the current camera sits at
 * T_world_curr = T_curr_prev^-1 and the moving box is moved by object_motion (world frame).
 */
struct BoxScene {
  std::vector<Box> boxes;
  Eigen::Isometry3d T_curr_prev =
      Eigen::Isometry3d::Identity(); ///< camera motion (H_k)
  Eigen::Isometry3d object_motion =
      Eigen::Isometry3d::Identity(); ///< world motion of moving boxes
  CameraIntrinsics intrinsics;       ///< of a width x height image
  std::uint32_t width = 160;
  std::uint32_t height = 120;

  /// The scene at 160x120 (or any size with the same field of view as 640x480 at f = 525).
  static BoxScene make(std::uint32_t width = 160, std::uint32_t height = 120)
  {
    BoxScene scene;
    scene.width = width;
    scene.height = height;
    const double scale = width / 640.0;
    scene.intrinsics.fx = scene.intrinsics.fy = 525.0 * scale;
    scene.intrinsics.cx = (width - 1) / 2.0;
    scene.intrinsics.cy = (height - 1) / 2.0;
    const auto add = [&scene](const Eigen::Isometry3d& pose, Eigen::Vector3d half,
                              bool moving) {
      scene.boxes.push_back(Box{pose, half, moving});
    };
    const Eigen::Vector3d y = Eigen::Vector3d::UnitY();
    add(rigid(y, 0.0, {0.0, 0.0, 3.5}), {3.0, 3.0, 0.05}, false); // back wall
    add(rigid(y, 0.0, {0.0, 0.9, 2.0}), {3.0, 0.05, 2.5},
        false); // floor (y points down)
    add(rigid(y, 0.0, {-1.5, 0.0, 2.0}), {0.05, 3.0, 2.5}, false); // left wall
    add(rigid(y, 30.0, {0.6, 0.55, 2.4}), {0.25, 0.3, 0.25},
        false);                                                   // static tilted box
    add(rigid(y, 0.0, {-0.3, -0.1, 1.6}), {0.3, 0.3, 0.2}, true); // moving object
    scene.T_curr_prev = rigid({0.3, 1.0, 0.2}, 2.0, {0.02, -0.01, 0.03});
    scene.object_motion = rigid({0.0, 0.0, 1.0}, 10.0, {0.12, 0.0, -0.05});
    return scene;
  }

  /** \brief A cluttered scene for nearest-neighbour refinement: a back wall at 2.2 m and
   * tilted boxes at 1.2-1.8 m seen at steep angles. (The room of make() shows the floor at
   * grazing angles, where 160x120 samples lie 8 cm apart in depth: too sparse for ICP.)
   */
  static BoxScene makeClutter()
  {
    BoxScene scene = make();
    scene.boxes.clear();
    const auto add = [&scene](const Eigen::Isometry3d& pose, Eigen::Vector3d half,
                              bool moving) {
      scene.boxes.push_back(Box{pose, half, moving});
    };
    add(rigid({0.0, 1.0, 0.0}, 0.0, {0.0, 0.0, 2.2}), {3.0, 3.0, 0.05}, false);
    add(rigid({0.2, 1.0, 0.1}, 35.0, {-0.45, -0.3, 1.6}), {0.25, 0.25, 0.25}, false);
    add(rigid({1.0, 0.3, 0.0}, 40.0, {0.45, -0.25, 1.5}), {0.2, 0.25, 0.2}, false);
    add(rigid({0.3, 0.2, 1.0}, 25.0, {0.4, 0.4, 1.7}), {0.3, 0.2, 0.2}, false);
    add(rigid({0.0, 1.0, 0.0}, -30.0, {-0.5, 0.45, 1.4}), {0.2, 0.15, 0.2}, false);
    add(rigid({0.0, 1.0, 0.0}, 0.0, {0.0, 0.0, 1.2}), {0.1, 0.1, 0.1}, true);
    return scene;
  }

  /// Box pose at the previous (current = false) or current (true) frame.
  Eigen::Isometry3d boxPose(const Box& box, bool current) const
  {
    return current && box.moving ? object_motion * box.T_world_box : box.T_world_box;
  }

  /// Ray casts the previous (current = false) or current (current = true) frame.
  template <typename PointT> RenderedFrame<PointT> render(bool current) const
  {
    const Eigen::Isometry3d T_world_cam =
        current ? T_curr_prev.inverse() : Eigen::Isometry3d::Identity();
    RenderedFrame<PointT> frame;
    frame.cloud.reset(new pcl::PointCloud<PointT>(width, height));
    frame.box.assign(std::size_t{width} * height, -1);
    const float nan = std::numeric_limits<float>::quiet_NaN();
    for (std::uint32_t v = 0; v < height; ++v)
      for (std::uint32_t u = 0; u < width; ++u) {
        // Ray o + z * d with d = [(u - cx) / fx, (v - cy) / fy, 1] in the camera: z is depth.
        const Eigen::Vector3d d_cam((u - intrinsics.cx) / intrinsics.fx,
                                    (v - intrinsics.cy) / intrinsics.fy, 1.0);
        double best = std::numeric_limits<double>::infinity();
        int best_box = -1;
        for (std::size_t b = 0; b < boxes.size(); ++b) {
          const Eigen::Isometry3d T_box_cam =
              boxPose(boxes[b], current).inverse() * T_world_cam;
          const double z = hitDepth(T_box_cam * Eigen::Vector3d::Zero(),
                                    T_box_cam.linear() * d_cam, boxes[b].half_size);
          if (z < best) {
            best = z;
            best_box = static_cast<int>(b);
          }
        }
        PointT& p = (*frame.cloud)(u, v);
        p.r = p.g = p.b = static_cast<std::uint8_t>(40 + 40 * (best_box + 1));
        if (best_box < 0) {
          p.x = p.y = p.z = nan;
          continue;
        }
        p.getVector3fMap() = (best * d_cam).cast<float>();
        frame.box[std::size_t{v} * width + u] = best_box;
      }
    frame.cloud->is_dense = false;
    return frame;
  }

  /** \brief Ideal grid scene flow on the current grid (cell_size px cells centred on
   * cell_size * (col, row) + cell_size / 2, as GridSceneFlowEstimation writes it).
   * \param[in] current the rendered current frame
   * \param[out] static_cell per cell: 1 when its centre sees a static box
   */
  template <typename PointT>
  pcl::PointCloud<PointFlow> flow(const RenderedFrame<PointT>& current,
                                  std::uint32_t cell_size,
                                  std::vector<std::uint8_t>& static_cell) const
  {
    const std::uint32_t cols = width / cell_size, rows = height / cell_size;
    pcl::PointCloud<PointFlow> grid(cols, rows);
    static_cell.assign(grid.size(), 0);
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const Eigen::Isometry3d T_prev_curr = T_curr_prev.inverse();
    for (std::uint32_t row = 0; row < rows; ++row)
      for (std::uint32_t col = 0; col < cols; ++col) {
        const std::uint32_t u = col * cell_size + cell_size / 2;
        const std::uint32_t v = row * cell_size + cell_size / 2;
        PointFlow& f = grid(col, row);
        f.u = static_cast<float>(u);
        f.v = static_cast<float>(v);
        const int box = current.box[std::size_t{v} * width + u];
        if (box < 0) {
          f.x = f.y = f.z = f.prev_x = f.prev_y = f.prev_z = f.prev_u = f.prev_v = nan;
          f.weight = 0.0f;
          f.valid_2d = f.valid_3d = 0;
          continue;
        }
        const Eigen::Vector3d b =
            (*current.cloud)(u, v).getVector3fMap().template cast<double>();
        // World = previous camera frame; a moving point is moved back by the object motion.
        Eigen::Vector3d a = T_prev_curr * b;
        if (boxes[box].moving)
          a = object_motion.inverse() * a;
        else
          static_cell[std::size_t{row} * cols + col] = 1;
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
};

/// Every pixel of the cells flagged in cell_mask (cell_size px cells on a width-wide image).
inline pcl::PointIndices::Ptr
cellPixels(const std::vector<std::uint8_t>& cell_mask,
           std::uint32_t cols,
           std::uint32_t cell_size,
           std::uint32_t width)
{
  pcl::PointIndices::Ptr indices(new pcl::PointIndices);
  for (std::size_t i = 0; i < cell_mask.size(); ++i) {
    if (!cell_mask[i])
      continue;
    const std::uint32_t col = i % cols, row = i / cols;
    for (std::uint32_t v = row * cell_size; v < (row + 1) * cell_size; ++v)
      for (std::uint32_t u = col * cell_size; u < (col + 1) * cell_size; ++u)
        indices->indices.push_back(static_cast<int>(v * width + u));
  }
  std::sort(indices->indices.begin(), indices->indices.end());
  return indices;
}

/// Rotation angle (degrees) between two rigid transformations. atan2 of the skew and symmetric
/// parts stays accurate near 0, where acos((trace - 1) / 2) would turn the 1e-7 round-off of a
/// float rotation into 0.03 degrees.
inline double
rotationErrorDeg(const Eigen::Matrix4f& A, const Eigen::Matrix4d& B)
{
  const Eigen::Matrix3d dR =
      A.topLeftCorner<3, 3>().cast<double>().transpose() * B.topLeftCorner<3, 3>();
  const Eigen::Vector3d skew(dR(2, 1) - dR(1, 2), dR(0, 2) - dR(2, 0),
                             dR(1, 0) - dR(0, 1));
  return std::atan2(skew.norm() / 2.0, (dR.trace() - 1.0) / 2.0) * 180.0 / M_PI;
}

/// Translation distance (metres) between two rigid transformations.
inline double
translationError(const Eigen::Matrix4f& A, const Eigen::Matrix4d& B)
{
  return (A.topRightCorner<3, 1>().cast<double>() - B.topRightCorner<3, 1>()).norm();
}

} // namespace dynvo::test
