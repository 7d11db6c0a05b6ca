// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/app/odometry_pipeline.h>
#include <dynvo/common/rigid_fit.h>
#include <dynvo/io/label_io.h>
#include <dynvo/motion_segmentation/rigid_motion_segmentation.h>
#include <dynvo/registration/static_scene_registration.h>
#include <dynvo/scene_flow/grid_scene_flow_estimation.h>

#include <Eigen/SVD>

#include <algorithm>
#include <chrono>
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

/// Rigid inverse of a pose.
Eigen::Matrix4d
inverse(const Eigen::Matrix4d& T)
{
  Eigen::Matrix4d inv = Eigen::Matrix4d::Identity();
  inv.topLeftCorner<3, 3>() = T.topLeftCorner<3, 3>().transpose();
  inv.topRightCorner<3, 1>() = -inv.topLeftCorner<3, 3>() * T.topRightCorner<3, 1>();
  return inv;
}

/// Centre pixel of every valid_3d cell: the whole valid flow counts as static (ablation).
pcl::IndicesPtr
allValidCells(const pcl::PointCloud<PointFlow>& flow, std::uint32_t image_width)
{
  auto indices = pcl::make_shared<pcl::Indices>();
  for (const PointFlow& cell : flow)
    if (cell.valid_3d)
      indices->push_back(static_cast<int>(cell.v) * static_cast<int>(image_width) +
                         static_cast<int>(cell.u));
  return indices;
}

} // namespace

PipelineOptions::PipelineOptions()
{
  scene_flow.depth_window_radius = 6;
  segmentation.inlier_threshold = 6e-5f;
}

void
PipelineOptions::validate() const
{
  intrinsics.validate();
  scene_flow.validate();
  segmentation.validate();
  registration.validate();
  table().checkAll(*this, "[dynvo::app::PipelineOptions]");
  if (!(min_inlier_threshold <= segmentation.inlier_threshold))
    throw std::invalid_argument(
        "[dynvo::app::PipelineOptions] min_inlier_threshold must "
        "be <= segmentation.inlier_threshold");
  if (segmentation.cell_size != scene_flow.cell_size)
    throw std::invalid_argument(
        "[dynvo::app::PipelineOptions] segmentation cell_size " +
        std::to_string(segmentation.cell_size) + " differs from scene flow cell_size " +
        std::to_string(scene_flow.cell_size));
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
  }

  void track(const Cloud::ConstPtr& cloud)
  {
    const auto flow_start = Clock::now();
    flow_estimation.shiftCurrentToPrevious();
    flow_estimation.setInputCloud(cloud);
    auto flow = pcl::make_shared<pcl::PointCloud<PointFlow>>();
    flow_estimation.compute(*flow);
    result.times.scene_flow_ms = millisecondsSince(flow_start);

    const auto segmentation_start = Clock::now();
    pcl::IndicesPtr static_indices;
    if (options.use_segmentation) {
      if (options.inlier_noise_factor > 0.0f && residual_mean > 0.0)
        inlier_threshold =
            std::clamp(options.inlier_noise_factor * residual_mean,
                       static_cast<double>(options.min_inlier_threshold),
                       static_cast<double>(options.segmentation.inlier_threshold));
      segmentation.setInlierThreshold(static_cast<float>(inlier_threshold));
      result.inlier_threshold = inlier_threshold;
      segmentation.setInputCloud(cloud);
      segmentation.setInputFlow(flow);
      segmentation.setPredictedMotion(T_curr_prev_predicted.cast<float>());
      segmentation.segment(result.segments);
      result.segment_labels = segmentation.getSegmentLabels();
      result.motions = segmentation.getMotions();
      static_indices = pcl::make_shared<pcl::Indices>(
          result.segments.empty() ? pcl::Indices{} : result.segments[0].indices);
    }
    else {
      static_indices = allValidCells(*flow, cloud->width);
    }
    result.times.segmentation_ms = millisecondsSince(segmentation_start);

    const auto registration_start = Clock::now();
    registration.setInputSource(cloud);
    registration.setInputTarget(previous);
    registration.setInputFlow(flow);
    // Static support: the segmentation's background gives a first estimate; then every
    // valid cell that moves like it counts as static, so background cells the noisy
    // segmentation split off are used again while moving objects stay out. Motion guard:
    // when that estimate is missing or departs from the constant-velocity prediction by more
    // than tau_cv (a moving object took the background label for a frame), the first
    // estimate comes from the cells within tau_cv of the prediction instead.
    const Eigen::Matrix4d T_prev_curr_predicted = inverse(T_curr_prev_predicted);
    const bool background_fit = align(static_indices, T_prev_curr_predicted);
    Eigen::Matrix4d T_prev_curr = registration.getFinalTransformation().cast<double>();
    const double departure =
        (T_curr_prev_predicted * T_prev_curr).topRightCorner<3, 1>().norm();
    if (options.use_segmentation && options.static_consensus > 0.0f) {
      const double tau = options.segmentation.static_guard_tolerance;
      const bool trusted = background_fit && departure <= tau;
      if (!trusted) {
        align(consensusCells(*flow, *cloud, T_prev_curr_predicted, false, tau * tau),
              T_prev_curr_predicted);
        T_prev_curr = registration.hasConverged()
                          ? registration.getFinalTransformation().cast<double>()
                          : T_prev_curr_predicted;
      }
      align(consensusCells(*flow, *cloud, T_prev_curr, trusted,
                           options.static_consensus * inlier_threshold),
            T_prev_curr);
    }
    result.lost = !registration.hasConverged();
    if (!result.lost)
      residual_mean = residual_mean > 0.0
                          ? 0.9 * residual_mean + 0.1 * registration.getFitnessScore()
                          : registration.getFitnessScore();
    result.T_curr_prev =
        result.lost ? T_curr_prev_predicted
                    : inverse(registration.getFinalTransformation().cast<double>());
    result.times.registration_ms = millisecondsSince(registration_start);
  }

  /// Registers on the given static pixels; true when it converged.
  bool align(const pcl::IndicesPtr& static_indices,
             const Eigen::Matrix4d& T_prev_curr_guess)
  {
    registration.setIndices(static_indices);
    Cloud aligned;
    registration.align(aligned, T_prev_curr_guess.cast<float>());
    return registration.hasConverged();
  }

  /// Centre pixels of the valid cells whose flow agrees with T_prev_curr within `limit`
  /// (squared transfer error of b_i onto a_i, m^2), leaving out the cells labelled as moving
  /// objects when the labels are trusted (slow objects pass the test).
  pcl::IndicesPtr consensusCells(const pcl::PointCloud<PointFlow>& flow,
                                 const Cloud& cloud,
                                 const Eigen::Matrix4d& T_prev_curr,
                                 bool exclude_objects,
                                 double limit) const
  {
    const std::vector<std::uint8_t>& labels = segmentation.getCellLabels();
    auto indices = pcl::make_shared<pcl::Indices>();
    for (std::size_t i = 0; i < flow.size(); ++i) {
      const PointFlow& cell = flow[i];
      if (cell.valid_3d && !(exclude_objects && labels[i] > LABEL_STATIC) &&
          squaredTransferError(
              T_prev_curr, cell.getVector3fMap().cast<double>(),
              Eigen::Vector3d(cell.prev_x, cell.prev_y, cell.prev_z)) <= limit)
        indices->push_back(static_cast<int>(cell.v) * static_cast<int>(cloud.width) +
                           static_cast<int>(cell.u));
    }
    return indices;
  }

  PipelineOptions options;
  GridSceneFlowEstimation<pcl::PointXYZRGB> flow_estimation;
  RigidMotionSegmentation<pcl::PointXYZRGB> segmentation;
  StaticSceneRegistration<pcl::PointXYZRGB> registration;
  Cloud::ConstPtr previous;
  Eigen::Matrix4d T_world_prev = Eigen::Matrix4d::Identity();
  Eigen::Matrix4d T_curr_prev_predicted = Eigen::Matrix4d::Identity();
  double residual_mean =
      0.0; ///< running mean of the static fit's residual (m^2), 0 = none
  /// this frame's segmentation inlier threshold (m^2), noise-following
  double inlier_threshold = options.segmentation.inlier_threshold;
  std::size_t frames = 0;
  FrameResult result;
};

