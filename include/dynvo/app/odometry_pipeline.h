// SPDX-License-Identifier: BSD-3-Clause
// The whole odometry: scene flow -> rigid motion segmentation -> static-only registration.
#pragma once

#include <dynvo/common/camera.h>
#include <dynvo/common/export.h>
#include <dynvo/common/parameter_table.h>
#include <dynvo/motion_segmentation/rigid_motion_segmentation_parameters.h>
#include <dynvo/registration/inlier_noise_tracker.h>
#include <dynvo/registration/motion_evidence.h>
#include <dynvo/registration/static_mask_registration_parameters.h>
#include <dynvo/registration/static_scene_registration_parameters.h>
#include <dynvo/registration/static_set_selection_parameters.h>
#include <dynvo/scene_flow/grid_scene_flow_parameters.h>

#include <pcl/PointIndices.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <Eigen/Core>
#include <Eigen/StdVector>

#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace dynvo::app {

/// Every knob of the pipeline: the modules' parameters plus the pipeline's own.
struct DYNVO_EXPORTS PipelineOptions {
  /// The modules' defaults, except three (the measurements behind them: src/app/NOTES.md):
  /// - the segmentation's inlier threshold: 6e-5 m^2 (7.7 mm) instead of the paper's 3e-5,
  ///   for real Kinect noise; it is also the upper bound of the noise-following threshold;
  /// - the scene flow's depth window radius: 6 px (a 7x7 sample of a 13x13 window) instead
  ///   of the single pixel, so that the depth noise at c_i stays below the inlier radius;
  /// - the ego-motion backend: direct (docs/algorithm.md §7.7) instead of the flow fit alone,
  ///   more accurate on every real clip.
  PipelineOptions();

  CameraIntrinsics intrinsics;        ///< back-projection of the input frames
  GridSceneFlowParameters scene_flow; ///< docs/algorithm.md §1
  RigidMotionSegmentationParameters
      segmentation; ///< docs/algorithm.md §3-§6 (seed included)
  StaticSceneRegistrationParameters registration; ///< docs/algorithm.md §7
  /// The ego-motion method on the static mask, from the flow estimate (StaticMaskRegistration;
  /// YAML registration.backend, registration.icp_*, registration.rgbd_*).
  StaticMaskRegistrationParameters backend;
  bool use_segmentation =
      true; ///< false: ablation, every valid flow cell counts as static
  /// Static consensus and motion guard (StaticSetSelection; YAML pipeline.static_consensus);
  /// tau_cv is segmentation.static_guard_tolerance.
  StaticSetSelectionParameters static_set;
  /// Noise-following inlier threshold (InlierNoiseTracker; YAML pipeline.inlier_noise_factor
  /// and pipeline.min_inlier_threshold), bounded above by segmentation.inlier_threshold.
  InlierNoiseTrackerParameters inlier_noise;
  /// Per-cell evidence of motion over frames (MotionEvidence; YAML pipeline.evidence_*):
  /// cells above its limit are left out of every fit. Only with segmentation.
  MotionEvidenceParameters motion_evidence;
  unsigned threads = 1; ///< worker threads; results do not depend on it
  /// Keyframe registration (docs/algorithm.md §7.3): the static cells of each frame are also
  /// registered against the current keyframe, which gives the pose; false: frame to frame.
  /// Only with the flow and direct backends (backend.backend); the others run frame to frame.
  bool keyframes = true;
  /// A new keyframe is taken when the inliers of the fit to the keyframe drop below this
  /// share of those of the first fit to it (static overlap, (0, 1]) ...
  double keyframe_min_overlap = 0.6;
  double keyframe_max_distance =
      0.3;                          ///< ... or the camera moved farther from it (m) ...
  double keyframe_max_angle = 0.35; ///< ... or turned by more (rad, 20 deg)
  /// Physical bound of the camera's motion (docs/algorithm.md §7.5): a fit that moves the
  /// camera faster than max_speed (m/s) or turns it faster than max_rotation_rate (rad/s)
  /// between the frames' depth instants, or is not finite, is rejected and the frame lost;
  /// the constant-velocity prediction is scaled down to the same bound.
  double max_speed = 3.0;
  double max_rotation_rate = 4.0; ///< rad/s (229 deg/s)
  /// Time constant (s) with which the last measured velocity fades while no frame measures
  /// it (docs/algorithm.md §7.5): it holds up to the first frame after the measured one,
  /// then fades, so over a blind stretch of any length (lost or bad frames) the prediction
  /// moves the camera about the last velocity times one frame interval plus this many
  /// seconds in all. 0.3 s: how long a hand-held camera's measured step still predicts its
  /// motion.
  double velocity_memory = 0.3;
  /// The motion guard's tolerance (segmentation.static_guard_tolerance, tau_cv) grows by
  /// this share of the RMS distance the predicted motion moves the flow's points: a
  /// constant-velocity prediction is off by more when the camera moves fast
  /// (docs/algorithm.md §7; 0 = the fixed tau_cv).
  double guard_motion_factor = 0.5;

