// SPDX-License-Identifier: BSD-3-Clause
// Grid-based scene flow between two organized RGB-D clouds (docs/algorithm.md §1).
#pragma once

#include <dynvo/common/camera.h>
#include <dynvo/common/export.h>
#include <dynvo/common/flow_grid.h>
#include <dynvo/common/point_types.h>
#include <dynvo/scene_flow/grid_flow_engine.h>
#include <dynvo/scene_flow/grid_scene_flow_parameters.h>

#include <pcl/pcl_base.h>
#include <pcl/point_cloud.h>

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace dynvo {

/** \brief Grid-based scene flow of Lee, Son & Kim, "Robust Real-time RGB-D Visual Odometry in
 * Dynamic Environments via Rigid Motion Model", IROS 2019 (arXiv 1907.08388), §III-A.
 *
 * The grid is anchored in the current frame k (the input cloud): each cell centre c_i is tracked
 * by pyramidal Lucas-Kanade into the previous frame k-1 (p_i) and checked by tracking p_i back
 * (forward-backward check). Depth is preprocessed (DepthPreprocessing), read at c_i and
 * interpolated at the sub-pixel p_i, and both are back-projected with the camera intrinsics:
 * b_i (metres, current camera frame) goes to x, y, z, a_i (metres, previous camera frame) to
 * prev_x, prev_y, prev_z of a PointFlow. For a static point b_i = T_curr_prev * a_i.
 *
 * Output: organized (width / cell_size) x (height / cell_size) cloud; cell i = row * cols + col,
 * the geometry of FlowGrid, from which the consumers infer the cell size (a cell size for which
 * width / (width / cell_size) != cell_size is an input error, see FlowGrid::isInferable()).
 * u, v always hold c_i. Only cells with depth at c_i are tracked (the others give no 3D flow).
 * valid_2d cells hold p_i in prev_u, prev_v (NaN otherwise); x, y, z hold b_i
 * whenever depth exists at c_i; valid_3d cells also hold a_i and a weight in (0, 1]. Every other
 * field is NaN and the weight 0. setIndices() is not used: every cell is computed.
 *
 * Sequences: after compute(), shiftCurrentToPrevious() turns the current frame (its grey pyramid
 * and preprocessed depth) into the previous one, so each frame is prepared once.
 * setCurrentAsKeyframe() also keeps it as a keyframe, and computeToKeyframe() tracks later
 * frames into it from a predicted motion.
 * \code
 * dynvo::GridSceneFlowEstimation<pcl::PointXYZRGB> flow_estimation;
 * flow_estimation.setCameraIntrinsics(dynvo::CameraIntrinsics::fromPreset("fr1"));
 * pcl::PointCloud<dynvo::PointFlow> flow;
 * flow_estimation.setInputCloud(frames[0]);
 * for (std::size_t k = 1; k < frames.size(); ++k) {
 *   flow_estimation.shiftCurrentToPrevious();   // frame k-1 becomes the previous frame
 *   flow_estimation.setInputCloud(frames[k]);
 *   flow_estimation.compute(flow);              // flow from frame k-1 to frame k
 * }
 * \endcode
 * Not thread-safe; separate instances may run concurrently. Explicitly instantiated for
 * pcl::PointXYZRGB and pcl::PointXYZRGBA (other types: include the impl .hpp).
 */
template <typename PointT> class GridSceneFlowEstimation : public pcl::PCLBase<PointT> {
public:
  using Base = pcl::PCLBase<PointT>;
  using PointCloud = pcl::PointCloud<PointT>;
  using PointCloudPtr = typename PointCloud::Ptr;
  using PointCloudConstPtr = typename PointCloud::ConstPtr;
  using Ptr = pcl::shared_ptr<GridSceneFlowEstimation<PointT>>;
  using ConstPtr = pcl::shared_ptr<const GridSceneFlowEstimation<PointT>>;
  using FlowCloud = pcl::PointCloud<PointFlow>;
  using Parameters = GridSceneFlowParameters;

  GridSceneFlowEstimation() = default;

  /// Name used in log prefixes: "GridSceneFlowEstimation".
  const std::string& getClassName() const { return class_name_; }

  /// Current frame k (organized, metres, current camera frame); the grid is anchored here.
  /// Its stamps are unknown until setInputStamps().
  void setInputCloud(const PointCloudConstPtr& cloud) override;

  /** \brief When the input cloud's colour and depth images were taken (seconds; call after
   * setInputCloud(), before compute()). A sensor whose two streams are not synchronised (TUM fr1: up to 17 ms
   * apart) sees a moving point in the depth image where it was at the depth instant: each
   * flow end is then read and back-projected there, moved along the cell's image velocity,
   * so that a_i and b_i are the points at the two frames' depth instants
   * (docs/algorithm.md §1.2). Unknown stamps (NaN, the default) or equal ones: no shift.
   */
  void setInputStamps(double colour_stamp, double depth_stamp)
  {
    input_stamps_ = {colour_stamp, depth_stamp};
  }

  /// Previous frame k-1 (organized, same size as the input cloud).
  void setPreviousCloud(const PointCloudConstPtr& cloud);

  const PointCloudConstPtr& getPreviousCloud() const { return previous_; }

  /** \brief The input cloud's z as compute() read it, row-major (metres, NaN where not
   * finite), for the stages after this one (RigidMotionSegmentation::setInputDepth()):
   * shared, not copied. Null until compute() has read the input cloud set last. A holder
   * keeps its image unchanged: compute() writes each frame's into one nobody else holds.
   */
  std::shared_ptr<const std::vector<float>> getInputDepth() const { return depth_; }

  /** \brief The input cloud's grey levels (luma()) as compute() read them, row-major, for the
   * stages after this one (StaticMaskRegistration::setInputSource()). Empty until compute()
   * has read the input cloud set last.
   */
  const std::vector<std::uint8_t>& getInputGrey() const { return grey_; }

  /** \brief Makes the current frame the previous one, keeping its pyramid and depth map.
   * The input cloud is cleared: set the next frame before calling compute() again.
   */
  void shiftCurrentToPrevious();

  /** \brief Computes the grid scene flow from the previous cloud to the input cloud.
   * \param[out] flow organized grid (see the class doc); empty when the inputs break the
   *             contract (null, unorganized, sizes differ, smaller than one cell), which is
   *             logged with PCL_ERROR
   * \throws std::invalid_argument (flow left empty) when getParameters().validate() fails,
   *         e.g. min_depth >= max_depth after setMinDepth()/setMaxDepth()
   */
  void compute(FlowCloud& flow);

  /** \brief Predicted camera motion H_pred = T_curr_prev of the next compute() (metres;
   * default identity): each cell starts its search at its predicted position in the previous
   * frame and the whole pyramid is searched
   * around it, so a fast but steady motion stays within the pyramid's reach
   * (docs/algorithm.md §1.2).
   */
  void setPredictedMotion(const Eigen::Matrix4f& T_curr_prev)
  {
    predicted_motion_ = T_curr_prev;
  }

  const Eigen::Matrix4f& getPredictedMotion() const { return predicted_motion_; }

  /** \brief The rotation R by which the last compute() turned the predicted motion onto the
   * image's own shift, when the two departed by more than the pyramid reaches
   * (docs/algorithm.md §1.2): its cells were seeded from H_pred * [R^T 0; 0 1]. Identity
   * when the prediction was kept.
   */
  const Eigen::Matrix3f& getPredictionCorrection() const
  {
    return prediction_correction_;
  }

  /** \brief Keeps the current frame of the last compute() as the keyframe (its pyramid and
   * depth map are shared, not copied), replacing the previous keyframe.
   * \return false (logged with PCL_ERROR) when compute() has not prepared the input cloud
   */
  bool setCurrentAsKeyframe();

  /// The keyframe's cloud; null before setCurrentAsKeyframe() or after new parameters.
  const PointCloudConstPtr& getKeyframeCloud() const { return keyframe_; }

  /** \brief Grid scene flow from the keyframe to the input cloud of the last compute()
   * (docs/algorithm.md §7.3): as compute(), with prev_* in the keyframe's camera frame.
   * Each cell with depth starts at its predicted position, the projection of
   * T_keyframe_current * b_i, and is tracked on pyramid levels 0..max_level only (0: a
   * good prediction; up to max_pyramid_level when the prediction may be far off).
   * \param[in] cells the cells to track, labelled LABEL_STATIC (e.g. the static set of the
   *            frame-to-frame fit); an empty grid (FlowGrid()) tracks every cell
   * \param[out] flow organized grid; empty (logged with PCL_ERROR) without a keyframe or a
   *             prepared input cloud, or when cells is not empty and not the flow's grid
   */
  void computeToKeyframe(const Eigen::Matrix4f& T_keyframe_current,
                         int max_level,
                         const FlowGrid& cells,
                         FlowCloud& flow);

  /// \throws std::invalid_argument when intrinsics.validate() fails
  void setCameraIntrinsics(const CameraIntrinsics& intrinsics);

  const CameraIntrinsics& getCameraIntrinsics() const { return intrinsics_; }

  /// Worker threads (default 1); results are identical for any count. \throws std::invalid_argument on 0
  void setNumberOfThreads(unsigned threads);

  unsigned getNumberOfThreads() const { return threads_; }

  /// All knobs at once. \throws std::invalid_argument when parameters.validate() fails
  void setParameters(const Parameters& parameters);

  const Parameters& getParameters() const { return params_; }

  // One setter/getter pair per field of Parameters. A setter throws std::invalid_argument
  // when the value is outside the field's own range (GridSceneFlowParameters::table()) and
  // keeps the old value; min_depth < max_depth is checked by compute().
  DYNVO_PARAMETER_ACCESSORS(CellSize, cell_size)
  DYNVO_PARAMETER_ACCESSORS(MinDepth, depth.min_depth)
  DYNVO_PARAMETER_ACCESSORS(MaxDepth, depth.max_depth)
  DYNVO_PARAMETER_ACCESSORS(FlyingPixelTolerance, depth.flying_pixel_tolerance)
  DYNVO_PARAMETER_ACCESSORS(MaxHoleWidth, depth.max_hole_width)
  DYNVO_PARAMETER_ACCESSORS(HoleFillTolerance, depth.hole_fill_tolerance)
  DYNVO_PARAMETER_ACCESSORS(WindowSize, window_size)
  DYNVO_PARAMETER_ACCESSORS(MaxPyramidLevel, max_pyramid_level)
  DYNVO_PARAMETER_ACCESSORS(MaxIterations, max_iterations)
  DYNVO_PARAMETER_ACCESSORS(Epsilon, epsilon)
  DYNVO_PARAMETER_ACCESSORS(MinEigenThreshold, min_eigen_threshold)
  DYNVO_PARAMETER_ACCESSORS(ForwardBackwardCheck, forward_backward_check)
  DYNVO_PARAMETER_ACCESSORS(ForwardBackwardThreshold, forward_backward_threshold)
  DYNVO_PARAMETER_ACCESSORS(DepthEdgeTolerance, depth_edge_tolerance)
  DYNVO_PARAMETER_ACCESSORS(DepthWindowRadius, depth_window_radius)
  DYNVO_PARAMETER_ACCESSORS(MaxFlow, max_flow)
  DYNVO_PARAMETER_ACCESSORS(WeightReferenceDepth, weight_reference_depth)

protected:
  using Base::deinitCompute;
  using Base::input_;

  /// Non-null, organized inputs of equal size; logs PCL_ERROR and returns false otherwise.
  bool initCompute();

  /// The image holds at least one grid cell and its grid gives the cell size back
  /// (FlowGrid::isInferable()); logs PCL_ERROR and returns false otherwise.
  bool validateInputs() const;

  /// Converts a cloud to grey levels and depths (into grey and depth) and prepares it in an
  /// engine slot.
  void prepareFrame(const PointCloud& cloud,
                    detail::GridFlowEngine::Slot slot,
                    const detail::GridFlowEngine::FrameStamps& stamps,
                    std::vector<std::uint8_t>& grey,
                    std::vector<float>& depth);

private:
  /// Stores checked parameters and drops the prepared frames (they depend on them).
  void assignParameters(const Parameters& parameters);

  std::string class_name_ = "GridSceneFlowEstimation"; ///< log prefix
  Parameters params_;                                  ///< validated knobs
  CameraIntrinsics intrinsics_;   ///< back-projection (default preset "default")
  unsigned threads_ = 1;          ///< worker threads
  PointCloudConstPtr previous_;   ///< frame k-1
  PointCloudConstPtr keyframe_;   ///< the kept keyframe, or null
  detail::GridFlowEngine engine_; ///< pyramids and preprocessed depth of both frames
  detail::GridFlowEngine::FrameStamps input_stamps_;    ///< of the input cloud
  detail::GridFlowEngine::FrameStamps previous_stamps_; ///< of the previous cloud
  bool current_ready_ = false;  ///< engine current slot matches input_ and params_
  bool previous_ready_ = false; ///< engine previous slot matches previous_ and params_
  std::vector<std::uint8_t> grey_; ///< the input cloud's grey levels (getInputGrey())
  std::shared_ptr<std::vector<float>> depth_; ///< the input cloud's z (getInputDepth())
  /// the images depth_ is one of: two, so that compute() finds one the last frame's holder
  /// (the segmentation's pixel stage) has let go of
  std::array<std::shared_ptr<std::vector<float>>, 2> depth_buffers_;
  std::vector<std::uint8_t> selected_; ///< cells computeToKeyframe() tracks
  Eigen::Matrix4f predicted_motion_ = Eigen::Matrix4f::Identity(); ///< H_pred
  /// getPredictionCorrection()
  Eigen::Matrix3f prediction_correction_ = Eigen::Matrix3f::Identity();
};

} // namespace dynvo

#ifdef DYNVO_NO_PRECOMPILE
#include <dynvo/scene_flow/impl/grid_scene_flow_estimation.hpp>
#endif
