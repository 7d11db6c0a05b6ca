// SPDX-License-Identifier: BSD-3-Clause
// The whole odometry: scene flow -> rigid motion segmentation -> static-only registration.
#pragma once

#include <dynvo/common/camera.h>
#include <dynvo/common/export.h>
#include <dynvo/common/parameter_table.h>
#include <dynvo/motion_segmentation/rigid_motion_segmentation_parameters.h>
#include <dynvo/registration/static_scene_registration_parameters.h>
#include <dynvo/scene_flow/grid_scene_flow_parameters.h>

#include <pcl/PointIndices.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <Eigen/Core>
#include <Eigen/StdVector>

#include <cstdint>
#include <memory>
#include <vector>

namespace dynvo::app {

/// Every knob of the pipeline: the three modules' parameters plus the pipeline's own.
struct DYNVO_EXPORTS PipelineOptions {
  /// The modules' defaults, except two:
  /// - the segmentation's inlier threshold: 6e-5 m^2 (7.7 mm) instead of the paper's 3e-5,
  ///   because with real Kinect noise too few hypotheses pass at 3e-5 (TUM fr1/xyz: RPE
  ///   0.053 m/s and 5 lost frames at 3e-5, 0.036 m/s and 1 at 6e-5);
  /// - the scene flow's depth window radius: 6 px (a 7x7 sample of a 13x13 window) instead
  ///   of the single pixel. At 2 m one Kinect pixel is about 9 mm noisy between two frames,
  ///   beyond the 7.7 mm inlier radius, so the background split into many segments whose
  ///   fits were biased by the selection (synthetic moving_static: RPE 0.027 -> 0.001 m/s).
  PipelineOptions();

  CameraIntrinsics intrinsics;        ///< back-projection of the input frames
  GridSceneFlowParameters scene_flow; ///< docs/algorithm.md §1
  RigidMotionSegmentationParameters
      segmentation; ///< docs/algorithm.md §3-§6 (seed included)
  StaticSceneRegistrationParameters registration; ///< docs/algorithm.md §7
  bool use_segmentation =
      true; ///< false: ablation, every valid flow cell counts as static
  /// Static support (multiple of the segmentation's inlier threshold in use, 0 = off): after
  /// a first fit on the background segment, every valid cell outside the moving objects whose
  /// flow agrees with it within this many thresholds (2: 7.7 mm on the synthetic scenes,
  /// 11 mm on TUM fr1) joins the static set for the final fit. Tied to the noise-following
  /// threshold rather than to a fixed radius, because a loose radius lets a slow object's
  /// unsegmented cells in (a box covering 80 % of the image moved the estimate by up to
  /// 10 mm per frame at 4 x 3e-5). When that first fit departs from the constant-velocity
  /// prediction by more than the segmentation's static_guard_tolerance (tau_cv, a moving
  /// object took the background label for a frame), the cells within tau_cv of the
  /// prediction give the first fit instead, and labels are not trusted.
  float static_consensus = 2.0f;
  /// Noise-following inlier threshold (0 = off: segmentation.inlier_threshold throughout).
  /// Each frame's segmentation uses this factor times the running mean (weight 0.1 per frame)
  /// of the static fit's mean residual E (its fitness score), clamped to
  /// [min_inlier_threshold, segmentation.inlier_threshold]; before the first fit, the upper
  /// bound. Residuals of a Gaussian static scene are sigma^2 chi^2_3 with mean 3 sigma^2, so
  /// 3 times the mean keeps about 97 % of the static cells. Measured mean residual: about
  /// 2e-6 m^2 on the synthetic scenes (the paper's 3e-5 applies) and 1.9e-5 on TUM fr1/xyz,
  /// whose colour and depth images are not taken at the same instant (6e-5 applies).
  float inlier_noise_factor = 3.0f;
  float min_inlier_threshold =
      3e-5f;            ///< lower bound of the noise-following threshold (m^2)
  unsigned threads = 1; ///< worker threads; results do not depend on it

