// SPDX-License-Identifier: BSD-3-Clause
// Structure-of-arrays view of one grid scene flow (docs/algorithm.md §1.2).
#pragma once

#include <dynvo/common/export.h>
#include <dynvo/common/flow_grid.h>
#include <dynvo/common/point_types.h>
#include <dynvo/common/sensor_noise_model.h>

#include <pcl/point_cloud.h>

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace dynvo {

/** \brief Per-cell scene flow on plain buffers, cell i = row * cols + col.
 *
 * Filled from the organized PointFlow cloud of GridSceneFlowEstimation, so that the
 * segmentation and tracking math compiles once, independent of the point type.
 */
struct DYNVO_EXPORTS GridFlowData {
  FlowGrid geometry; ///< cells, cell size and image size (its labels are unused)
  std::vector<std::uint8_t> valid_2d; ///< 1 when the 2D track p_i is valid
  std::vector<std::uint8_t> valid_3d; ///< 1 when a_i and b_i are valid
  std::vector<Eigen::Vector2f>
      previous_pixel; ///< p_i (px, previous image); NaN when !valid_2d
  std::vector<Eigen::Vector3f>
      a; ///< a_i (metres, previous camera frame); NaN when missing
  std::vector<Eigen::Vector3f>
      b; ///< b_i (metres, current camera frame); NaN when no depth at c_i
  /// W_i, information matrix of the transfer error (sensor model: E_i = e^T W_i e, in
  /// sigma^2); empty for the paper model (W_i = I, E_i in m^2)
  std::vector<Eigen::Matrix3f> information;

  /// Number of cells.
  std::size_t size() const { return valid_3d.size(); }

  /// Gx, grid columns.
  int cols() const { return static_cast<int>(geometry.cols); }

  /// Gy, grid rows.
  int rows() const { return static_cast<int>(geometry.rows); }

  /// w_grid (px).
  int cellSize() const { return static_cast<int>(geometry.cell_size); }

  /// Centre c_i of cell i (px, current image).
  Eigen::Vector2f cellCentre(std::size_t i) const { return geometry.centre(i); }

  /** \brief Copies an organized flow grid.
   * \param[in] flow organized cloud as computed by GridSceneFlowEstimation
   * \param[in] grid its geometry (FlowGrid::fromFlow()); only the geometry is kept
   */
  void assign(const pcl::PointCloud<PointFlow>& flow, const FlowGrid& grid);

  /// E_i of cell i under the motion (R, t) mapping a_i to b_i: ||R a_i + t - b_i||^2, or
  /// e^T W_i e with the information matrices (docs/algorithm.md §2).
  float error(std::size_t i, const Eigen::Matrix3f& R, const Eigen::Vector3f& t) const
  {
    const Eigen::Vector3f e = R * a[i] + t - b[i];
    return information.empty() ? e.squaredNorm() : e.dot(information[i] * e);
  }

  /** \brief Fills information for the sensor model: per cell
   * noise.transferInformation(a_i, b_i, focal, axial_gain, lateral_gain), zero for cells
   * without valid_3d.
   */
  void setSensorNoise(const SensorNoiseModel& noise,
                      float focal,
                      float axial_gain,
                      float lateral_gain);
};

} // namespace dynvo
