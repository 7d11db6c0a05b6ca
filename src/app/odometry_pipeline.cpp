// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/app/odometry_pipeline.h>
#include <dynvo/common/parallel.h>
#include <dynvo/common/rigid_fit.h>
#include <dynvo/common/trajectory.h>
#include <dynvo/io/label_io.h>
#include <dynvo/motion_segmentation/rigid_motion_segmentation.h>
#include <dynvo/registration/inlier_noise_tracker.h>
#include <dynvo/registration/static_mask_registration.h>
#include <dynvo/registration/static_scene_registration.h>
#include <dynvo/registration/static_set_selection.h>
#include <dynvo/scene_flow/grid_scene_flow_estimation.h>

#include <pcl/console/print.h>

#include <Eigen/Geometry>
#include <Eigen/SVD>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <future>
#include <stdexcept>

namespace dynvo::app {

namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZRGB>;
using Clock = std::chrono::steady_clock;

double
millisecondsSince(Clock::time_point start)
{
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

/// Projects the rotation of a pose back onto SO(3) (drift of repeated products).
void
orthonormalize(Eigen::Matrix4d& T)
{
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(T.topLeftCorner<3, 3>(),
                                        Eigen::ComputeFullU | Eigen::ComputeFullV);
  T.topLeftCorner<3, 3>() = svd.matrixU() * svd.matrixV().transpose();
}

/** The largest share x in [0, 1] of a camera step T_curr_prev (blendPose(I, T, x)) that
 * stays within the motion bound over dt seconds; 0 when the step is not finite.
 */
double
shareWithinBound(const Eigen::Matrix4d& T_curr_prev,
                 double dt,
                 const PipelineOptions& o)
{
  if (!T_curr_prev.allFinite())
    return 0.0;
  const double distance = T_curr_prev.topRightCorner<3, 1>().norm();
  const double angle =
      Eigen::AngleAxisd(Eigen::Matrix3d(T_curr_prev.topLeftCorner<3, 3>())).angle();
  double share = 1.0;
  if (distance > o.max_speed * dt)
    share = std::min(share, o.max_speed * dt / distance);
  if (angle > o.max_rotation_rate * dt)
    share = std::min(share, o.max_rotation_rate * dt / angle);
  return share;
}

/// The step T_curr_prev taken x times (blendPose from the identity; x >= 0).
Eigen::Matrix4d
scaleStep(const Eigen::Matrix4d& T_curr_prev, double x)
{
  return blendPose(Eigen::Isometry3d::Identity(), Eigen::Isometry3d(T_curr_prev), x)
      .matrix();
}

/// The step T_curr_prev, scaled down to its share within the motion bound over dt seconds
/// (shareWithinBound()) when it lies beyond it.
Eigen::Matrix4d
boundedStep(const Eigen::Matrix4d& T_curr_prev, double dt, const PipelineOptions& o)
{
  const double share = shareWithinBound(T_curr_prev, dt, o);
  return share < 1.0 ? scaleStep(T_curr_prev, share) : T_curr_prev;
}

/// How far the velocity of the last measured step (taken over step_interval seconds) carries
/// the camera between `since` and `since + interval` seconds after that step's frame, in
/// steps (docs/algorithm.md §7.5): it holds for `hold` seconds, then fades with the time
/// constant `memory`.
double
velocityReach(
    double since, double interval, double hold, double step_interval, double memory)
{
  const auto reach = [&](double t) {
    return (t <= hold ? t : hold - memory * std::expm1(-(t - hold) / memory)) /
           step_interval;
  };
  return reach(since + interval) - reach(since);
}

/// RMS distance (metres) by which the step T_curr_prev moves the previous-frame points a_i
/// of the valid flow cells; 0 without any.
double
predictedDisplacement(const pcl::PointCloud<PointFlow>& flow,
                      const Eigen::Matrix4d& T_curr_prev)
{
  double sum = 0.0;
  std::size_t count = 0;
  for (const PointFlow& cell : flow) {
    if (!cell.valid_3d)
      continue;
    const Eigen::Vector3d a(cell.prev_x, cell.prev_y, cell.prev_z);
    sum += ((T_curr_prev * a.homogeneous()).head<3>() - a).squaredNorm();
    ++count;
  }
  return count > 0 ? std::sqrt(sum / static_cast<double>(count)) : 0.0;
}

LostReason
lostReasonOf(StaticRegistrationStatus status)
{
  return status == StaticRegistrationStatus::degenerate
             ? LostReason::degenerate
             : LostReason::too_few_static_cells;
}

std::string
sizeText(const Cloud& cloud)
{
  return std::to_string(cloud.width) + "x" + std::to_string(cloud.height);
}

} // namespace

const char*
lostReasonName(LostReason reason)
{
  switch (reason) {
  case LostReason::none:
    return "none";
  case LostReason::bad_frame:
    return "bad_frame";
  case LostReason::too_few_static_cells:
    return "too_few_static_cells";
  case LostReason::degenerate:
    return "degenerate";
  case LostReason::beyond_bound:
    return "beyond_bound";
  }
  return "unknown";
}

PipelineOptions::PipelineOptions()
{
  scene_flow.depth_window_radius = 6;
  segmentation.inlier_threshold = 6e-5f;
  backend.backend = RegistrationBackend::direct;
}

void
PipelineOptions::validate() const
{
  intrinsics.validate();
  scene_flow.validate();
  segmentation.validate();
  registration.validate();
  backend.validate();
  static_set.validate();
  inlier_noise.validate();
  motion_evidence.validate();
  table().checkAll(*this, "[dynvo::app::PipelineOptions]");
  if (!(inlier_noise.min_inlier_threshold <= segmentation.inlier_threshold))
    throw std::invalid_argument(
        "[dynvo::app::PipelineOptions] min_inlier_threshold must "
        "be <= segmentation.inlier_threshold");
}

struct OdometryPipeline::Impl {
  explicit Impl(const PipelineOptions& o)
      : options(o)
  {
    options.validate();
    flow_estimation.setCameraIntrinsics(options.intrinsics);
    flow_estimation.setParameters(options.scene_flow);
    flow_estimation.setNumberOfThreads(options.threads);
    segmentation.setCameraIntrinsics(options.intrinsics);
    segmentation.setParameters(options.segmentation);
    segmentation.setNumberOfThreads(options.threads);
    registration.setParameters(options.registration);
    keyframe_registration.setParameters(options.registration);
    const auto focal =
        static_cast<float>(0.5 * (options.intrinsics.fx + options.intrinsics.fy));
    registration.setSensorNoise(options.segmentation.noise, focal);
    keyframe_registration.setSensorNoise(options.segmentation.noise, focal);
    selection.setParameters(options.static_set);
    evidence.setParameters(options.motion_evidence);
    evidence.setSensorNoise(options.segmentation.noise, focal);
    noise_tracker.setParameters(options.inlier_noise);
    noise_tracker.setUpperBound(options.segmentation.inlier_threshold);
    backend.setParameters(options.backend);
    backend.setCameraIntrinsics(options.intrinsics);
    backend.setNumberOfThreads(options.threads);
    StaticMaskRegistrationParameters dense = options.backend;
    dense.backend = RegistrationBackend::cv_rgbd;
    recovery.setParameters(dense);
    recovery.setCameraIntrinsics(options.intrinsics);
    if (options.threads > 1)
      worker = std::make_unique<TaskThread>();
  }

