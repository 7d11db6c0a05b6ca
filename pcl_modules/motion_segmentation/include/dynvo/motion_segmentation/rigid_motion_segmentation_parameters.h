// SPDX-License-Identifier: BSD-3-Clause
// Every knob of the rigid motion segmentation and tracking stages (docs/algorithm.md
// §3-§6, §9).
#pragma once

#include <dynvo/common/export.h>
#include <dynvo/common/parameter_table.h>
#include <dynvo/common/sensor_noise_model.h>

#include <cstdint>

namespace dynvo {

/// How the transfer error E_i of a cell under a motion is measured (docs/algorithm.md §2).
enum class ResidualModel {
  paper, ///< E_i = ||R a_i + t - b_i||^2 (m^2), the paper's fixed metric tests
  sensor ///< E_i = e^T (Sigma(a_i) + Sigma(b_i))^-1 e (gains applied): in sigma^2
};

/** \brief Parameters of RigidMotionSegmentation (the single source of the defaults).
 *
 * Names in parentheses are the docs/algorithm.md §9 symbols. Validation ranges follow
 * each field.
 */
struct DYNVO_EXPORTS RigidMotionSegmentationParameters {
  /// h_max (1..254): accepted hypotheses per frame
  int max_hypotheses = 20;
  /// T_max (>= max_hypotheses): trials per frame, failed ones included
  int max_trials = 200;
  /// m (>= 3): points per hypothesis
  int sample_size = 7;
  /// r_search (grid cells, Chebyshev, >= 1): seed neighbourhood. The paper says 2 (5x5);
  /// 1 (3x3) is our default: a 5x5 window around a seed on an object of 6x3 cells (0.6 x 0.3 m
  /// at 3 m) nearly always holds boundary cells with mixed flow, so its 7-point samples fail.
  /// Measured on static_two (VGA, 40 frames): moving-object cell IoU 0.62 with 2, 0.81 with 1.
  int search_radius = 1;
  /// Unit of E_i: the paper's squared metres or the noise-normalised Mahalanobis distance.
  ResidualModel residual_model = ResidualModel::sensor;
  /// th_inlier (m^2, > 0), paper model: E_i <= th_inlier is an inlier (5.5 mm);
  /// dynvo::app::PipelineOptions raises it to 6e-5 for real Kinect noise
  float inlier_threshold = 3e-5f;
  /// th_chi2 (sigma^2, > 0), sensor model: E_i <= th_chi2 is an inlier (16: 0.1 % of
  /// static cells fail, chi-square with 3 degrees of freedom)
  float inlier_chi2 = 16.0f;
  /// lambda_chi2 (sigma^-2, > 0), sensor model: entropy shape. The paper's lambda times
  /// th_inlier / th_chi2, so the entropy at the inlier radius is the paper's.
  float sensor_entropy_lambda = 1.875e-3f;
  /// eps_chi2 (sigma, > 0), sensor model: DBSCAN radius. The paper's eps times
  /// sqrt(th_chi2 / th_inlier): the same ratio to the inlier radius.
  float sensor_dbscan_epsilon = 3.65f;
  /// Shape of the per-point covariance Sigma (sensor model).
  SensorNoiseModel noise;
  /// s_min (> 0): smallest noise gain. Two gains (axial, lateral) multiply the sensor
  /// model's sigmas and are fitted to the residuals near the background's motion every
  /// frame (docs/algorithm.md §3.0). 0.2: 0.12 px across the ray, well below real tracking
  /// (0.3-0.8 px on TUM fr1/xyz) and above the synthetic scenes' 0.03 px, which would let
  /// every 7-point hypothesis explain only its own neighbourhood.
  float noise_scale_min = 0.2f;
  /// s_max (>= s_min): largest noise gain
  float noise_scale_max = 4.0f;
  /// lambda (m^-2, > 0): entropy shape, S = 1 - exp(-delta - lambda E)
  float entropy_lambda = 1e3f;
  /// delta (> 0): entropy floor
  float entropy_delta = 1e-2f;
  /// refine_iters (>= 1): inlier/refit rounds per hypothesis
  int refine_iterations = 2;
  /// s_done (0..1): mean entropy low enough to stop. The paper says 0.15, but objects
  /// cover a few % of the cells, so the mean is below 0.15 as soon as the background is
  /// explained and the search stopped before any object was hypothesised (IoU 0.28 on
  /// static_two). 0.012 = the floor S_min = 1 - e^-delta (0.00995) + 0.2 %: stop only when
  /// nearly every valid cell is explained.
  float entropy_done = 0.012f;
  /// s_sat (>= 0): smallest mean-entropy drop that continues the search
  float entropy_saturation = 0.005f;
  /// p_min (>= 1): DBSCAN core size (1 = connected components)
  int dbscan_min_points = 1;
  /// eps (m, > 0): motion-field distance joining two hypotheses
  float dbscan_epsilon = 0.005f;
  /// n_seg_min (cells, >= 1): smaller segments are dissolved
  int min_segment_size = 7;
  /// false: segment() returns the two-frame result (largest segment = label 1)
  bool tracking = true;
  /// n_obj (2..254): label ids 1..n_obj, 1 = static background
  int max_labels = 15;
  /// alpha_max (frames, >= 1): model age saturation and swap age
  float max_age = 5.0f;
  /// L_buf (frames, >= 1): past label maps used for matching
  int buffer_length = 5;
  /// c_min (0..1]: smallest correlation C_ij that matches
  float min_correlation = 0.2f;
  /// tau_cv (m, > 0): largest RMS residual under H_pred of the background segment
  float static_guard_tolerance = 0.03f;
  /// n_static_min (cells, >= 1): smallest segment that may take label 1
  int static_min_cells = 20;
  /// k_sep (>= 0, 0 = off) [D]: an object merged into the background segment keeps its cells
  /// while they fit the background's motion k_sep times worse (RMS residual) than their own.
  /// 3: measured largest ratio on TUM fr1/xyz (static scene, spurious objects) 2.8; a box
  /// covering 80 % of the image at 1.5-6 mm per frame relative motion 7.8-26.
  float object_separation_ratio = 3.0f;
  /// k_hold (1..k_sep) [D]: the ratio that keeps an object apart once it has been kept apart
  /// (hysteresis). 1.15: the moving_occluder box's ratio falls to 1.2 while it turns round at
  /// 80 % of the image; a still object's is 1 (its own fit's 6 degrees of freedom discounted).
  float object_separation_hold = 1.15f;
  /// n_birth (frames, >= 1; 1 = off) [D]: an object is output (segments, pixel labels, ids)
  /// from its n_birth-th consecutive frame; before that its pixels are static in the output,
  /// and its cells stay out of the ego-motion fit. 3: on TUM fr1/xyz (static scene) 42 of 69
  /// spurious objects last one frame and 58 at most three.
  int object_birth_frames = 3;
  /// k_birth (>= 0, 0 = off) [D]: a new object whose cells fit the background's motion k_birth
  /// times worse (RMS) than their own is output at once. 5: TUM fr1/xyz's spurious objects
  /// mostly stay below it (moving_share 0.045 with 3, 0.033 with 5, 0.029 with 8), the
  /// synthetic objects entering or starting again pass it (enter_stop_leave loses moving_iou
  /// from 8 on).
  float object_birth_ratio = 5.0f;
  /// r_amb (px, >= 0, 0 = off) [D]: the ambiguity test (docs/algorithm.md §4.1) searches
  /// frame k-1 within r_amb px of where the background's motion puts a cell, and calls the
  /// cell far from it beyond 2 r_amb. 3: on TUM fr1/xyz the background's positions of
  /// aliased keyboard cells lie 20-24 px from their tracks, and their best matches within
  /// 1-3 px of those positions.
  int ambiguity_search_radius = 3;
  /// seed: hypothesis sampling RNG, re-seeded on every segment()
  std::uint32_t seed = 0;

  /// Names, units and ranges of the fields above, in file order (ParameterTable).
  static const ParameterTable<RigidMotionSegmentationParameters>& table();

  /// \throws std::invalid_argument naming the first field out of the range stated above,
  ///         including the rules that tie two fields (max_trials, object_separation_hold)
  void validate() const;
};

} // namespace dynvo
