// SPDX-License-Identifier: BSD-3-Clause
// An ordinary odometry run beside the pipeline on the same frames (-bench_reference).
#pragma once

#include <dynvo/app/cli.h>
#include <dynvo/common/camera.h>
#include <dynvo/common/export.h>
#include <dynvo/common/trajectory.h>
#include <dynvo/io/frame.h>
#include <dynvo/registration/static_mask_registration_parameters.h>

#include <Eigen/Core>

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

namespace dynvo::detail {
struct RgbdImage;
} // namespace dynvo::detail

namespace dynvo::app {

/** \brief OpenCV's dense RGB-D odometry (cv::rgbd::RgbdOdometry) frame to frame over the
 * whole image, as a reference for the pipeline on the same frames (-bench_reference cv_rgbd).
 *
 * Frame k is registered to frame k-1 by detail::estimateRgbdOdometry() on the grey level and
 * depth of its cloud (detail::rgbdImageOf()) with every pixel that has depth in the mask: no
 * segmentation, no flow estimate. Each registration starts from the previous frame's motion
 * (constant velocity; identity for the first pair), and the poses are composed camera-to-world
 * from frame 0 (T_world_curr = T_world_prev * T_prev_curr), stamped with the colour stamp.
 * When OpenCV reports no success the frame is lost and takes the prediction; a frame that
 * breaks the contract (no cloud, unorganized, or of another size than the previous frame) is
 * lost too and does not become the previous frame.
 *
 * Every frame after frame 0 is timed: the conversion of the cloud plus the OpenCV call
 * (decoding excluded, as RunReport times the pipeline).
 * \code
 * dynvo::app::ReferenceOdometry reference(options.intrinsics);
 * while (source.next(frame)) {
 *   pipeline.process(frame.cloud, frame.timestamp);  // timed on its own
 *   reference.add(frame);
 * }
 * reference.printSummary(report.medianMs(), groundtruth);
 * \endcode
 */
class DYNVO_EXPORTS ReferenceOdometry {
public:
  /** \param[in] intrinsics pinhole model of the frames
   * \param[in] parameters rgbd_max_depth and rgbd_max_depth_difference; the defaults are
   *            OpenCV's own
   * \throws std::invalid_argument when parameters.validate() fails
   */
  explicit ReferenceOdometry(const CameraIntrinsics& intrinsics,
                             const StaticMaskRegistrationParameters& parameters = {});
  ~ReferenceOdometry();
  ReferenceOdometry(const ReferenceOdometry&) = delete;
  ReferenceOdometry& operator=(const ReferenceOdometry&) = delete;

  /// Registers the next frame to the previous one and appends its pose.
  void add(const Frame& frame);

  /// Camera poses so far (camera-to-world, frame 0 at the identity).
  const Trajectory& trajectory() const { return trajectory_; }

  /// Frames added.
  std::size_t frames() const { return trajectory_.size(); }

  /// Frames after frame 0 that took the constant-velocity prediction.
  std::size_t lost() const { return lost_; }

  /// Median time per frame after frame 0 (ms); 0 before the second frame.
  double medianMs() const;

  /** \brief "reference=cv_rgbd frames=<n> lost=<n> median_ms=<x> speed_ratio=<x>", the ratio
   * being pipeline_median_ms / medianMs() (below 1: the pipeline is faster; nan when either
   * median is 0).
   */
  std::string summary(double pipeline_median_ms) const;

  /** \brief The dynvo_evaluate line of the trajectory against the ground truth with every key
   * prefixed "reference_" ("reference_rpe_trans_rmse=<m/s> ... reference_pairs=<n>"), or
   * "reference accuracy not available: <why>".
   */
  std::string accuracy(const Trajectory& groundtruth) const;

  /// Prints accuracy() when groundtruth is not empty, then summary().
  void printSummary(double pipeline_median_ms, const Trajectory& groundtruth) const;

private:
  CameraIntrinsics intrinsics_;
  StaticMaskRegistrationParameters parameters_;
  std::unique_ptr<detail::RgbdImage>
      previous_; ///< the last frame that met the contract
  Eigen::Matrix4d T_prev_curr_ =
      Eigen::Matrix4d::Identity(); ///< the last motion: the next frame's prediction
  Eigen::Matrix4d T_world_curr_ = Eigen::Matrix4d::Identity(); ///< the last pose
  Trajectory trajectory_;
  std::size_t lost_ = 0;
  std::vector<double> times_ms_; ///< per frame after frame 0 (ms)
};

/// The -bench_reference flag of dynvo_odometry.
DYNVO_EXPORTS Option referenceOdometryOption();

/** \brief -bench_reference METHOD: the reference odometry to run beside the pipeline (METHOD
 * cv_rgbd: ReferenceOdometry with OpenCV's defaults), or none without the flag.
 * \throws UsageError naming the flag and the accepted value for any other METHOD
 */
DYNVO_EXPORTS std::unique_ptr<ReferenceOdometry>
referenceOdometryFromArguments(const Arguments& args,
                               const CameraIntrinsics& intrinsics);

} // namespace dynvo::app