  /// Why the frame cannot be processed, or empty when it can.
  std::string frameProblem(const Cloud::ConstPtr& cloud) const
  {
    if (!cloud || !cloud->isOrganized())
      return "the frame must be an organized cloud (2 rows or more), got " +
             (cloud ? sizeText(*cloud) : std::string("none"));
    if (previous &&
        (cloud->width != previous->width || cloud->height != previous->height))
      return "frame size changed from " + sizeText(*previous) + " to " +
             sizeText(*cloud);
    return {};
  }

  void track(const Cloud::ConstPtr& cloud, double depth_stamp)
  {
    const auto flow_start = Clock::now();
    flow_estimation.shiftCurrentToPrevious();
    flow_estimation.setInputCloud(cloud);
    flow_estimation.setInputStamps(result.timestamp, depth_stamp);
    flow_estimation.setPredictedMotion(T_curr_prev_predicted.cast<float>());
    auto flow = pcl::make_shared<pcl::PointCloud<PointFlow>>();
    flow_estimation.compute(*flow);
    // The flow's search started from the prediction turned onto the image's own shift
    // (docs/algorithm.md §1.2); the guards compare against it too, within the motion bound.
    const Eigen::Matrix3f& R_shift = flow_estimation.getPredictionCorrection();
    if (!R_shift.isIdentity()) {
      Eigen::Matrix4d turn = Eigen::Matrix4d::Identity();
      turn.topLeftCorner<3, 3>() = R_shift.transpose().cast<double>();
      T_curr_prev_predicted = boundedStep(T_curr_prev_predicted * turn, step_dt, options);
      PCL_DEBUG(
          "[dynvo::app::OdometryPipeline] frame %zu: the prediction turned by %.2f "
          "deg onto the image's shift\n",
          frames,
          Eigen::AngleAxisf(R_shift).angle() * 180.0f / static_cast<float>(EIGEN_PI));
    }
    result.times.scene_flow_ms = millisecondsSince(flow_start);
    frame_flow = flow;
    startBackendInputs(cloud);

    const auto segmentation_start = Clock::now();
    // The guards' tolerances grow with the predicted motion (docs/algorithm.md §4, §7): the
    // ego-motion guard's by rho D_pred, the segmentation's background guard's by half that.
    const double tau_cv = options.segmentation.static_guard_tolerance;
    const double widening = options.guard_motion_factor *
                            predictedDisplacement(*flow, T_curr_prev_predicted);
    selection.setMotionGuardTolerance(tau_cv + widening);
    if (options.use_segmentation) {
      segmentation.setStaticGuardTolerance(static_cast<float>(tau_cv + 0.5 * widening));
      result.inlier_threshold = noise_tracker.getInlierThreshold();
      segmentation.setInlierThreshold(static_cast<float>(result.inlier_threshold));
      segmentation.setInputCloud(cloud);
      segmentation.setInputDepth(flow_estimation.getInputDepth());
      segmentation.setInputFlow(flow);
      segmentation.setPredictedMotion(T_curr_prev_predicted.cast<float>());
      segmentation.segmentCells();
      result.segment_labels = segmentation.getSegmentLabels();
      result.motions = segmentation.getMotions();
      selection.setCellLabels(segmentation.getCellGrid());
      selection.setInlierThreshold(result.inlier_threshold);
      evidence.predict(*flow, cloud->width, cloud->height);
      selection.setMovingCells(evidence.getMovingCells());
    }
    else {
      selection.clearCellLabels();
    }
    result.times.segmentation_ms = millisecondsSince(segmentation_start);
    if (options.use_segmentation)
      startSegments();

    const auto registration_start = Clock::now();
    registration.setInputSource(cloud);
    registration.setInputTarget(previous);
    registration.setInputFlow(flow);
    selection.setPredictedMotion(T_curr_prev_predicted);
    result.lost = true;
    if (!selection.align(registration))
      result.lost_reason = lostReasonOf(registration.getStatus());
    else if (!withinBound(
                 rigidInverse(registration.getFinalTransformation().cast<double>())))
      result.lost_reason = LostReason::beyond_bound;
    else {
      result.lost = false;
      noise_tracker.addResidual(registration.getMeanSquaredResidual());
      result.static_cells = registration.getNumberOfInliers();
      result.residual = registration.getMeanSquaredResidual();
    }
    result.T_curr_prev =
        result.lost
            ? T_curr_prev_predicted
            : rigidInverse(registration.getFinalTransformation().cast<double>());
    result.times.registration_ms += backend_inputs_ms.get();
    alignOnStaticMask();
    if (!result.lost) {
      previous_static_cells = selection.getStaticCells();
      markUnmovedCells();
    }
    result.times.registration_ms = millisecondsSince(registration_start);
  }

