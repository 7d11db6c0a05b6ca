// SPDX-License-Identifier: BSD-3-Clause
// Template bodies of GridSceneFlowEstimation (compiled in src/ for XYZRGB and XYZRGBA).
#pragma once

#include <dynvo/common/image.h>
#include <dynvo/common/parallel.h>
#include <dynvo/common/flow_grid.h>
#include <dynvo/common/rigid_fit.h>
#include <dynvo/scene_flow/grid_scene_flow_estimation.h>

#include <pcl/console/print.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace dynvo {

template <typename PointT>
void
GridSceneFlowEstimation<PointT>::setInputCloud(const PointCloudConstPtr& cloud)
{
  Base::setInputCloud(cloud);
  current_ready_ = false;
  input_stamps_ = {};
  grey_.clear();
  depth_.reset();
}

template <typename PointT>
void
GridSceneFlowEstimation<PointT>::setPreviousCloud(const PointCloudConstPtr& cloud)
{
  previous_ = cloud;
  previous_ready_ = false;
  previous_stamps_ = {};
}

template <typename PointT>
void
GridSceneFlowEstimation<PointT>::shiftCurrentToPrevious()
{
  engine_.shiftCurrentToPrevious();
  previous_ = input_;
  previous_ready_ = current_ready_;
  previous_stamps_ = input_stamps_;
  input_.reset();
  current_ready_ = false;
  input_stamps_ = {};
  grey_.clear();
  depth_.reset();
}

template <typename PointT>
void
GridSceneFlowEstimation<PointT>::setCameraIntrinsics(const CameraIntrinsics& intrinsics)
{
  intrinsics.validate();
  intrinsics_ = intrinsics;
}

template <typename PointT>
void
GridSceneFlowEstimation<PointT>::setNumberOfThreads(unsigned threads)
{
  if (threads == 0)
    throw std::invalid_argument("[dynvo::" + getClassName() +
                                "::setNumberOfThreads] need at least 1 thread, got 0");
  threads_ = threads;
}

template <typename PointT>
void
GridSceneFlowEstimation<PointT>::setParameters(const Parameters& parameters)
{
  parameters.validate();
  assignParameters(parameters);
}

template <typename PointT>
void
GridSceneFlowEstimation<PointT>::assignParameters(const Parameters& parameters)
{
  params_ = parameters;
  // Pyramids depend on the LK window and levels, depth maps on the depth rules.
  current_ready_ = false;
  previous_ready_ = false;
  engine_.clearKeyframe();
  keyframe_.reset();
}

template <typename PointT>
bool
GridSceneFlowEstimation<PointT>::initCompute()
{
  const char* name = getClassName().c_str();
  if (!input_ || !previous_) {
    PCL_ERROR("[dynvo::%s::compute] %s cloud not set.\n", name,
              input_ ? "previous" : "input (current)");
    return false;
  }
  if (!input_->isOrganized() || !previous_->isOrganized()) {
    PCL_ERROR("[dynvo::%s::compute] %s cloud is not organized.\n", name,
              input_->isOrganized() ? "previous" : "input (current)");
    return false;
  }
  if (input_->width != previous_->width || input_->height != previous_->height) {
    PCL_ERROR(
        "[dynvo::%s::compute] input cloud is %ux%u but previous cloud is %ux%u.\n",
        name, input_->width, input_->height, previous_->width, previous_->height);
    return false;
  }
  return true;
}

template <typename PointT>
bool
GridSceneFlowEstimation<PointT>::validateInputs() const
{
  const auto cell = static_cast<std::uint32_t>(params_.cell_size);
  if (input_->width < cell || input_->height < cell) {
    PCL_ERROR("[dynvo::%s::compute] a %ux%u cloud holds no %u px grid cell.\n",
              getClassName().c_str(), input_->width, input_->height, cell);
    return false;
  }
  // The consumers infer the cell size as width / grid columns (FlowGrid::fromFlow()).
  if (!FlowGrid(input_->width, input_->height, cell).isInferable()) {
    PCL_ERROR(
        "[dynvo::%s::compute] %u px cells on a %u px wide cloud leave more columns "
        "over than there are cells: the cell size could not be inferred from the "
        "grid.\n",
        getClassName().c_str(), cell, input_->width);
    return false;
  }
  return true;
}

