// SPDX-License-Identifier: BSD-3-Clause
// Every knob of the grid scene flow stage (ALGORITHM.md §1 and §9).
#pragma once

#include <dynvo/common/export.h>
#include <dynvo/scene_flow/depth_preprocessing.h>

namespace dynvo {

/// How the forward-backward check of ALGORITHM.md §1.2 tracks p_i back into the current image.
enum class ForwardBackwardCheck {
  full,  ///< from scratch through the whole pyramid, as ALGORITHM.md §1.2 states (cost x2)
  local, ///< started at c_i on the finest level only (about a quarter of the forward cost):
         ///< rejects tracks whose reverse LK does not stay at c_i, not far-away wrong matches
};

/** \brief Parameters of GridSceneFlowEstimation (the single source of the defaults).
 *
 * The Lucas-Kanade settings differ from ALGORITHM.md §1.2 (window 21, maxLevel 3, 30 iterations,
 * eps 0.01): those cost about 20 ms per VGA frame with the forward-backward check on one core
 * (PLATFORM.md), against a budget of 8 ms for the whole stage. The defaults below were chosen by
 * measurement on TUM fr1/xyz and synthetic frame pairs (see pcl_modules/scene_flow/NOTES.md).
 */
struct DYNVO_EXPORTS GridSceneFlowParameters {
  int cell_size = 16; ///< w_grid (px, >= 2): grid cell size; cell (col, row) is centred on pixel (col, row) * cell_size + cell_size / 2
  DepthPreprocessing::Parameters depth; ///< z_min, z_max, tau_fly, w_hole, tau_fill (ALGORITHM.md §1.1)
  int window_size = 15;        ///< LK win (px, >= 3): side of the square LK window
  int max_pyramid_level = 3;   ///< LK levels (>= 0): OpenCV maxLevel, 0 = no pyramid
  int max_iterations = 10;     ///< LK iters (>= 1): iteration cap per pyramid level
  double epsilon = 0.03;       ///< LK eps (px, > 0): stop when an update is shorter
  double min_eigen_threshold = 1e-4; ///< OpenCV minEigThreshold (> 0): rejects textureless windows
  ForwardBackwardCheck forward_backward_check = ForwardBackwardCheck::local; ///< backward tracking scheme
  float forward_backward_threshold = 1.0f; ///< fb_max (px, > 0): largest |c' - c| of the forward-backward check
  float depth_edge_tolerance = 0.05f; ///< tau_edge (relative, >= 0): bilinear depth needs (max - min) <= tau_edge * min
  float max_flow = 0.5f;       ///< max_flow3d (metres per frame, > 0): larger |b - a| is a gross error
  float weight_reference_depth = 1.5f; ///< z_ref (metres, > 0): weight = min(1, (z_ref / z)^4), the inverse of the z^2 depth-noise variance

  /// \throws std::invalid_argument naming the first field out of the range stated above
  void
  validate() const;
};

} // namespace dynvo
