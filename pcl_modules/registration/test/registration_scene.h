// SPDX-License-Identifier: BSD-3-Clause
// The registration tests' scenes (a room with a moving box, a cluttered corner) and frame
// pairs, rendered by the shared generator of test/support/synthetic_scene.h.
#pragma once

#include <dynvo/common/camera.h>
#include <dynvo/common/flow_grid.h>
#include <dynvo/common/point_types.h>

#include "support/pose_compare.h"
#include "support/synthetic_scene.h"

#include <pcl/PointIndices.h>
#include <pcl/point_cloud.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cstdint>
#include <vector>

namespace dynvo::test {

constexpr std::uint32_t CELL = 16; ///< w_grid (px), docs/algorithm.md §0

// The ideal flow holds float copies of exact points at <= 4 m: round-off is ~2e-7 m per
// coordinate, so a fit on static cells only is exact within 1 mm and 0.05 degrees with a
// margin of three orders of magnitude, while any systematic error fails: a swapped direction
// (2 degrees / 3.7 cm in BoxScene::make()), an untrimmed outlier bias (> 1 mm) or a moving
// cell in the set (the box moves by 13 cm and 10 degrees).
constexpr double TRANSLATION_TOL = 1e-3;       ///< metres
constexpr double ROTATION_TOL = radians(0.05); ///< radians

/** \brief Boxes, a known camera motion and one independently moving box. The world frame is
 * the previous camera frame; the current camera sits at T_curr_prev^-1 and the moving boxes
 * are moved by object_motion (world frame).
 */
struct BoxScene {
  std::vector<SceneBox> boxes; ///< in their previous poses
  Eigen::Isometry3d T_curr_prev =
      Eigen::Isometry3d::Identity(); ///< camera motion (H_k)
  Eigen::Isometry3d object_motion =
      Eigen::Isometry3d::Identity(); ///< world motion of moving boxes
  CameraIntrinsics intrinsics;       ///< of a width x height image
  std::uint32_t width = 160;         ///< px
  std::uint32_t height = 120;        ///< px

  /// A room corner (back wall, floor, left wall), a static tilted box and a moving box, at
  /// 160x120 (or any size with the field of view of 640x480 at f = 525 px).
  static BoxScene make(std::uint32_t width = 160, std::uint32_t height = 120)
  {
    BoxScene scene;
    scene.width = width;
    scene.height = height;
    const double scale = width / 640.0;
    scene.intrinsics.fx = scene.intrinsics.fy = 525.0 * scale;
    scene.intrinsics.cx = (width - 1) / 2.0;
    scene.intrinsics.cy = (height - 1) / 2.0;
    const Eigen::Vector3d y = Eigen::Vector3d::UnitY();
    scene.add(makePose(y, 0.0, {0.0, 0.0, 3.5}), {3.0, 3.0, 0.05}, false); // back wall
    scene.add(makePose(y, 0.0, {0.0, 0.9, 2.0}), {3.0, 0.05, 2.5},
              false); // floor (y down)
    scene.add(makePose(y, 0.0, {-1.5, 0.0, 2.0}), {0.05, 3.0, 2.5}, false); // left wall
    scene.add(makePose(y, radians(30.0), {0.6, 0.55, 2.4}), {0.25, 0.3, 0.25},
              false);                                                      // static box
    scene.add(makePose(y, 0.0, {-0.3, -0.1, 1.6}), {0.3, 0.3, 0.2}, true); // moving box
    scene.T_curr_prev = makePose({0.3, 1.0, 0.2}, radians(2.0), {0.02, -0.01, 0.03});
    scene.object_motion = makePose({0.0, 0.0, 1.0}, radians(10.0), {0.12, 0.0, -0.05});
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
    scene.add(makePose({0.0, 1.0, 0.0}, 0.0, {0.0, 0.0, 2.2}), {3.0, 3.0, 0.05}, false);
    scene.add(makePose({0.2, 1.0, 0.1}, radians(35.0), {-0.45, -0.3, 1.6}),
              {0.25, 0.25, 0.25}, false);
    scene.add(makePose({1.0, 0.3, 0.0}, radians(40.0), {0.45, -0.25, 1.5}),
              {0.2, 0.25, 0.2}, false);
    scene.add(makePose({0.3, 0.2, 1.0}, radians(25.0), {0.4, 0.4, 1.7}),
              {0.3, 0.2, 0.2}, false);
    scene.add(makePose({0.0, 1.0, 0.0}, radians(-30.0), {-0.5, 0.45, 1.4}),
              {0.2, 0.15, 0.2}, false);
    scene.add(makePose({0.0, 1.0, 0.0}, 0.0, {0.0, 0.0, 1.2}), {0.1, 0.1, 0.1}, true);
    return scene;
  }