  /** Registers the frame's static cells against the keyframe and takes a new keyframe when
   * needed (docs/algorithm.md §7.3); sets result.T_world_curr, and result.lost to false when
   * the keyframe fit passes although the frame-to-frame one did not.
   */
  void trackKeyframe(const Cloud::ConstPtr& cloud)
  {
    if (flow_estimation.getKeyframeCloud())
      registerToKeyframe(cloud);
    const Eigen::Matrix4d T_keyframe_curr =
        rigidInverse(T_world_keyframe) * result.T_world_curr;
    const double angle =
        Eigen::AngleAxisd(Eigen::Matrix3d(T_keyframe_curr.topLeftCorner<3, 3>()))
            .angle();
    const bool renew =
        !flow_estimation.getKeyframeCloud() ||
        result.keyframe_overlap < options.keyframe_min_overlap ||
        T_keyframe_curr.topRightCorner<3, 1>().norm() > options.keyframe_max_distance ||
        angle > options.keyframe_max_angle;
    // A lost frame never becomes the keyframe: the next frames are tracked against the last
    // good one.
    PCL_DEBUG(
        "[dynvo::app::OdometryPipeline] frame %zu: keyframe overlap %.2f, %.3f m, "
        "%.3f rad from it%s\n",
        frames, result.keyframe_overlap, T_keyframe_curr.topRightCorner<3, 1>().norm(),
        angle, renew ? ", new keyframe" : "");
    if (renew && !result.lost && flow_estimation.setCurrentAsKeyframe()) {
      T_world_keyframe = result.T_world_curr;
      keyframe_frame = frames;
      keyframe_inliers = 0;
      result.keyframe = true;
    }
  }