template <typename PointT>
void
GridSceneFlowEstimation<PointT>::prepareFrame(
    const PointCloud& cloud,
    detail::GridFlowEngine::Slot slot,
    const detail::GridFlowEngine::FrameStamps& stamps,
    std::vector<std::uint8_t>& grey,
    std::vector<float>& depth)
{
  const std::size_t size = cloud.size();
  grey.resize(size);
  depth.resize(size);
  forEachStripe(size, threads_, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      const PointT& p = cloud[i];
      grey[i] = luma(p.r, p.g, p.b);
      depth[i] = std::isfinite(p.z) ? p.z : std::numeric_limits<float>::quiet_NaN();
    }
  });
  engine_.prepare(slot, grey, depth, cloud.width, cloud.height, params_, threads_,
                  stamps);
}

template <typename PointT>
void
GridSceneFlowEstimation<PointT>::compute(FlowCloud& flow)
{
  flow.clear();
  prediction_correction_.setIdentity();
  params_.validate(); // the per-field setters leave the cross-field rules to here
  if (!initCompute())
    return;
  struct DeinitGuard {
    GridSceneFlowEstimation& self;
    ~DeinitGuard() { self.deinitCompute(); }
  } guard{*this};
  if (!validateInputs())
    return;
  if (!current_ready_) {
    // A buffer no one else holds (use count 1: this object's), else a new one in place of
    // the first (its holder keeps it).
    depth_.reset();
    auto unheld = std::find_if(depth_buffers_.begin(), depth_buffers_.end(),
                               [](const auto& buffer) { return buffer.use_count() <= 1; });
    if (unheld == depth_buffers_.end())
      unheld = depth_buffers_.begin();
    if (unheld->use_count() != 1)
      *unheld = std::make_shared<std::vector<float>>();
    depth_ = *unheld;
    prepareFrame(*input_, detail::GridFlowEngine::Slot::current, input_stamps_, grey_,
                 *depth_);
  }
  current_ready_ = true;
  if (!previous_ready_) { // the first pair, or a previous cloud set apart
    std::vector<std::uint8_t> grey;
    std::vector<float> depth;
    prepareFrame(*previous_, detail::GridFlowEngine::Slot::previous, previous_stamps_,
                 grey, depth);
  }
  previous_ready_ = true;
  prediction_correction_ = engine_.compute(
      params_, intrinsics_, threads_,
      rigidInverse(predicted_motion_.cast<double>()).cast<float>(), flow);
  flow.header = input_->header;
}

template <typename PointT>
bool
GridSceneFlowEstimation<PointT>::setCurrentAsKeyframe()
{
  if (!input_ || !current_ready_) {
    PCL_ERROR("[dynvo::%s::setCurrentAsKeyframe] the input cloud has not been "
              "prepared by compute().\n",
              getClassName().c_str());
    return false;
  }
  engine_.keepCurrentAsKeyframe();
  keyframe_ = input_;
  return true;
}

template <typename PointT>
void
GridSceneFlowEstimation<PointT>::computeToKeyframe(
    const Eigen::Matrix4f& T_keyframe_current,
    int max_level,
    const FlowGrid& cells,
    FlowCloud& flow)
{
  flow.clear();
  if (!keyframe_ || !input_ || !current_ready_) {
    PCL_ERROR("[dynvo::%s::computeToKeyframe] %s.\n", getClassName().c_str(),
              keyframe_ ? "the input cloud has not been prepared by compute()"
                        : "no keyframe set");
    return;
  }
  const FlowGrid grid(input_->width, input_->height,
                      static_cast<std::uint32_t>(params_.cell_size));
  if (cells.size() > 0 && !cells.sameGeometry(grid)) {
    PCL_ERROR(
        "[dynvo::%s::computeToKeyframe] the cells are not the flow's %ux%u grid.\n",
        getClassName().c_str(), grid.cols, grid.rows);
    return;
  }
  selected_.clear();
  for (const std::uint8_t label : cells.labels)
    selected_.push_back(label == LABEL_STATIC);
  engine_.computeToKeyframe(params_, intrinsics_, threads_, T_keyframe_current,
                            selected_, max_level, flow);
  flow.header = input_->header;
}

} // namespace dynvo