  /// Adds a box with its own texture seed.
  void add(const Eigen::Isometry3d& pose, const Eigen::Vector3d& half, bool moving)
  {
    boxes.push_back({pose, half, static_cast<std::uint32_t>(boxes.size()), moving});
  }

  /// Ray casts the previous (current = false) or current (current = true) frame.
  template <typename PointT> RenderedView<PointT> render(bool current) const
  {
    return current
               ? test::render<PointT>(moveBoxes(boxes, object_motion),
                                      T_curr_prev.inverse(), intrinsics, width, height)
               : test::render<PointT>(boxes, Eigen::Isometry3d::Identity(), intrinsics,
                                      width, height);
  }

  /// Ideal flow grid on the current frame; static_cells: 1 where the centre sees a static box.
  template <typename PointT>
  pcl::PointCloud<PointFlow> flow(const RenderedView<PointT>& current,
                                  std::vector<std::uint8_t>& static_cells) const
  {
    return idealFlow(current, boxes, T_curr_prev.inverse(),
                     Eigen::Isometry3d::Identity(), object_motion, intrinsics, CELL,
                     &static_cells);
  }
};

/// A frame pair of a box scene with its flow grid and the static cells.
template <typename PointT> struct FramePair {
  RenderedView<PointT> previous;
  RenderedView<PointT> current;
  pcl::PointCloud<PointFlow>::Ptr flow;
  std::vector<std::uint8_t> static_cells; ///< 1 where the cell centre sees a static box
  FlowGrid grid;                          ///< cell geometry of the flow

  explicit FramePair(const BoxScene& scene)
      : previous(scene.render<PointT>(false))
      , current(scene.render<PointT>(true))
      , grid(scene.width, scene.height, CELL)
  {
    flow.reset(new pcl::PointCloud<PointFlow>(scene.flow(current, static_cells)));
  }

  /// Sets a registration's source (current), target (previous) and flow.
  template <typename Registration> void feed(Registration& registration) const
  {
    registration.setInputSource(current.cloud);
    registration.setInputTarget(previous.cloud);
    registration.setInputFlow(flow);
  }

  /// The cells flagged in mask, labelled LABEL_STATIC on the flow's grid.
  FlowGrid cells(const std::vector<std::uint8_t>& mask) const
  {
    FlowGrid selected = grid;
    for (std::size_t i = 0; i < mask.size(); ++i)
      selected.labels[i] = mask[i] ? LABEL_STATIC : LABEL_NONE;
    return selected;
  }

  /// Every pixel of the cells flagged in mask, in increasing order.
  pcl::PointIndices::Ptr pixels(const std::vector<std::uint8_t>& mask) const
  {
    pcl::PointIndices::Ptr indices(new pcl::PointIndices);
    for (std::size_t i = 0; i < mask.size(); ++i)
      if (mask[i])
        grid.forEachPixel(i, [&](std::size_t index) {
          indices->indices.push_back(static_cast<int>(index));
        });
    std::sort(indices->indices.begin(), indices->indices.end());
    return indices;
  }

  /// Every pixel of the static cells.
  pcl::PointIndices::Ptr staticPixels() const { return pixels(static_cells); }

  /// The pixels of the static cells that see a static box (cells at the moving box's border
  /// also hold some of its pixels, which a point-based refinement must not get).
  pcl::PointIndices::Ptr staticSurfacePixels(const BoxScene& scene) const
  {
    pcl::PointIndices::Ptr indices = staticPixels();
    auto& list = indices->indices;
    list.erase(std::remove_if(list.begin(), list.end(),
                              [&](int index) {
                                const int box =
                                    current.ids[static_cast<std::size_t>(index)];
                                return box < 0 || scene.boxes[box].moving;
                              }),
               list.end());
    return indices;
  }

  std::size_t staticCellCount() const
  {
    return static_cast<std::size_t>(
        std::count(static_cells.begin(), static_cells.end(), std::uint8_t{1}));
  }
};

} // namespace dynvo::test