  /// Names, units and ranges of the pipeline's own fields above (use_segmentation ...
  /// threads), in file order; the modules' fields are in their Parameters::table().
  static const ParameterTable<PipelineOptions>& table();

  /// \throws std::invalid_argument when a module's parameters or a pipeline value are invalid
  void validate() const;
};

/// Wall-clock time of each stage of one frame (milliseconds), image decoding excluded.
struct StageTimes {
  double scene_flow_ms = 0.0;   ///< depth preprocessing, pyramid, LK, back-projection
  double segmentation_ms = 0.0; ///< hypotheses, clustering, tracking
  double registration_ms = 0.0; ///< static-only ego-motion
  double total_ms = 0.0;        ///< the whole frame
};

/// Everything the pipeline knows about one frame.
struct FrameResult {
  double timestamp = 0.0; ///< seconds
  Eigen::Matrix4d T_world_curr =
      Eigen::Matrix4d::Identity(); ///< camera pose (camera-to-world)
  Eigen::Matrix4d T_curr_prev =
      Eigen::Matrix4d::Identity(); ///< ego-motion H_k (identity at frame 0)
  bool lost =
      false; ///< too few static cells: T_curr_prev is the constant-velocity prediction
  /// segments[0] = static background pixels, then moving objects (pcl::PointIndices each)
  std::vector<pcl::PointIndices> segments;
  std::vector<std::uint8_t> segment_labels; ///< label id of each segment (1 = static)
  /// T_curr_prev of each segment (metres): objects' frame-to-frame motion in the current frame
  std::vector<Eigen::Matrix4f, Eigen::aligned_allocator<Eigen::Matrix4f>> motions;
  /// segmentation inlier threshold used for this frame (m^2; noise-following, see
  /// PipelineOptions::inlier_noise_factor), 0 without segmentation
  double inlier_threshold = 0.0;
  std::uint32_t width = 0;  ///< image columns (px)
  std::uint32_t height = 0; ///< image rows (px)
  std::vector<std::uint8_t>
      labels;       ///< per pixel: 0 no measurement, 1 static, 2.. objects
  StageTimes times; ///< stage timings
};

/** \brief Chains GridSceneFlowEstimation, RigidMotionSegmentation and StaticSceneRegistration
 * over a sequence and composes the camera poses (T_world_curr = T_world_prev * T_prev_curr;
 * frame 0 is the world frame).
 * \code
 * dynvo::app::PipelineOptions options;
 * options.intrinsics = dynvo::CameraIntrinsics::fromPreset("fr1");
 * dynvo::app::OdometryPipeline pipeline(options);
 * dynvo::Frame frame;
 * while (source.next(frame)) {
 *   const auto& result = pipeline.process(frame.cloud, frame.timestamp);
 *   std::cout << result.T_world_curr << (result.lost ? " (lost)" : "") << "\n";
 * }
 * \endcode
 */
class DYNVO_EXPORTS OdometryPipeline {
public:
  /// \throws std::invalid_argument when options.validate() fails
  explicit OdometryPipeline(const PipelineOptions& options);
  ~OdometryPipeline();
  OdometryPipeline(const OdometryPipeline&) = delete;
  OdometryPipeline& operator=(const OdometryPipeline&) = delete;

  /** \brief Processes the next frame of the sequence.
   * \param[in] cloud organized frame (metres, NaN where no depth), same size every frame
   * \param[in] timestamp seconds
   * \return the frame's result, valid until the next call
   * \throws std::invalid_argument when the cloud is null, unorganized or changes size
   */
  const FrameResult& process(const pcl::PointCloud<pcl::PointXYZRGB>::ConstPtr& cloud,
                             double timestamp);

  /// Forgets the sequence: the next frame becomes frame 0 again.
  void reset();

  /// Frames processed since construction or reset().
  std::size_t frameCount() const;

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

} // namespace dynvo::app