  /// The colour interval dt (s) from the previous frame; one that is not positive (stamps
  /// not increasing) counts as the last measured one.
  double colourInterval(double dt) const
  {
    return std::isfinite(dt) && dt > 0.0 ? dt : last_colour_dt;
  }

  /// The last measured step carried over the colour interval dt that follows the previous
  /// frame (velocityReach()), within the motion bound over bound_dt. The velocity holds up
  /// to the first frame after the measured one, good or bad: the whole step is the flow's
  /// best seed (docs/algorithm.md §7.5).
  Eigen::Matrix4d predictStep(double dt, double bound_dt)
  {
    if (hold == 0.0)
      hold = dt;
    const double x =
        velocityReach(unmeasured, dt, hold, last_colour_dt, options.velocity_memory);
    return boundedStep(x != 1.0 ? scaleStep(last_step, x) : last_step, bound_dt,
                       options);
  }

  /// The step T_curr_prev lies within the motion bound over this frame's step_dt.
  bool withinBound(const Eigen::Matrix4d& T_curr_prev) const
  {
    return shareWithinBound(T_curr_prev, step_dt, options) >= 1.0;
  }

  /** Segments a frame without a background again against its measured step (docs/algorithm.md
   * §4): the guard's reference is the best motion estimate there is, the prediction before
   * the fit and the fit itself after it, within tau_cv (the measured step has no prediction
   * error to widen for).
   */
  void resegment()
  {
    const auto start = Clock::now();
    segmentation.setPredictedMotion(result.T_curr_prev.cast<float>());
    segmentation.setStaticGuardTolerance(
        static_cast<float>(options.segmentation.static_guard_tolerance));
    segmentation.resegment(result.segments);
    PCL_DEBUG("[dynvo::app::OdometryPipeline] frame %zu: segmented again against the "
              "measured step, %s background\n",
              frames, segmentation.hasBackground() ? "a" : "still no");
    result.segment_labels = segmentation.getSegmentLabels();
    result.motions = segmentation.getMotions();
    makeLabelImage();
    result.times.segmentation_ms += millisecondsSince(start);
  }

  /// result.labels: the segmentation's pixel labels when it made them for this frame, else
  /// painted from result.segments (the first frame's start-up segment, or none).
  void makeLabelImage()
  {
    const std::vector<std::uint8_t>& pixels = segmentation.getPixelLabels();
    result.labels = options.use_segmentation && frames > 0 &&
                            pixels.size() == std::size_t{result.width} * result.height
                        ? pixels
                        : paintLabelImage(result.segments, result.segment_labels,
                                          result.width, result.height)
                              .data;
  }

  /** The backend's inputs that do not depend on this frame's fits: the direct backend's
   * pyramids of this frame (from the grey levels and depths the flow read) and the previous
   * frame's samples on its static cells. With a second thread they are made beside the
   * segmentation's cell stage, which runs on one; track() waits for them before the backend
   * runs, and their time counts in registration_ms.
   */
  void startBackendInputs(const Cloud::ConstPtr& cloud)
  {
    const auto inputs = [this, cloud, target_cells = previous_static_cells] {
      const auto start = Clock::now();
      backend.setInputSource(cloud, flow_estimation.getInputGrey(),
                             *flow_estimation.getInputDepth());
      backend.setInputTarget(previous);
      if (target_cells.size() > 0) {
        backend.setTargetStaticCells(target_cells);
        backend.precomputeTarget();
      }
      return millisecondsSince(start);
    };
    backend_inputs_ms = start(inputs);
  }

  /// task on the second thread when there is one, else deferred until its future is read
  template <typename Task>
  std::future<double> start(Task task)
  {
    return worker ? worker->run(std::move(task))
                  : std::async(std::launch::deferred, std::move(task));
  }

  /** The segmentation's pixel stage (pixel labels, indices, the label image): nothing the
   * fits do depends on it (they take cells), so with a second thread it runs beside them until
   * finishSegments(). Its time counts in segmentation_ms, so with two threads the stages can
   * add up to more than the frame's total.
   */
  void startSegments()
  {
    const auto pixel_stage = [this] {
      const auto start = Clock::now();
      segmentation.computeSegments(result.segments);
      makeLabelImage();
      return millisecondsSince(start);
    };
    segments_ms = start(pixel_stage);
  }