OdometryPipeline::OdometryPipeline(const PipelineOptions& options)
    : impl_(std::make_unique<Impl>(options))
{
}

OdometryPipeline::~OdometryPipeline() = default;

const FrameResult&
OdometryPipeline::process(const pcl::PointCloud<pcl::PointXYZRGB>::ConstPtr& cloud,
                          double timestamp)
{
  Impl& p = *impl_;
  if (!cloud || !cloud->isOrganized())
    throw std::invalid_argument(
        "[dynvo::app::OdometryPipeline::process] the frame must be an organized cloud "
        "(2 rows or more), got " +
        (cloud ? std::to_string(cloud->width) + "x" + std::to_string(cloud->height)
               : std::string("none")));
  if (p.previous &&
      (cloud->width != p.previous->width || cloud->height != p.previous->height))
    throw std::invalid_argument(
        "[dynvo::app::OdometryPipeline::process] frame size changed from " +
        std::to_string(p.previous->width) + "x" + std::to_string(p.previous->height) +
        " to " + std::to_string(cloud->width) + "x" + std::to_string(cloud->height));

  const auto start = Clock::now();
  FrameResult& result = p.result;
  result = FrameResult{};
  result.timestamp = timestamp;
  result.width = cloud->width;
  result.height = cloud->height;
  if (p.frames == 0) {
    p.flow_estimation.setInputCloud(cloud);
  }
  else {
    p.track(cloud);
    result.T_world_curr = p.T_world_prev * inverse(result.T_curr_prev);
    if (p.frames % 100 == 0)
      orthonormalize(result.T_world_curr);
    p.T_curr_prev_predicted = result.T_curr_prev;
  }
  result.labels = paintLabelImage(result.segments, result.segment_labels, result.width,
                                  result.height)
                      .data;
  p.T_world_prev = result.T_world_curr;
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
