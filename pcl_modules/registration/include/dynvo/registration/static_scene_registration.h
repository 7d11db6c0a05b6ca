// SPDX-License-Identifier: BSD-3-Clause
// Ego-motion from the static part of the scene (docs/algorithm.md §7) as a
// pcl::Registration.
#pragma once

#include <dynvo/common/export.h>
#include <dynvo/common/flow_grid.h>
#include <dynvo/common/point_types.h>
#include <dynvo/common/sensor_noise_model.h>
#include <dynvo/registration/lazy_kd_tree.h>
#include <dynvo/registration/static_scene_registration_parameters.h>

#include <pcl/point_cloud.h>
#include <pcl/registration/registration.h>

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace dynvo {

/// What the last align() produced (StaticSceneRegistration::getStatus()).
enum class StaticRegistrationStatus {
  not_computed, ///< align() has not run yet
  invalid_input, ///< the inputs broke the contract (logged with PCL_ERROR); not converged
  too_few_correspondences, ///< fewer than min_correspondences usable static cells; not converged
  degenerate,              ///< the static cells are (nearly) collinear; not converged
  converged                ///< the result is the trimmed flow estimate
};

/** \brief Camera ego-motion from the static cells of a grid scene flow: Lee, Son & Kim, "Robust
 * Real-time RGB-D Visual Odometry in Dynamic Environments via Rigid Motion Model", IROS 2019
 * (arXiv 1907.08388), §III-D; docs/algorithm.md §7.
 *
 * PCL's naming applies: the source (setInputSource) is the current frame k, setIndices() holds
 * its static pixels (linear indices row * width + col), the target (setInputTarget) is the
 * previous frame k-1, and getFinalTransformation() is T_prev_curr (the inverse of the paper's
 * H_k); a pipeline composes T_world_curr = T_world_prev * T_prev_curr.
 *
 * Flow estimate (no nearest-neighbour search): the flow grid (setInputFlow, from
 * GridSceneFlowEstimation on the same frame pair) gives per cell b_i (x, y, z; current frame)
 * and a_i (prev_x, prev_y, prev_z; previous frame); the cell geometry is inferred from it
 * (FlowGrid::fromFlow()). The static cells come as cells (setStaticCells(): the cells labelled
 * LABEL_STATIC, e.g. from StaticSetSelection) or, PCL's way, as pixels (setIndices()): a pixel
 * selects the cell holding it (FlowGrid::cellOfPixel(); pixels right of or below the last full
 * cell select none), and a cell counts once however many of its pixels are listed. Static cells,
 * when set, take precedence over indices; with neither, every cell counts as static. The set S
 * holds the selected cells with valid_3d, finite a_i and b_i and weight > 0. The weighted
 * least-squares rigid fit (RigidFitAccumulator, weights = flow weights) maps b_i onto a_i; then
 * trim_rounds rounds keep the cells of S with E_i <= trim_factor * th_inlier and refit; a round
 * leaving fewer than min_correspondences cells, or a degenerate refit, keeps the previous fit.
 *
 * The fit is closed-form on the flow's correspondences: pcl::Registration's iteration,
 * correspondence-distance and epsilon knobs, correspondence estimation and rejectors are not
 * used. Other methods on the static mask (OpenCV's RGB-D odometry, ICP, GICP) started from
 * this estimate are StaticMaskRegistration's.
 *
 * Results: hasConverged() is false for invalid input, too few cells (|S| < min_correspondences)
 * and degenerate cells; getStatus() says which, and getFinalTransformation() is then the guess
 * passed to align() (identity by default), so a pipeline can pass its constant-velocity
 * prediction and flag the frame as lost. getMeanSquaredResidual() is the mean squared
 * residual E_i (m^2) of the kept cells under the final transformation;
 * getFitnessScore(max_range) keeps PCL's meaning (mean squared distance of the source points to
 * their nearest target points, on a kd-tree built on the first call only).
 * getNumberOfCorrespondences() is |S|, getNumberOfInliers() the number of kept cells.
 * The output cloud of align() holds the source points at the centres of the static cells, or
 * else those of setIndices() (all of them without), transformed into the previous frame; it is
 * unorganized once indices or cells are set (PCL's registration.hpp) and empty when not
 * converged. With static cells, getIndices() is those centres.
 *
 * Only computeTransformation() is overridden, so align() works the same through a
 * pcl::Registration pointer. A missing source or target is pcl::Registration's to report
 * (its PCL_ERROR, no result); the other inputs are checked by computeTransformation()
 * (validateInputs()). Indices are
 * range-checked when they or the source are set, before pcl::Registration::align() copies the
 * indexed points: an out-of-range index is logged with PCL_ERROR there and again by the next
 * align(), which does not converge (the rejected indices select nothing). Indices changed
 * through a kept pointer after setIndices() are not checked again, as in any pcl::Registration.
 * \code
 * dynvo::StaticSceneRegistration<pcl::PointXYZRGB> registration;
 * registration.setInputSource(current);               // frame k
 * registration.setInputTarget(previous);              // frame k-1
 * registration.setInputFlow(flow);                    // grid scene flow k-1 -> k
 * registration.setStaticCells(static_cells);          // e.g. from StaticSetSelection
 * pcl::PointCloud<pcl::PointXYZRGB> aligned;           // pcl::Registration::align:
 * registration.align(aligned, T_prev_curr_predicted); // the guess is returned when not converged
 * if (registration.hasConverged()) T_world_curr = T_world_prev * registration.getFinalTransformation();
 * \endcode
 * Not thread-safe; separate instances may run concurrently. Explicitly instantiated for
 * pcl::PointXYZRGB and pcl::PointXYZRGBA (other types: include the impl .hpp).
 */
template <typename PointT>
class StaticSceneRegistration : public pcl::Registration<PointT, PointT, float> {
public:
  using Base = pcl::Registration<PointT, PointT, float>;
  using PointCloud = pcl::PointCloud<PointT>;
  using PointCloudPtr = typename PointCloud::Ptr;
  using PointCloudConstPtr = typename PointCloud::ConstPtr;
  using Ptr = pcl::shared_ptr<StaticSceneRegistration<PointT>>;
  using ConstPtr = pcl::shared_ptr<const StaticSceneRegistration<PointT>>;
  using FlowCloud = pcl::PointCloud<PointFlow>;
  using FlowCloudConstPtr = FlowCloud::ConstPtr;
  using Matrix4 = typename Base::Matrix4;
  using Parameters = StaticSceneRegistrationParameters;
  using Status = StaticRegistrationStatus;

  /// Sets the class name, the lazily built target kd-tree and the default parameters.
  StaticSceneRegistration();

  using Base::setIndices;

  // Static pixels, PCL's way (see the class doc), range-checked against the source.
  void setIndices(const pcl::IndicesPtr& indices) override
  {
    Base::setIndices(indices);
    adoptIndices();
  }
  void setIndices(const pcl::IndicesConstPtr& indices) override
  {
    Base::setIndices(indices);
    adoptIndices();
  }
  void setIndices(const pcl::PointIndicesConstPtr& indices) override
  {
    Base::setIndices(indices);
    adoptIndices();
  }
  void setIndices(std::size_t row_start,
                  std::size_t col_start,
                  std::size_t nb_rows,
                  std::size_t nb_cols) override
  {
    Base::setIndices(row_start, col_start, nb_rows, nb_cols);
    adoptIndices();
  }

  /// Frame k (organized, metres); the indices are range-checked against it.
  void setInputSource(const PointCloudConstPtr& cloud) override;

  /// Grid scene flow from the target (frame k-1) to the source (frame k), organized Gx x Gy.
  void setInputFlow(const FlowCloudConstPtr& flow) { flow_ = flow; }

  const FlowCloudConstPtr& getInputFlow() const { return flow_; }

  /** \brief The static set as cells: those labelled LABEL_STATIC. Its geometry must be the
   * flow's on the source cloud (checked by align()); takes precedence over setIndices(). An
   * empty grid (FlowGrid()) removes it.
   */
  void setStaticCells(const FlowGrid& cells);

  const FlowGrid& getStaticCells() const { return static_cells_input_; }

  /// Mean squared residual E_i (m^2) of the kept cells under the final transformation;
  /// std::numeric_limits<double>::max() when not converged.
  double getMeanSquaredResidual() const { return mean_squared_residual_; }

  /// |S|: usable static cells of the last align() (0 for invalid input).
  std::size_t getNumberOfCorrespondences() const { return source_points_.size(); }

  /// Cells kept by the trimming (the ones the flow estimate was fitted on).
  std::size_t getNumberOfInliers() const { return inlier_count_; }

  Status getStatus() const { return status_; }

  /// All knobs at once. \throws std::invalid_argument when parameters.validate() fails
  void setParameters(const Parameters& parameters);

  const Parameters& getParameters() const { return params_; }

  // One setter/getter pair per field of Parameters. A setter throws std::invalid_argument
  // when the value is outside the field's own range (StaticSceneRegistrationParameters::
  // table()) and keeps the old value.
  DYNVO_PARAMETER_ACCESSORS(InlierThreshold, th_inlier)
  DYNVO_PARAMETER_ACCESSORS(TrimFactor, trim_factor)
  DYNVO_PARAMETER_ACCESSORS(TrimRounds, trim_rounds)
  DYNVO_PARAMETER_ACCESSORS(MinCorrespondences, min_correspondences)
  DYNVO_PARAMETER_ACCESSORS(InformationIterations, information_iterations)
  DYNVO_PARAMETER_ACCESSORS(HuberThreshold, huber_threshold)

  /** \brief The depth camera's noise for the information-weighted fit (docs/algorithm.md
   * §7.2): each kept cell's transfer error is weighed by
   * noise.transferInformation(a_i, b_i, focal) (the model's gains of 1: the segmentation's
   * fitted gains were measured here and not kept, src/app/NOTES.md).
   * Defaults: SensorNoiseModel(), focal 525 px (Kinect v1).
   * \throws std::invalid_argument when noise.validate() fails or focal is not > 0
   */
  void setSensorNoise(const SensorNoiseModel& noise, float focal);

protected:
  using Base::converged_;
  using Base::fake_indices_;
  using Base::final_transformation_;
  using Base::indices_;
  using Base::input_;
  using Base::reg_name_;
  using Base::target_;
  using Base::transformation_;

  /// Checks the inputs and runs the flow estimate (called by pcl::Registration::align).
  void computeTransformation(PointCloud& output, const Matrix4& guess) override;

  /// Non-null organized source, target and flow; equal source and target sizes; a flow grid
  /// matching the cloud (see the class doc), static cells on the same grid; indices in range.
  /// Sets grid_; logs PCL_ERROR otherwise.
  bool validateInputs();

  /// Keeps the indices the base class just stored as the user's, then updateIndices().
  void adoptIndices();

  /// The indices pcl::Registration::align() copies: the centres of the static cells when
  /// they are set, else the indices given last, range-checked against the source (rejected
  /// ones are replaced by none and logged with PCL_ERROR).
  void updateIndices();

  /// Collects S from the indices and the flow (fills source_points_, target_points_, weights_).
  void collectCorrespondences();

  /// Weighted fit on S, then trimming. Sets status_, flow_transformation_ and inliers_.
  bool estimateFromFlow();

private:
  /// Stores checked parameters.
  void assignParameters(const Parameters& parameters) { params_ = parameters; }

  /// Clears every result; the final transformation becomes the guess.
  void resetResults(const Matrix4& guess);

  Parameters params_;                    ///< validated knobs
  SensorNoiseModel noise_;               ///< setSensorNoise()
  float focal_ = 525.0f;                 ///< focal length of the noise model (px)
  FlowCloudConstPtr flow_;               ///< grid scene flow k-1 -> k
  Status status_ = Status::not_computed; ///< outcome of the last align()
  double mean_squared_residual_ =
      std::numeric_limits<double>::max(); ///< mean kept E_i (m^2)
  pcl::IndicesPtr user_indices_;          ///< the indices given last (null: none)
  int rejected_index_ = 0;                ///< first out-of-range index of user_indices_
  bool indices_rejected_ = false;         ///< user_indices_ do not fit the source
  Matrix4 flow_transformation_ =
      Matrix4::Identity();       ///< trimmed flow estimate T_prev_curr
  std::size_t inlier_count_ = 0; ///< cells the flow estimate was fitted on
  std::vector<Eigen::Vector3d> source_points_; ///< b_i of S (metres, current frame)
  std::vector<Eigen::Vector3d> target_points_; ///< a_i of S (metres, previous frame)
  std::vector<double> weights_;                ///< flow weight of each cell of S
  std::vector<std::uint8_t> inliers_; ///< 1 for the cells of S kept by the trimming
  FlowGrid static_cells_input_;       ///< setStaticCells(); empty when not set
  FlowGrid grid_;                     ///< geometry of the flow on the source cloud
  std::vector<std::uint8_t> static_cells_; ///< per grid cell: selected
};

} // namespace dynvo

#ifdef DYNVO_NO_PRECOMPILE
#include <dynvo/registration/impl/static_scene_registration.hpp>
#endif