  /** Waits for startSegments(); nothing before it may touch the segmentation or the segments
   * (hasBackground() and the other const getters of the cell stage aside). A stage not
   * started yet (one thread) is dropped when not `needed`.
   */
  void finishSegments(bool needed)
  {
    if (!segments_ms.valid())
      return;
    if (!needed &&
        segments_ms.wait_for(std::chrono::seconds(0)) == std::future_status::deferred)
      segments_ms = {};
    else
      result.times.segmentation_ms += segments_ms.get();
  }

  /// The fit to the keyframe, seeded with the frame-to-frame estimate (or the prediction).
  void registerToKeyframe(const Cloud::ConstPtr& cloud)
  {
    const auto flow_start = Clock::now();
    const Eigen::Matrix4d T_keyframe_guess =
        rigidInverse(T_world_keyframe) * result.T_world_curr;
    // Without a frame-to-frame estimate the guess is the constant-velocity prediction: the
    // whole pyramid is searched around it.
    const int levels = result.lost ? options.scene_flow.max_pyramid_level : 0;
    // Only the frame-to-frame static set is tracked (every cell after a lost frame).
    flow_estimation.computeToKeyframe(
        T_keyframe_guess.cast<float>(), levels,
        result.lost ? FlowGrid() : selection.getStaticCells(), *keyframe_flow);
    result.times.scene_flow_ms += millisecondsSince(flow_start);

    const auto registration_start = Clock::now();
    keyframe_registration.setInputSource(cloud);
    keyframe_registration.setInputTarget(flow_estimation.getKeyframeCloud());
    keyframe_registration.setInputFlow(keyframe_flow);
    selection.setPredictedMotion(rigidInverse(T_keyframe_guess));
    const bool fitted = selection.align(keyframe_registration);
    const Eigen::Matrix4d T_world_fit =
        T_world_keyframe *
        keyframe_registration.getFinalTransformation().cast<double>();
    if (fitted && withinBound(rigidInverse(T_world_fit) * T_world_prev)) {
      result.T_world_curr = result.lost ? T_world_fit : combineWithChain(T_world_fit);
      result.lost = false;
      result.lost_reason = LostReason::none;
      result.static_cells = keyframe_registration.getNumberOfInliers();
      result.residual = keyframe_registration.getMeanSquaredResidual();
      result.keyframe_index = static_cast<long>(keyframe_frame);
      // The first fit to a keyframe (the frame after it) is the reference of its overlap.
      const std::size_t inliers = keyframe_registration.getNumberOfInliers();
      if (keyframe_inliers == 0)
        keyframe_inliers = inliers;
      result.keyframe_overlap =
          keyframe_inliers == 0
              ? 0.0
              : static_cast<double>(inliers) / static_cast<double>(keyframe_inliers);
    }
    result.times.registration_ms += millisecondsSince(registration_start);
  }

  /** The pose from two measurements (docs/algorithm.md §7.3): the keyframe fit and the
   * frame-to-frame chain, whose step is fitted again, by the method that made it, on the cells
   * the keyframe fit kept (a mover too slow to split off in one frame pair drifts out of the
   * longer baseline's static set). Their mean; with the flow backend, the keyframe fit alone
   * when they depart from each other by more than 3 times the median departure of the last
   * DEPARTURE_HISTORY frames.
   */
  Eigen::Matrix4d combineWithChain(const Eigen::Matrix4d& T_world_fit)
  {
    Eigen::Matrix4d T_world_chain = result.T_world_curr;
    const Eigen::Matrix4f T_prev_curr = rigidInverse(result.T_curr_prev).cast<float>();
    if (options.backend.backend == RegistrationBackend::direct) {
      // The direct step again, its source pixels those of the keyframe fit's cells.
      backend.setSourceStaticCells(selection.getStaticCells());
      Eigen::Matrix4f T_prev_curr_refit;
      if (backend.align(T_prev_curr, T_prev_curr_refit))
        T_world_chain = T_world_prev * T_prev_curr_refit.cast<double>();
    }
    else {
      registration.setStaticCells(selection.getStaticCells());
      pcl::PointCloud<pcl::PointXYZRGB> aligned;
      registration.align(aligned, T_prev_curr);
      if (registration.hasConverged())
        T_world_chain =
            T_world_prev * registration.getFinalTransformation().cast<double>();
    }
    const double departure =
        (rigidInverse(T_world_chain) * T_world_fit).topRightCorner<3, 1>().norm();
    std::vector<double> history(departures.begin(), departures.end());
    const auto middle =
        history.begin() + static_cast<std::ptrdiff_t>(history.size() / 2);
    std::nth_element(history.begin(), middle, history.end());
    // The direct step's refit keeps a slow mover out of the chain by itself (docs/algorithm.md
    // §7.7): the test is the flow backend's.
    const bool apart = options.backend.backend == RegistrationBackend::flow &&
                       history.size() >= MIN_DEPARTURES && departure > 3.0 * *middle;
    departures.push_back(departure);
    if (departures.size() > DEPARTURE_HISTORY)
      departures.pop_front();
    return apart ? T_world_fit
                 : blendPose(Eigen::Isometry3d(T_world_chain),
                             Eigen::Isometry3d(T_world_fit), 0.5)
                       .matrix();
  }

