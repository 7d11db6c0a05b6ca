// SPDX-License-Identifier: BSD-3-Clause
// The ego-motion policy: which cells count as static, with the motion guard
// (docs/algorithm.md §7).
#pragma once

#include <dynvo/common/flow_grid.h>
#include <dynvo/common/point_types.h>
#include <dynvo/registration/static_scene_registration.h>
#include <dynvo/registration/static_set_selection_parameters.h>

#include <pcl/point_cloud.h>

#include <Eigen/Core>

#include <string>

namespace dynvo {

/** \brief Chooses the static cells of a frame and drives StaticSceneRegistration on them
 * (docs/algorithm.md §7): up to four fits per frame.
 *
 * 1. First fit on the segmentation's static cells (setCellLabels(): cells labelled
 *    LABEL_STATIC), started from the prediction H_pred (setPredictedMotion()).
 * 2. Motion guard: when that fit failed or its translation departs from H_pred by more than
 *    tau_cv (setMotionGuardTolerance(), metres), a fit on the valid cells whose flow agrees
 *    with H_pred within tau_cv (squared transfer error <= tau_cv^2) replaces it, and the
 *    labels are not trusted for step 3.
 * 3. Static consensus: the final fit on every valid cell whose flow agrees with the fit so
 *    far within static_consensus times the inlier threshold in use (setInlierThreshold(),
 *    m^2), leaving out the cells labelled as objects (label > LABEL_STATIC) when the labels
 *    are trusted. Background cells the segmentation split off count again; moving objects
 *    stay out.
 * 4. Surface contest: the valid cells step 3 left out are fitted on their own; when that
 *    motion's consensus covers more than twice the surface of step 3's (sum of z^2), it is
 *    the background's, and its cells and motion replace step 3's.
 * The moving cells of setMovingCells() (MotionEvidence's, docs/algorithm.md §7.6) are left
 * out of every step whatever their label.
 * Steps 2 to 4 run only when static_consensus > 0. Without labels (clearCellLabels(), the
 * default) every valid flow cell is static and only step 1 runs (the pipeline's ablation
 * without segmentation). Labels whose grid is not the flow's (e.g. the empty grid of a failed
 * segmentation) select no cell for step 1 and are never trusted.
 *
 * The registration's source, target and flow are set by the caller; align() sets its static
 * cells and leaves the last fit in it (hasConverged(), getFinalTransformation() =
 * T_prev_curr, getMeanSquaredResidual()).
 * \code
 * dynvo::StaticSetSelection<pcl::PointXYZRGB> selection;
 * registration.setInputSource(current);
 * registration.setInputTarget(previous);
 * registration.setInputFlow(flow);
 * selection.setCellLabels(segmentation.getCellGrid());
 * selection.setInlierThreshold(threshold);                     // m^2, this frame's
 * selection.setMotionGuardTolerance(tau_cv);                   // metres
 * selection.setPredictedMotion(T_curr_prev_predicted);
 * if (selection.align(registration)) T_prev_curr = registration.getFinalTransformation();
 * \endcode
 * Not thread-safe; separate instances may run concurrently. Explicitly instantiated for
 * pcl::PointXYZRGB and pcl::PointXYZRGBA (other types: include the impl .hpp).
 */
template <typename PointT> class StaticSetSelection {
public:
  using Registration = StaticSceneRegistration<PointT>;
  using FlowCloud = pcl::PointCloud<PointFlow>;
  using Parameters = StaticSetSelectionParameters;

  /// Name used in log prefixes: "StaticSetSelection".
  const std::string& getClassName() const { return class_name_; }

  /// All knobs at once. \throws std::invalid_argument when parameters.validate() fails
  void setParameters(const Parameters& parameters)
  {
    parameters.validate();
    assignParameters(parameters);
  }

  const Parameters& getParameters() const { return params_; }

  // A setter throws std::invalid_argument when the value is outside the field's own range
  // (StaticSetSelectionParameters::table()) and keeps the old value.
  DYNVO_PARAMETER_ACCESSORS(StaticConsensus, static_consensus)

  /// The segmentation's cell labels of this frame (RigidMotionSegmentation::getCellGrid()).
  void setCellLabels(const FlowGrid& labels)
  {
    labels_ = labels;
    use_labels_ = true;
  }

  /// No labels: every valid flow cell is static, one fit.
  void clearCellLabels()
  {
    labels_ = FlowGrid();
    use_labels_ = false;
  }

  /** \brief Cells left out of every fit whatever their label (MotionEvidence's moving cells:
   * labels other than LABEL_NONE); an empty grid, or one that is not the flow's, leaves none
   * out (the default).
   */
  void setMovingCells(const FlowGrid& moving) { moving_ = moving; }

  /// Segmentation inlier threshold in use this frame (m^2, default 3e-5).
  void setInlierThreshold(double threshold) { inlier_threshold_ = threshold; }

  double getInlierThreshold() const { return inlier_threshold_; }

  /// tau_cv (metres, default 0.03): the segmentation's static_guard_tolerance.
  void setMotionGuardTolerance(double tolerance) { guard_tolerance_ = tolerance; }

  double getMotionGuardTolerance() const { return guard_tolerance_; }

  /// H_pred = T_curr_prev of the previous frame (metres; default identity).
  void setPredictedMotion(const Eigen::Matrix4d& T_curr_prev)
  {
    T_curr_prev_predicted_ = T_curr_prev;
  }

  const Eigen::Matrix4d& getPredictedMotion() const { return T_curr_prev_predicted_; }

  /** \brief Runs the fits of the class doc on registration (source, target and flow set).
   * \return registration.hasConverged() after the last fit
   */
  bool align(Registration& registration);

  /// The static cells of the last fit of align() (labelled LABEL_STATIC).
  const FlowGrid& getStaticCells() const { return static_cells_; }

  /// False when the motion guard replaced the first fit in the last align().
  bool getLabelsTrusted() const { return labels_trusted_; }

private:
  /// Stores checked parameters.
  void assignParameters(const Parameters& parameters) { params_ = parameters; }

  /// Sets static_cells_ on the registration and fits from T_prev_curr_guess; only a final
  /// fit keeps the registration's information-weighted refinement.
  bool
  fit(Registration& registration, const Eigen::Matrix4d& T_prev_curr_guess, bool final);

  /// Marks in static_cells_ the valid cells whose flow agrees with T_prev_curr within limit
  /// (squared transfer error of b_i onto a_i, m^2), leaving out the cells labelled as
  /// objects when exclude_objects (slow objects pass the test).
  void selectConsensus(const FlowCloud& flow,
                       const Eigen::Matrix4d& T_prev_curr,
                       bool exclude_objects,
                       double limit);

  /** Step 4 (docs/algorithm.md §7.8): the valid cells the consensus left out (not moving,
   * not objects when the labels are trusted) fitted on their own, and that motion's
   * consensus. When it holds more than twice the consensus' surface in the world, it is the
   * background: static_cells_ and T_prev_curr become its; else static_cells_ is restored.
   */
  void contestBackground(Registration& registration,
                         const FlowCloud& flow,
                         double limit,
                         Eigen::Matrix4d& T_prev_curr);

  /// Cell i may enter a static set: it has 3D flow, is not among the moving cells, and is
  /// not labelled as an object when exclude_objects.
  bool eligible(const FlowCloud& flow, std::size_t i, bool exclude_objects) const
  {
    return flow[i].valid_3d && !(exclude_objects && labels_.labels[i] > LABEL_STATIC) &&
           !leftOut(i);
  }

  /// Cell i (of static_cells_' grid) is among the moving cells of setMovingCells().
  bool leftOut(std::size_t i) const
  {
    return moving_.sameGeometry(static_cells_) &&
           moving_.labels.size() == static_cells_.labels.size() &&
           moving_.labels[i] != LABEL_NONE;
  }

  std::string class_name_ = "StaticSetSelection"; ///< log prefix
  Parameters params_;                             ///< validated knobs
  FlowGrid labels_;                               ///< segmentation's cell labels
  bool use_labels_ = false;                       ///< false: every valid cell is static
  FlowGrid moving_;                               ///< cells left out of every fit
  double inlier_threshold_ = 3e-5;                ///< m^2
  double guard_tolerance_ = 0.03;                 ///< tau_cv (metres)
  Eigen::Matrix4d T_curr_prev_predicted_ = Eigen::Matrix4d::Identity(); ///< H_pred
  FlowGrid static_cells_;      ///< the static set of the last fit
  bool labels_trusted_ = true; ///< the first fit was kept
};

} // namespace dynvo

#ifdef DYNVO_NO_PRECOMPILE
#include <dynvo/registration/impl/static_set_selection.hpp>
#endif
