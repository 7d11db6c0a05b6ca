// SPDX-License-Identifier: BSD-3-Clause
// Point types of dynvo, registered with PCL so that clouds of them can be saved as PCD.
#pragma once

#include <pcl/point_types.h>
#include <pcl/register_point_struct.h>

#include <cstdint>

namespace dynvo {

/** \brief One grid cell of the scene flow (docs/algorithm.md §1.2).
 *
 * x, y, z is the cell's point in the current camera frame k (the paper's b_i, metres);
 * prev_x, prev_y, prev_z the same physical point in the previous camera frame k-1 (a_i).
 * The flow of the cell is (x - prev_x, ...) once both are expressed in one frame.
 * Invalid cells hold NaN coordinates and weight 0.
 */
struct EIGEN_ALIGN16 PointFlow {
  PCL_ADD_POINT4D;       ///< current point b_i (metres, current camera frame)
  float prev_x;          ///< previous point a_i, x (metres, previous camera frame)
  float prev_y;          ///< previous point a_i, y (metres)
  float prev_z;          ///< previous point a_i, z (metres)
  float u;               ///< cell centre column in the current image (px)
  float v;               ///< cell centre row in the current image (px)
  float prev_u;          ///< tracked column in the previous image (px)
  float prev_v;          ///< tracked row in the previous image (px)
  float weight;          ///< confidence in [0, 1]; 0 for invalid cells
  std::uint8_t valid_2d; ///< 1 when the 2D track passed all checks
  std::uint8_t valid_3d; ///< 1 when both 3D points exist and passed the checks
  PCL_MAKE_ALIGNED_OPERATOR_NEW
};

} // namespace dynvo

// clang-format off
POINT_CLOUD_REGISTER_POINT_STRUCT(dynvo::PointFlow,
                                  (float, x, x)
                                  (float, y, y)
                                  (float, z, z)
                                  (float, prev_x, prev_x)
                                  (float, prev_y, prev_y)
                                  (float, prev_z, prev_z)
                                  (float, u, u)
                                  (float, v, v)
                                  (float, prev_u, prev_u)
                                  (float, prev_v, prev_v)
                                  (float, weight, weight)
                                  (std::uint8_t, valid_2d, valid_2d)
                                  (std::uint8_t, valid_3d, valid_3d))
// clang-format on
