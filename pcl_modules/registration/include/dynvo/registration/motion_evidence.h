// SPDX-License-Identifier: BSD-3-Clause
// Per-cell evidence of motion relative to the camera's, accumulated over frames
// (docs/algorithm.md §7.6).
#pragma once

#include <dynvo/common/export.h>
#include <dynvo/common/flow_grid.h>
#include <dynvo/common/parameter_table.h>
#include <dynvo/common/point_types.h>
#include <dynvo/common/sensor_noise_model.h>

#include <pcl/point_cloud.h>

#include <Eigen/Core>

#include <string>
#include <vector>

namespace dynvo {

/// Parameters of MotionEvidence (the single source of the defaults).
struct DYNVO_EXPORTS MotionEvidenceParameters {
  /// kappa (> 0): subtracted from every cell's normalised chi-square each frame. Between the
  /// static mean (3, three degrees of freedom) and a slow mover's; a static cell's evidence
  /// drifts down by about kappa - 3 per frame.
  float evidence_drift = 5.0f;
  /// c (> 0): largest contribution of one frame, so that a single bad track cannot flag a
  /// cell on its own.
  float evidence_clip = 25.0f;
  /// h (>= 0, 0 = off): a cell whose evidence exceeds h is left out of the static set. The
  /// evidence is kept below 2 h, so a mover that stops rejoins after about h / (kappa - 3)
  /// frames (10 with the defaults).
  float evidence_limit = 20.0f;

  /// Names, units and ranges of the fields above, in file order (ParameterTable).
  static const ParameterTable<MotionEvidenceParameters>& table();
  /// \throws std::invalid_argument naming the first field out of the range stated above
  void validate() const;
};

/** \brief Per-cell sequential test (CUSUM) of "this cell moves with the static scene",
 * accumulated along the flow over frames (docs/algorithm.md §7.6, not in the paper).
 *
 * A mover that is only two to four sigma off the camera's motion per frame pair falls into
 * the background's segment whenever it is not already apart, and a near, well-textured one
 * then outweighs the background in the fit. Its residual under the final camera motion is
 * small in one frame but steady, so the evidence adds up over frames while a static cell's
 * falls back to zero:
 *
 *   S_i = min(2 h, max(0, S~_i + min(chi2_i, c) - kappa)),
 *
 * where chi2_i = e^T (Sigma(a_i) + Sigma(b_i))^-1 e with e = T_prev_curr b_i - a_i under the
 * sensor model at gains 1, scaled down so that its median over the cells not flagged is at
 * most the chi-square median with three degrees of freedom (2.366): a frame whose fit or flow
 * is worse as a whole does not count as motion, and a quieter frame does not make a residual
 * within the model's noise one. S~_i is the evidence of the previous cell that p_i falls in
 * (nearest), 0 for a cell without a 2D track.
 *
 * Per frame: predict() with the frame's flow carries the evidence into the current grid and
 * says which cells are moving (getMovingCells(); used to leave them out of every fit of
 * StaticSetSelection), then update() with the frame's final camera motion adds the frame.
 * \code
 * dynvo::MotionEvidence evidence;
 * evidence.setSensorNoise(noise, focal);
 * evidence.predict(*flow, cloud->width, cloud->height);
 * selection.setMovingCells(evidence.getMovingCells());
 * ...                                                  // the fits
 * evidence.update(*flow, T_prev_curr);                 // the frame's final motion
 * \endcode
 */
class DYNVO_EXPORTS MotionEvidence {
public:
  using Parameters = MotionEvidenceParameters;
  using FlowCloud = pcl::PointCloud<PointFlow>;

  /// Name used in log prefixes: "MotionEvidence".
  const std::string& getClassName() const { return class_name_; }

  /// All knobs at once. \throws std::invalid_argument when parameters.validate() fails
  void setParameters(const Parameters& parameters);

  const Parameters& getParameters() const { return params_; }

  /// The sensor model of chi2_i (gains 1) and the focal length (px) of its lateral term.
  void setSensorNoise(const SensorNoiseModel& noise, float focal);

  /** \brief Carries the evidence into the grid of flow (computed on a width x height
   * image) and marks the cells above the limit in getMovingCells(). A flow whose grid
   * differs from the last one's, or no evidence yet, starts every cell at 0.
   */
  void predict(const FlowCloud& flow, std::uint32_t width, std::uint32_t height);

  /// Adds this frame's chi-square under T_prev_curr (the frame's final camera motion, maps
  /// current points into the previous frame) to the evidence predict() carried over.
  void update(const FlowCloud& flow, const Eigen::Matrix4d& T_prev_curr);

  /// Cells whose evidence exceeds the limit, labelled LABEL_STATIC + 1 (others LABEL_NONE);
  /// the flow's grid after predict(), empty before.
  const FlowGrid& getMovingCells() const { return moving_; }

  /// Evidence per cell of the current grid (after update(): this frame's).
  const std::vector<float>& getEvidence() const { return evidence_; }

  /// Forgets the evidence.
  void reset();

private:
  std::string class_name_ = "MotionEvidence"; ///< log prefix
  Parameters params_;                         ///< validated knobs
  SensorNoiseModel noise_;                    ///< chi2_i's model, gains 1
  float focal_ = 525.0f;                      ///< px
  FlowGrid moving_;                           ///< cells above the limit
  std::vector<float> evidence_;               ///< per cell of the current grid
};

} // namespace dynvo