  /// The backend (options.backend, its source set by track()) from the flow estimate, on the
  /// static cells of this frame and of the previous one (this frame's for the first pair,
  /// whose first frame is not labelled); the flow backend keeps the flow estimate.
  void alignOnStaticMask()
  {
    const FlowGrid& static_cells = selection.getStaticCells();
    if (!result.lost && options.backend.backend != RegistrationBackend::flow) {
      backend.setInputTarget(previous);
      backend.setSourceStaticCells(static_cells);
      backend.setTargetStaticCells(
          previous_static_cells.size() > 0 ? previous_static_cells : static_cells);
      Eigen::Matrix4f T_prev_curr;
      backend.align(registration.getFinalTransformation(), T_prev_curr);
      result.T_curr_prev = rigidInverse(T_prev_curr.cast<double>());
    }
  }

  /** Marks in unmoved_cells the cells of this measured frame that nothing calls moving:
   * neither the segmentation (an object's label) nor the motion evidence. Without
   * segmentation every cell.
   */
  void markUnmovedCells()
  {
    const FlowGrid& cells = selection.getStaticCells();
    unmoved_cells = cells;
    const auto called = [&](const FlowGrid& grid, std::size_t i, std::uint8_t above) {
      return grid.sameGeometry(cells) && grid.labels.size() == cells.labels.size() &&
             grid.labels[i] > above;
    };
    for (std::size_t i = 0; i < cells.labels.size(); ++i) {
      const bool moving = options.use_segmentation &&
                          (called(segmentation.getCellGrid(), i, LABEL_STATIC) ||
                           called(evidence.getMovingCells(), i, LABEL_NONE));
      unmoved_cells.labels[i] = moving ? LABEL_NONE : LABEL_STATIC;
    }
  }

  /** A frame that no flow fit measured (docs/algorithm.md §7.5): OpenCV's dense RGB-D
   * odometry against the previous frame, from the prediction, on the cells the last
   * measured frame did not call moving (both frames). Taken when it converges within the
   * motion bound: sets result.T_curr_prev and result.T_world_curr, clears result.lost and
   * sets result.recovered.
   */
  void recoverDense(const Cloud::ConstPtr& cloud)
  {
    const auto start = Clock::now();
    // No frame measured yet: the start-up assumption, every cell static (docs §4).
    FlowGrid mask = unmoved_cells;
    if (mask.size() == 0) {
      mask = FlowGrid(cloud->width, cloud->height,
                      static_cast<std::uint32_t>(options.scene_flow.cell_size));
      std::fill(mask.labels.begin(), mask.labels.end(), LABEL_STATIC);
    }
    recovery.setInputSource(cloud);
    recovery.setInputTarget(previous);
    recovery.setSourceStaticCells(mask);
    recovery.setTargetStaticCells(mask);
    Eigen::Matrix4f T_prev_curr;
    if (recovery.align(rigidInverse(T_curr_prev_predicted).cast<float>(),
                       T_prev_curr)) {
      const Eigen::Matrix4d T_curr_prev = rigidInverse(T_prev_curr.cast<double>());
      if (withinBound(T_curr_prev)) {
        result.T_curr_prev = T_curr_prev;
        result.T_world_curr = T_world_prev * T_prev_curr.cast<double>();
        result.lost = false;
        result.lost_reason = LostReason::none;
        result.recovered = true;
      }
    }
    result.times.registration_ms += millisecondsSince(start);
  }