  /// Names, units and ranges of the pipeline's own fields (use_segmentation, threads and
  /// the keyframe policy); the modules' fields, static_set's and inlier_noise's are in their
  /// Parameters::table().
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

/// Why a frame is lost (FrameResult::lost_reason).
enum class LostReason {
  none,                 ///< not lost
  bad_frame,            ///< the frame broke the contract (FrameResult::error)
  too_few_static_cells, ///< fewer usable static cells than the fit needs
  degenerate,           ///< the static cells do not constrain a motion
  beyond_bound ///< the fit was not finite or beyond PipelineOptions::max_speed or
               ///< max_rotation_rate
};

/// "none", "bad_frame", "too_few_static_cells", "degenerate" or "beyond_bound".
DYNVO_EXPORTS const char* lostReasonName(LostReason reason);

/// Everything the pipeline knows about one frame.
struct FrameResult {
  double timestamp = 0.0; ///< seconds (the colour image's stamp)
  /// camera pose at `timestamp` (camera-to-world). The 3D points, hence the fits, belong to
  /// the depth image's instant; when its stamp differs (TUM fr1: by up to 17 ms either way),
  /// the pose is carried to `timestamp` along the step from the previous frame's depth
  /// instant (docs/algorithm.md §7.4)
  Eigen::Matrix4d T_world_curr = Eigen::Matrix4d::Identity();
  Eigen::Matrix4d T_curr_prev =
      Eigen::Matrix4d::Identity(); ///< ego-motion H_k (identity at frame 0)
  /// no ego-motion (too few static cells, or a bad frame: see error); T_curr_prev is then
  /// the constant-velocity prediction
  bool lost = false;
  LostReason lost_reason = LostReason::none; ///< why lost (none when not)
  /// no flow fit measured the frame, and OpenCV's dense RGB-D odometry on the cells the
  /// last measured frame did not call moving recovered it (not lost; static_cells and
  /// residual are 0)
  bool recovered = false;
  /// static cells of the fit that gave the pose (its inliers; 0 when lost)
  std::size_t static_cells = 0;
  /// mean squared transfer error of those cells (m^2; 0 when lost)
  double residual = 0.0;
  /// frame number (from 0) of the keyframe the pose was measured against; -1 when the pose
  /// is frame to frame or predicted
  long keyframe_index = -1;
  /// this frame became the keyframe later frames are registered against
  bool keyframe = false;
  /// inliers of the fit to the keyframe over those of the first fit to it, on the frame
  /// after the keyframe (1 there; 0 when the fit failed or keyframes are off)
  double keyframe_overlap = 0.0;
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
      labels;        ///< per pixel: 0 no measurement, 1 static, 2.. objects
  StageTimes times;  ///< stage timings
  std::string error; ///< why the frame was not processed (then lost); empty when it was
};

/** \brief Chains GridSceneFlowEstimation, RigidMotionSegmentation, StaticSetSelection (on
 * StaticSceneRegistration) and InlierNoiseTracker over a sequence and composes the camera poses
 * (T_world_curr = T_world_prev * T_prev_curr; frame 0 is the world frame).
 *
 * A frame that breaks the contract (null, unorganized, odd-sized or of another size than the
 * first frame) is reported with PCL_WARN and in FrameResult::error, and flagged lost:
 * T_curr_prev is the constant-velocity prediction and the sequence goes on with the next
 * frame as if the bad one had not come (it does not become the previous frame).
 * \code
 * dynvo::app::PipelineOptions options;
 * options.intrinsics = dynvo::CameraIntrinsics::fromPreset("fr1");
 * dynvo::app::OdometryPipeline pipeline(options);
 * dynvo::Frame frame;
 * while (source.next(frame)) {
 *   const auto& result = pipeline.process(frame.cloud, frame.timestamp, frame.depth_timestamp);
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
   * \param[in] timestamp seconds, the colour image's stamp (the stamp of the pose)
   * \param[in] depth_timestamp seconds, the depth image's stamp; NaN (the default): the same
   * \return the frame's result, valid until the next call; a bad frame gives a lost result
   *         with FrameResult::error set (see the class doc)
   */
  const FrameResult&
  process(const pcl::PointCloud<pcl::PointXYZRGB>::ConstPtr& cloud,
          double timestamp,
          double depth_timestamp = std::numeric_limits<double>::quiet_NaN());

  /// Forgets the sequence: the next frame becomes frame 0 again.
  void reset();

  /// Frames processed since construction or reset().
  std::size_t frameCount() const;

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

} // namespace dynvo::app
