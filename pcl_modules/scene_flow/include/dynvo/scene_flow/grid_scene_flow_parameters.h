// SPDX-License-Identifier: BSD-3-Clause
// Every knob of the grid scene flow stage (docs/algorithm.md §1 and §9).
#pragma once

#include <dynvo/common/export.h>
#include <dynvo/common/parameter_table.h>
#include <dynvo/scene_flow/depth_preprocessing.h>

namespace dynvo {

/// How the forward-backward check of docs/algorithm.md §1.2 tracks p_i back into the
/// current image.
enum class ForwardBackwardCheck {
  full, ///< from scratch through the whole pyramid, as the paper states (cost x2)
  local, ///< started at c_i on the finest level only (about a quarter of the forward cost):
  ///< rejects tracks whose reverse LK does not stay at c_i, not far-away wrong matches
};

/** \brief Parameters of GridSceneFlowEstimation (the single source of the defaults).
 *
 * The Lucas-Kanade defaults differ from the paper's (docs/algorithm.md §1.2: window
 * 21, maxLevel 3, 30 iterations,
 * eps 0.01, backward track from scratch): those cost about 25 ms per VGA frame on one core of
 * the target machine (docs/platform.md), against a budget of 8 ms for the whole stage.
 * Window 13,
 * maxLevel 2, 8 iterations, eps 0.03 and the local check keep the synthetic end-point error at
 * about 0.1 px (VGA, 15-27 px of flow) and the share of valid cells on TUM fr1/xyz within 3
 * points of the paper's settings; the measurements are in pcl_modules/scene_flow/NOTES.md.
 */
struct DYNVO_EXPORTS GridSceneFlowParameters {
  /// w_grid (px, >= 2): cell size; cell (col, row) is centred on pixel
  /// (col, row) * cell_size + cell_size / 2.
  int cell_size = 16;
  /// z_min, z_max, tau_fly, w_hole, tau_fill (docs/algorithm.md §1.1).
  DepthPreprocessing::Parameters depth;
  /// LK win (px, >= 3): side of the square LK window (paper: 21). 16 because LK works on
  /// rows in steps of 16 pixels (AVX2) or 8 and does the rest one by one: 16 costs less
  /// than 13 (docs/algorithm.md §1.2).
  int window_size = 16;
  /// LK levels (>= 0): OpenCV maxLevel, 0 = no pyramid (paper: 3).
  int max_pyramid_level = 2;
  /// LK iters (>= 1): iteration cap per pyramid level (paper: 30).
  int max_iterations = 8;
  /// LK eps (px, > 0): stop iterating when an update is shorter (paper: 0.01).
  double epsilon = 0.03;
  /// OpenCV minEigThreshold (> 0): rejects textureless windows.
  double min_eigen_threshold = 1e-4;
  /// Backward tracking scheme of the forward-backward check (paper: full).
  ForwardBackwardCheck forward_backward_check = ForwardBackwardCheck::local;
  /// fb_max (px, > 0): largest |c' - c| accepted by the forward-backward check.
  float forward_backward_threshold = 1.0f;
  /// tau_edge (relative, >= 0): bilinear depth needs (max - min) <= tau_edge * min.
  float depth_edge_tolerance = 0.05f;
  /// Depth window radius r (px, 0..15): with r > 0 the depths of a_i and b_i come from a
  /// plane fitted in inverse depth (exact for planar surfaces) to every other pixel of the
  /// (2r + 1)^2 window around the point whose depth is within tau_edge of the single-pixel
  /// value, evaluated at the point. This averages out most of the sensor's per-pixel noise
  /// and disparity quantisation; 0 = the paper's single pixel.
  int depth_window_radius = 0;
  /// max_flow3d (metres per frame, > 0): a larger |b - a| is a gross error.
  float max_flow = 0.5f;
  /// z_ref (metres, > 0): weight = min(1, (z_ref / z)^4), the inverse of the depth-noise
  /// variance (sigma_z grows as z^2) relative to z_ref; z = the larger of the two depths.
  float weight_reference_depth = 1.5f;

  /// Names, units and ranges of the fields above (depth as "depth.<field>"), in file order.
  static const ParameterTable<GridSceneFlowParameters>& table();

  /// \throws std::invalid_argument naming the first field out of the range stated above,
  ///         or depth.validate()'s reason
  void validate() const;
};

} // namespace dynvo