  PipelineOptions options;
  GridSceneFlowEstimation<pcl::PointXYZRGB> flow_estimation;
  RigidMotionSegmentation<pcl::PointXYZRGB> segmentation;
  StaticSceneRegistration<pcl::PointXYZRGB> registration;
  StaticSceneRegistration<pcl::PointXYZRGB> keyframe_registration;
  pcl::PointCloud<PointFlow>::Ptr keyframe_flow =
      pcl::make_shared<pcl::PointCloud<PointFlow>>();
  Eigen::Matrix4d T_world_keyframe = Eigen::Matrix4d::Identity();
  std::size_t keyframe_inliers =
      0; ///< inliers of the first fit to the keyframe (0: none yet)
  std::size_t keyframe_frame = 0; ///< frame number of the keyframe
  /// frames whose departure between chain and keyframe fit sets the scale of the next
  static constexpr std::size_t DEPARTURE_HISTORY = 30;
  static constexpr std::size_t MIN_DEPARTURES = 5; ///< fewer: the mean, unconditionally
  std::deque<double> departures; ///< the last departures (metres), oldest first
  StaticSetSelection<pcl::PointXYZRGB> selection;
  MotionEvidence evidence;         ///< cells left out of the fits (with segmentation)
  std::future<double> segments_ms; ///< the pixel stage of this frame (startSegments())
  /// the backend's inputs of this frame (startBackendInputs())
  std::future<double> backend_inputs_ms;
  pcl::PointCloud<PointFlow>::ConstPtr
      frame_flow; ///< this frame's flow to the previous
  InlierNoiseTracker noise_tracker;
  StaticMaskRegistration<pcl::PointXYZRGB> backend;
  StaticMaskRegistration<pcl::PointXYZRGB>
      recovery; ///< dense, for frames no fit measured
  /// the static set of the last measured frame (the backend's target mask)
  FlowGrid previous_static_cells;
  /// the last measured frame's cells not called moving (the recovery's mask)
  FlowGrid unmoved_cells;
  Cloud::ConstPtr previous;
  Eigen::Matrix4d T_world_prev =
      Eigen::Matrix4d::Identity();   ///< at the previous frame's depth instant
  double previous_depth_stamp = 0.0; ///< seconds
  double previous_stamp = 0.0;       ///< the previous frame's colour stamp (s)
  /// H_pred of this frame: the last measured step carried over its interval (predictStep())
  Eigen::Matrix4d T_curr_prev_predicted = Eigen::Matrix4d::Identity();
  Eigen::Matrix4d last_step =
      Eigen::Matrix4d::Identity();    ///< T_curr_prev of the last measured frame
  double last_colour_dt = 1.0 / 30.0; ///< that frame's colour interval (s)
  /// seconds from the last measured frame to the previous frame (lost frames between)
  double unmeasured = 0.0;
  double hold = 0.0; ///< seconds the velocity holds after that frame (0: no frame yet)
  double step_dt = 1.0 / 30.0; ///< this frame's interval (s), the bound's duration
  std::size_t frames = 0;
  FrameResult result;
  /// the second thread (threads > 1); last, so that it ends before the members its tasks use
  std::unique_ptr<TaskThread> worker;
};

OdometryPipeline::OdometryPipeline(const PipelineOptions& options)
    : impl_(std::make_unique<Impl>(options))
{
}

OdometryPipeline::~OdometryPipeline() = default;

const FrameResult&
OdometryPipeline::process(const pcl::PointCloud<pcl::PointXYZRGB>::ConstPtr& cloud,
                          double timestamp,
                          double depth_timestamp)
{
  Impl& p = *impl_;
  const auto start = Clock::now();
  FrameResult& result = p.result;
  result = FrameResult{};
  result.timestamp = timestamp;
  result.width = cloud ? cloud->width : 0;
  result.height = cloud ? cloud->height : 0;
  result.error = p.frameProblem(cloud);
  if (!result.error.empty()) {
    // docs/style.md §2.6: one bad frame must not end a recording. The sequence state is
    // kept, so the next frame is registered against the last good one.
    PCL_WARN("[dynvo::app::OdometryPipeline::process] frame at %.6f s skipped and "
             "flagged lost: %s.\n",
             timestamp, result.error.c_str());
    result.lost = true;
    result.lost_reason = LostReason::bad_frame;
    const double dt = p.colourInterval(timestamp - p.previous_stamp);
    result.T_curr_prev = p.predictStep(dt, dt);
    result.T_world_curr = p.T_world_prev * rigidInverse(result.T_curr_prev);
    result.labels.assign(static_cast<std::size_t>(result.width) * result.height,
                         LABEL_NONE);
    result.times.total_ms = millisecondsSince(start);
    return result;
  }
  const double depth_stamp = std::isnan(depth_timestamp) ? timestamp : depth_timestamp;
  if (p.frames == 0) {
    p.flow_estimation.setInputCloud(cloud);
    p.flow_estimation.setInputStamps(timestamp, depth_stamp);
    // No motion to segment yet: under the start-up assumption (docs/algorithm.md §4, §6.1)
    // every pixel with depth is static background.
    result.segments.assign(1, pcl::PointIndices());
    result.segments[0].header = cloud->header;
    for (std::size_t index = 0; index < cloud->size(); ++index)
      if (std::isfinite((*cloud)[index].z))
        result.segments[0].indices.push_back(static_cast<int>(index));
    result.segment_labels.assign(1, LABEL_STATIC);
    result.motions.assign(1, Eigen::Matrix4f::Identity());
  }
  else {
    // The velocity over time (docs/algorithm.md §7.5): the last measured step carried over
    // the colour interval, within the motion bound. The bound holds over the longer of the
    // colour and depth intervals (TUM fr1 drops colour and depth frames at different
    // instants).
    const double colour_dt = p.colourInterval(timestamp - p.previous_stamp);
    const double dt = std::max(colour_dt, depth_stamp - p.previous_depth_stamp);
    p.step_dt = std::isfinite(dt) && dt > 0.0 ? dt : p.step_dt;
    p.T_curr_prev_predicted = p.predictStep(colour_dt, p.step_dt);
    p.track(cloud, depth_stamp);
    result.T_world_curr = p.T_world_prev * rigidInverse(result.T_curr_prev);
    // The keyframe fit is the flow and direct backends'; the others run frame to frame.
    if (p.options.keyframes &&
        (p.options.backend.backend == RegistrationBackend::flow ||
         p.options.backend.backend == RegistrationBackend::direct)) {
      p.trackKeyframe(cloud);
      result.T_curr_prev = rigidInverse(result.T_world_curr) * p.T_world_prev;
    }
    // A measured frame without a background is segmented again (resegment()), which makes
    // its own pixel stage: the first one is then not needed.
    const bool segment_again =
        !result.lost && p.options.use_segmentation && !p.segmentation.hasBackground();
    p.finishSegments(!segment_again);
    if (result.lost)
      p.recoverDense(cloud);
    else if (segment_again)
      p.resegment();
    // Every pose is rigid: a product that drifts off SO(3) makes rigidInverse() inexact, and
    // the last step, taken from two poses, feeds the error back through the prediction on
    // lost frames until it diverges (docs/algorithm.md §7.5).
    orthonormalize(result.T_world_curr);
    // A lost frame measures no velocity: the last measured one goes on fading over it.
    if (result.lost) {
      p.unmeasured += colour_dt;
    }
    else {
      p.last_step = result.T_curr_prev;
      p.last_colour_dt = colour_dt;
      p.unmeasured = 0.0;
      p.hold = 0.0;
    }
    if (p.options.use_segmentation && !result.lost)
      p.evidence.update(*p.frame_flow, rigidInverse(result.T_curr_prev));
  }
  // The pixel stage makes the label image (on the second thread when there is one); the
  // first frame and a run without segmentation have no pixel stage.
  if (result.labels.empty())
    p.makeLabelImage();
  // The chain stays at the depth instants; the reported pose moves to the colour stamp.
  const Eigen::Matrix4d T_world_depth = result.T_world_curr;
  if (p.frames > 0 && depth_stamp != timestamp &&
      depth_stamp > p.previous_depth_stamp) {
    // At most one step beyond the depth instant either way: an offset larger than a frame
    // interval is not a sensor's, and extrapolating it would only add the step's noise.
    const double x = std::clamp((timestamp - p.previous_depth_stamp) /
                                    (depth_stamp - p.previous_depth_stamp),
                                0.0, 2.0);
    result.T_world_curr = blendPose(Eigen::Isometry3d(p.T_world_prev),
                                    Eigen::Isometry3d(T_world_depth), x)
                              .matrix();
  }
  p.T_world_prev = T_world_depth;
  p.previous_depth_stamp = depth_stamp;
  p.previous_stamp = timestamp;
  p.previous = cloud;
  ++p.frames;
  result.times.total_ms = millisecondsSince(start);
  return result;
}

void
OdometryPipeline::reset()
{
  impl_ = std::make_unique<Impl>(impl_->options);
}

std::size_t
OdometryPipeline::frameCount() const
{
  return impl_->frames;
}

} // namespace dynvo::app
