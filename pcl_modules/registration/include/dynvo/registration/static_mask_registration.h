// SPDX-License-Identifier: BSD-3-Clause
// The ego-motion backend restricted to the static mask of both frames (docs/algorithm.md §7,
// the paper's Table III).
#pragma once

#include <dynvo/common/camera.h>
#include <dynvo/common/flow_grid.h>
#include <dynvo/registration/direct_odometry.h>
#include <dynvo/registration/static_mask_registration_parameters.h>

#include <pcl/point_cloud.h>

#include <Eigen/Core>

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

namespace dynvo {

/// What the last align() of StaticMaskRegistration produced.
enum class StaticMaskRegistrationStatus {
  not_computed,   ///< align() has not run yet
  flow,           ///< the backend is flow: the guess is the result
  invalid_input,  ///< the inputs broke the contract (logged with PCL_ERROR): the guess
  too_few_points, ///< fewer than MIN_POINTS usable masked points: the guess
  not_converged,  ///< the backend did not converge: the guess
  converged       ///< the backend's estimate is the result
};

/** \brief Re-estimates the ego-motion with another method restricted to the static mask,
 * started from the flow estimate: the experiment of Lee, Son & Kim, "Robust Real-time RGB-D
 * Visual Odometry in Dynamic Environments via Rigid Motion Model", IROS 2019, Table III (a
 * dense or ICP odometry made robust by the segmentation's mask).
 *
 * The source (setInputSource) is the current frame k, the target (setInputTarget) the
 * previous frame k-1, both organized with the same size (metres, RGB), and the result is
 * T_prev_curr, as for StaticSceneRegistration. The mask of each frame comes as cells
 * (setSourceStaticCells(), setTargetStaticCells(): the cells labelled LABEL_STATIC, on the
 * grid of the flow); a pixel belongs to the mask when its cell does. The pipeline passes the
 * static set of the final flow fit of frame k (StaticSetSelection::getStaticCells()) as the
 * source mask and that of frame k-1 (kept from the previous step) as the target mask.
 *
 * Backends (Parameters::backend):
 * - flow: align() returns the guess (the flow estimate is the method);
 * - cv_rgbd: cv::rgbd::RgbdOdometry (photometric, dense) on the gray image and depth of both
 *   frames, with both masks (OpenCV uses the source mask for the points it moves and the
 *   target mask for the textured pixels it compares with), initialised with the guess;
 * - icp, gicp: PCL's ICP/GICP on plain XYZ copies of the finite masked points of both frames
 *   on every icp_stride-th row and column, initialised with the guess;
 * - direct: direct photometric alignment (detail::estimateDirectOdometry()): the textured
 *   masked pixels of the target, with their depths, moved into the source image where it is
 *   masked, from the guess over a 3-level pyramid; each cloud's pyramids are built once, for
 *   its alignments as frame k and as frame k-1.
 * A backend that fails (too few points, not converged) leaves the guess as the result, and
 * getStatus() says why. The camera intrinsics (setCameraIntrinsics()) are used by cv_rgbd and
 * direct.
 * \code
 * dynvo::StaticMaskRegistration<pcl::PointXYZRGB> backend;
 * backend.setCameraIntrinsics(intrinsics);
 * backend.setBackend(dynvo::RegistrationBackend::cv_rgbd);
 * backend.setInputSource(current);                           // frame k
 * backend.setInputTarget(previous);                          // frame k-1
 * backend.setSourceStaticCells(selection.getStaticCells());  // static set of frame k
 * backend.setTargetStaticCells(previous_static_cells);       // static set of frame k-1
 * Eigen::Matrix4f T_prev_curr;
 * backend.align(registration.getFinalTransformation(), T_prev_curr);
 * \endcode
 * Not thread-safe; separate instances may run concurrently. Explicitly instantiated for
 * pcl::PointXYZRGB and pcl::PointXYZRGBA (other types: include the impl .hpp).
 */
template <typename PointT> class StaticMaskRegistration {
public:
  using PointCloud = pcl::PointCloud<PointT>;
  using PointCloudConstPtr = typename PointCloud::ConstPtr;
  using Parameters = StaticMaskRegistrationParameters;
  using Status = StaticMaskRegistrationStatus;

  /// Fewer usable masked points (icp, gicp: finite lattice points; cv_rgbd: masked pixels)
  /// in either frame than this is too few: a rigid motion needs 3, with a margin.
  static constexpr std::size_t MIN_POINTS = 6;

  /// Name used in log prefixes: "StaticMaskRegistration".
  const std::string& getClassName() const { return class_name_; }

  /// All knobs at once. \throws std::invalid_argument when parameters.validate() fails
  void setParameters(const Parameters& parameters)
  {
    parameters.validate();
    assignParameters(parameters);
  }

  const Parameters& getParameters() const { return params_; }

  // A setter throws std::invalid_argument when the value is outside the field's own range
  // (StaticMaskRegistrationParameters::table()) and keeps the old value.
  DYNVO_PARAMETER_ACCESSORS(Backend, backend)
  DYNVO_PARAMETER_ACCESSORS(IcpStride, icp_stride)

  /// Pinhole model of both frames (cv_rgbd). \throws std::invalid_argument when invalid
  void setCameraIntrinsics(const CameraIntrinsics& intrinsics)
  {
    intrinsics.validate();
    intrinsics_ = intrinsics;
  }

  const CameraIntrinsics& getCameraIntrinsics() const { return intrinsics_; }

  /** \brief Worker threads (default 1) of the direct backend's residuals; results are
   * identical for any count. \throws std::invalid_argument on 0
   */
  void setNumberOfThreads(unsigned threads)
  {
    if (threads == 0)
      throw std::invalid_argument(
          "[dynvo::" + class_name_ +
          "::setNumberOfThreads] at least one thread is needed");
    threads_ = threads;
  }

  unsigned getNumberOfThreads() const { return threads_; }

  /// Frame k (organized, metres). With the direct backend its pyramids are built here, once
  /// per cloud (set it while the cloud is still in the cache).
  void setInputSource(const PointCloudConstPtr& cloud)
  {
    if (cloud && params_.backend == RegistrationBackend::direct)
      directFrameOf(cloud, source_);
    source_ = cloud;
  }

  /** \brief Frame k with its grey levels (luma()) and depths (metres, NaN where none) as an
   * earlier stage read them from it, row-major (GridSceneFlowEstimation::getInputGrey() and
   * getInputDepth()): the direct backend builds its pyramids from them instead of reading the
   * cloud again. When they do not hold one value per point (e.g. empty), the cloud is read.
   */
  void setInputSource(const PointCloudConstPtr& cloud,
                      const std::vector<std::uint8_t>& grey,
                      const std::vector<float>& depth);

  /// Frame k-1 (organized, metres, the source's size).
  void setInputTarget(const PointCloudConstPtr& cloud) { target_ = cloud; }

  /// Static cells of frame k (labelled LABEL_STATIC), on a grid over the source image.
  void setSourceStaticCells(const FlowGrid& cells) { source_cells_ = cells; }

  /// Static cells of frame k-1 (labelled LABEL_STATIC), on a grid over the target image.
  void setTargetStaticCells(const FlowGrid& cells) { target_cells_ = cells; }

  /** \brief With the direct backend, builds the target's pyramids (when not kept from its
   * use as a source) and chooses its samples for the target's static cells now instead of in
   * the next align(), with the same result: a caller may run this beside other work. Does
   * nothing with the other backends, or when the target or its cells are not set (align()
   * reports that).
   */
  void precomputeTarget();

  /** \brief Runs the backend from guess.
   * \param[in] guess initial T_prev_curr (metres), e.g. the flow estimate
   * \param[out] T_prev_curr the backend's estimate, or guess when it failed (getStatus())
   * \return true when the result is the backend's own estimate (flow: always true)
   */
  bool align(const Eigen::Matrix4f& guess, Eigen::Matrix4f& T_prev_curr);

  Status getStatus() const { return status_; }

private:
  /// Stores checked parameters.
  void assignParameters(const Parameters& parameters) { params_ = parameters; }

  /// The cells are a grid over the cloud's image.
  static bool covers(const FlowGrid& cells, const PointCloud& cloud);

  /// Non-null organized clouds of equal size, masks on grids over them; logs PCL_ERROR.
  bool validateInputs() const;

  /// True when both counts reach MIN_POINTS; logs PCL_DEBUG otherwise.
  bool enoughPoints(std::size_t source_count, std::size_t target_count) const;

  /// ICP/GICP on the masked lattice points; T_prev_curr written when converged.
  Status alignPoints(const Eigen::Matrix4f& guess, Eigen::Matrix4f& T_prev_curr);

  /// cv::rgbd::RgbdOdometry on the masked images; T_prev_curr written when converged.
  Status alignImages(const Eigen::Matrix4f& guess, Eigen::Matrix4f& T_prev_curr);

  /// The direct estimate from the masked frames' pyramids; T_prev_curr written on success.
  Status alignDirect(const Eigen::Matrix4f& guess, Eigen::Matrix4f& T_prev_curr);

  /// The pyramids of a cloud, built once for its alignments as frame k and as frame k-1 (the
  /// same pointer and header stamp; a cloud changed in place needs a new stamp); those of
  /// keep are not evicted.
  const detail::DirectFrame& directFrameOf(const PointCloudConstPtr& cloud,
                                           const PointCloudConstPtr& keep);

  /// The pyramids built for this cloud, or null.
  const detail::DirectFrame* builtFrameOf(const PointCloudConstPtr& cloud) const;

  /// An entry for a cloud without pyramids, its finest level sized and left to fill: the
  /// buffers of the entry that does not hold keep's pyramids.
  detail::DirectFrame& claimDirectFrame(const PointCloudConstPtr& cloud,
                                        const PointCloudConstPtr& keep);

  std::string class_name_ = "StaticMaskRegistration"; ///< log prefix
  Parameters params_;                                 ///< validated knobs
  CameraIntrinsics intrinsics_;                       ///< of both frames
  unsigned threads_ = 1;                              ///< worker threads (direct)
  PointCloudConstPtr source_;                         ///< frame k
  PointCloudConstPtr target_;                         ///< frame k-1
  FlowGrid source_cells_;                             ///< static cells of frame k
  FlowGrid target_cells_;                             ///< static cells of frame k-1
  Status status_ = Status::not_computed;              ///< outcome of the last align()
  /// A cloud (and its header stamp) whose pyramids the direct backend built.
  struct DirectEntry {
    PointCloudConstPtr cloud;
    std::uint64_t stamp = 0;
    std::unique_ptr<detail::DirectFrame> frame;
  };
  std::array<DirectEntry, 2> direct_frames_; ///< frames k and k-1, in either order
};

} // namespace dynvo

#ifdef DYNVO_NO_PRECOMPILE
#include <dynvo/registration/impl/static_mask_registration.hpp>
#endif
