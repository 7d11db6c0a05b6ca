// SPDX-License-Identifier: BSD-3-Clause
// Template bodies of RigidMotionSegmentation (compiled in src/ for XYZRGB and XYZRGBA).
#pragma once

#include <dynvo/common/parallel.h>
#include <dynvo/motion_segmentation/rigid_motion_segmentation.h>

#include <pcl/console/print.h>
#include <pcl/point_types.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <numeric>
#include <stdexcept>
#include <string>
#include <utility>

namespace dynvo {

template <typename PointT>
void
RigidMotionSegmentation<PointT>::setInputCloud(const PointCloudConstPtr& cloud)
{
  Base::setInputCloud(cloud);
  input_depth_.reset();
}

template <typename PointT>
void
RigidMotionSegmentation<PointT>::setInputFlow(const FlowCloudConstPtr& flow)
{
  flow_ = flow;
}

template <typename PointT>
void
RigidMotionSegmentation<PointT>::reset()
{
  clearOutputs();
  tracker_.reset();
  noise_gains_ = {1.0f, 1.0f};
}

template <typename PointT>
void
RigidMotionSegmentation<PointT>::setPredictedMotion(const Eigen::Matrix4f& T_curr_prev)
{
  if (!T_curr_prev.allFinite())
    throw std::invalid_argument("[dynvo::" + getClassName() +
                                "::setPredictedMotion] the motion must be finite");
  predicted_motion_ = T_curr_prev;
}

template <typename PointT>
void
RigidMotionSegmentation<PointT>::setCameraIntrinsics(const CameraIntrinsics& intrinsics)
{
  intrinsics.validate();
  intrinsics_ = intrinsics;
}

template <typename PointT>
void
RigidMotionSegmentation<PointT>::setNumberOfThreads(unsigned threads)
{
  if (threads == 0)
    throw std::invalid_argument("[dynvo::" + getClassName() +
                                "::setNumberOfThreads] need at least 1 thread, got 0");
  threads_ = threads;
}

template <typename PointT>
void
RigidMotionSegmentation<PointT>::setParameters(const Parameters& parameters)
{
  parameters.validate();
  assignParameters(parameters);
}

template <typename PointT>
void
RigidMotionSegmentation<PointT>::clearOutputs()
{
  cell_grid_ = FlowGrid();
  output_grid_ = FlowGrid();
  segment_labels_.clear();
  motions_.clear();
  spatial_ = SpatialSegmentationResult();
  pixel_labels_.clear();
}

template <typename PointT>
bool
RigidMotionSegmentation<PointT>::initCompute()
{
  const char* name = getClassName().c_str();
  if (!input_ || !flow_) {
    PCL_ERROR("[dynvo::%s::segment] %s not set.\n", name,
              input_ ? "input flow" : "input (current) cloud");
    return false;
  }
  if (!input_->isOrganized() || !flow_->isOrganized()) {
    PCL_ERROR("[dynvo::%s::segment] %s is not organized.\n", name,
              input_->isOrganized() ? "input flow" : "input (current) cloud");
    return false;
  }
  return true;
}

template <typename PointT>
bool
RigidMotionSegmentation<PointT>::validateInputs()
{
  if (!FlowGrid::fromFlow(*flow_, input_->width, input_->height, cell_grid_)) {
    PCL_ERROR("[dynvo::%s::segment] a %ux%u flow grid does not tile a %ux%u cloud "
              "(cell size = width / flow width).\n",
              getClassName().c_str(), flow_->width, flow_->height, input_->width,
              input_->height);
    return false;
  }
  return true;
}

template <typename PointT>
void
RigidMotionSegmentation<PointT>::computeImplPixelLabels()
{
  // Fallback of a cell without a label: the dual model's read-out when it is an output id.
  std::vector<std::uint8_t> fallback;
  if (params_.tracking) {
    std::array<bool, 256> output{};
    for (const std::uint8_t id : segment_labels_)
      output[id] = true;
    fallback = tracker_.modelLabels();
    for (std::uint8_t& label : fallback)
      label = output[label] ? label : LABEL_NONE;
  }
  static_assert(sizeof(PointT) % sizeof(float) == 0,
                "point fields must be 4-byte words");
  const std::size_t stride = sizeof(PointT) / sizeof(float);
  const std::uint32_t* rgba = nullptr;
  if constexpr (pcl::traits::has_color<PointT>::value)
    rgba = &(*input_)[0].rgba;
  const bool image = input_depth_ && input_depth_->size() == input_->size();
  refinement_.refine(output_grid_, fallback,
                     image ? input_depth_->data() : &(*input_)[0].z, image ? 1 : stride,
                     rgba, stride, pixel_labels_);
}

template <typename PointT>
void
RigidMotionSegmentation<PointT>::computeImplIndices(
    std::vector<pcl::PointIndices>& segments) const
{
  // Output position of each label id (label ids are < 256).
  std::array<int, 256> slot;
  slot.fill(-1);
  for (std::size_t s = 0; s < segment_labels_.size(); ++s)
    slot[segment_labels_[s]] = static_cast<int>(s);
  const int width = static_cast<int>(input_->width);
  const int height = static_cast<int>(input_->height);
  // Stripes of pixel rows, concatenated in order: the same indices for any thread count.
  const int stripes = std::max(1, std::min<int>(static_cast<int>(threads_), height));
  std::vector<std::vector<std::vector<int>>> parts(
      stripes, std::vector<std::vector<int>>(segment_labels_.size()));
  const auto extract = [&](std::size_t stripe, std::size_t) {
    std::vector<std::vector<int>>& out = parts[stripe];
    const int first = width * (height * static_cast<int>(stripe) / stripes);
    const int end = width * (height * (static_cast<int>(stripe) + 1) / stripes);
    // Runs of one label (most of a row is one segment): counted, then written as ranges.
    struct Run {
      int begin, end, segment;
    };
    std::vector<Run> runs;
    std::vector<std::size_t> size(out.size(), 0);
    for (int index = first; index < end;) {
      const std::uint8_t label = pixel_labels_[index];
      int run_end = index + 1;
      while (run_end < end && pixel_labels_[run_end] == label)
        ++run_end;
      const int s = slot[label];
      if (s >= 0) {
        runs.push_back({index, run_end, s});
        size[s] += static_cast<std::size_t>(run_end - index);
      }
      index = run_end;
    }
    for (std::size_t s = 0; s < out.size(); ++s)
      out[s].reserve(size[s]);
    for (const Run& run : runs) {
      std::vector<int>& indices = out[run.segment];
      const std::size_t old = indices.size();
      indices.resize(old + static_cast<std::size_t>(run.end - run.begin));
      std::iota(indices.begin() + static_cast<std::ptrdiff_t>(old), indices.end(),
                run.begin);
    }
  };
  forEachStripe(static_cast<std::size_t>(stripes), threads_, extract);
  segments.assign(segment_labels_.size(), pcl::PointIndices());
  for (std::size_t s = 0; s < segments.size(); ++s) {
    segments[s].header = input_->header;
    segments[s].indices = std::move(parts[0][s]);
    for (int stripe = 1; stripe < stripes; ++stripe)
      segments[s].indices.insert(segments[s].indices.end(), parts[stripe][s].begin(),
                                 parts[stripe][s].end());
  }
}

template <typename PointT>
void
RigidMotionSegmentation<PointT>::segment(std::vector<pcl::PointIndices>& segments)
{
  segments.clear();
  segmentCells();
  computeSegments(segments);
}

template <typename PointT>
void
RigidMotionSegmentation<PointT>::segmentCells()
{
  clearOutputs();
  params_.validate(); // the per-field setters leave the cross-field rules to here
  if (!initCompute())
    return;
  struct DeinitGuard {
    RigidMotionSegmentation& self;
    ~DeinitGuard() { self.deinitCompute(); }
  } guard{*this};
  if (!validateInputs())
    return;
  previous_input_ = std::exchange(last_input_, input_);
  grid_.assign(*flow_, cell_grid_);
  computeInformation();
  segmenter_.segment(grid_, params_, spatial_);
  PCL_DEBUG("[dynvo::%s::segment] %d segments from %zu hypotheses (%d trials).\n",
            getClassName().c_str(), spatial_.segmentCount(), spatial_.hypotheses.size(),
            spatial_.trials);
  tracker_before_ = tracker_;
  noise_gains_before_ = noise_gains_;
  computeImplLabels();
}

template <typename PointT>
void
RigidMotionSegmentation<PointT>::computeSegments(
    std::vector<pcl::PointIndices>& segments)
{
  segments.clear();
  if (output_grid_.labels.empty())
    return; // no cell labels to refine
  computeImplPixelLabels();
  computeImplIndices(segments);
}

template <typename PointT>
void
RigidMotionSegmentation<PointT>::resegment(std::vector<pcl::PointIndices>& segments)
{
  segments.clear();
  if (output_grid_.labels.empty())
    return; // no segment() output to run again
  segment_labels_.clear();
  motions_.clear();
  tracker_ = tracker_before_;
  noise_gains_ = noise_gains_before_;
  computeImplLabels();
  computeSegments(segments);
}

template <typename PointT>
bool
RigidMotionSegmentation<PointT>::hasBackground() const
{
  const std::vector<std::uint8_t>& labels = cell_grid_.labels;
  return std::find(labels.begin(), labels.end(), LABEL_STATIC) != labels.end();
}

template <typename PointT>
void
RigidMotionSegmentation<PointT>::computeImplLabels()
{
  if (params_.tracking) {
    // Frames k-1 and k for the ambiguity test (§4.1), when the points have colour.
    FramePairColours colours;
    if constexpr (pcl::traits::has_color<PointT>::value) {
      if (previous_input_ && previous_input_->width == input_->width &&
          previous_input_->height == input_->height && !input_->empty()) {
        colours.previous = &(*previous_input_)[0].rgba;
        colours.current = &(*input_)[0].rgba;
        colours.stride = sizeof(PointT) / sizeof(float);
        colours.width = static_cast<int>(input_->width);
        colours.height = static_cast<int>(input_->height);
      }
    }
    tracker_.update(grid_, spatial_, predicted_motion_.cast<double>(), intrinsics_,
                    params_, colours);
    cell_grid_.labels = tracker_.labels();
    // [D] Objects younger than n_birth frames are not output yet: most spurious objects of
    // a real static scene last one to three frames. Nor is any object on a frame without a
    // background (no segment agrees with the prediction, §4): nothing was measured to move
    // against it. Nor is an object whose tracks the image leaves ambiguous this frame
    // (§4.1): the background's motion explains how it looks. The tracker keeps the ids for
    // the next frames, and the fits leave the held objects' cells out.
    const bool background = hasBackground();
    std::array<bool, 256> held{};
    for (std::size_t s = 0; s < tracker_.ids().size(); ++s) {
      const std::uint8_t id = tracker_.ids()[s];
      held[id] = id != LABEL_STATIC &&
                 (!background || tracker_.age(id) < params_.object_birth_frames ||
                  tracker_.ambiguous(id));
      if (held[id])
        continue;
      segment_labels_.push_back(id);
      motions_.push_back(tracker_.motions()[s].cast<float>());
    }
    output_grid_ = cell_grid_;
    for (std::uint8_t& label : output_grid_.labels)
      label = held[label] ? LABEL_STATIC : label;
  }
  else {
    // Two-frame result: segments by size, the largest taken as the background.
    cell_grid_.labels = spatial_.labels;
    segment_labels_.push_back(LABEL_STATIC);
    motions_.push_back(spatial_.motions.empty() ? predicted_motion_
                                                : spatial_.motions[0].cast<float>());
    for (int c = 2; c <= spatial_.segmentCount(); ++c) {
      segment_labels_.push_back(static_cast<std::uint8_t>(c));
      motions_.push_back(spatial_.motions[c - 1].cast<float>());
    }
    output_grid_ = cell_grid_;
  }
  updateNoiseScale();
}

template <typename PointT>
void
RigidMotionSegmentation<PointT>::segment(std::vector<pcl::PointIndices>& segments,
                                         pcl::PointCloud<pcl::Label>& labels)
{
  labels.clear();
  segment(segments);
  if (pixel_labels_.empty())
    return;
  labels.header = input_->header;
  labels.resize(input_->width, input_->height);
  labels.is_dense = true;
  for (std::size_t index = 0; index < pixel_labels_.size(); ++index)
    labels[index].label = pixel_labels_[index];
}

template <typename PointT>
void
RigidMotionSegmentation<PointT>::computeInformation()
{
  if (params_.residual_model != ResidualModel::sensor)
    return;
  for (float& gain : noise_gains_)
    gain = std::clamp(gain, params_.noise_scale_min, params_.noise_scale_max);
  grid_.setSensorNoise(params_.noise, focalLength(), noise_gains_[0], noise_gains_[1]);
}

template <typename PointT>
void
RigidMotionSegmentation<PointT>::updateNoiseScale()
{
  if (grid_.information.empty() || motions_.empty())
    return;
  // On static cells, the axial part of the transfer error over its model variance is
  // chi-square with 1 degree of freedom (median 0.455), the lateral part with 2 (median
  // 1.386), when the model's shape holds; each gain is the root of the observed median
  // over that. The cells are every valid cell within 4 th_chi2 (about 8 sigma) of the
  // background's motion, not only label 1: when noise splits the background, label 1 is
  // the part that fits best, and its residuals alone would shrink the gains frame by frame.
  constexpr float MEDIAN[2] = {0.455f, 1.386f};
  constexpr std::size_t MIN_CELLS = 30;
  const float focal = focalLength();
  const Eigen::Matrix3f R = motions_[0].topLeftCorner<3, 3>();
  const Eigen::Vector3f t = motions_[0].topRightCorner<3, 1>();
  std::array<std::vector<float>, 2> ratios;
  std::size_t measured = 0;
  for (std::size_t i = 0; i < grid_.size(); ++i) {
    measured += grid_.valid_3d[i] ? 1 : 0;
    if (grid_.valid_3d[i] && grid_.error(i, R, t) <= 4.0f * params_.inlier_chi2) {
      const Eigen::Vector3f& a = grid_.a[i];
      const Eigen::Vector3f& b = grid_.b[i];
      const Eigen::Vector3f e = R * a + t - b;
      const float axial = e.dot(b.normalized());
      const SensorNoiseModel::TransferVariance variance =
          params_.noise.transferVariance(a, b, focal);
      ratios[0].push_back(axial * axial / variance.axial);
      ratios[1].push_back((e.squaredNorm() - axial * axial) / variance.lateral);
    }
  }
  if (measured < MIN_CELLS)
    return;
  // Fewer than MIN_CELLS of the valid cells within reach: the frame lies beyond the gains (a
  // blurred frame after a repeated or a sharp one; without a background the motion is the
  // prediction the tracker keeps, and the frame's own motion lies beyond them too). Fitted on
  // the few cells within reach, the gains would stay as small and no sample would fit on the
  // next frames either: they move half way to s_max instead (docs/algorithm.md §3.0).
  const bool beyond_reach = ratios[0].size() < MIN_CELLS;
  for (int k = 0; k < 2; ++k) {
    float fitted = params_.noise_scale_max;
    if (!beyond_reach) {
      std::vector<float>& r = ratios[k];
      const auto middle = r.begin() + static_cast<std::ptrdiff_t>(r.size() / 2);
      std::nth_element(r.begin(), middle, r.end());
      fitted = std::sqrt(*middle / MEDIAN[k]);
    }
    // Geometric mean with the previous gain: the fit of one frame moves it half way.
    noise_gains_[k] = std::clamp(std::sqrt(noise_gains_[k] * fitted),
                                 params_.noise_scale_min, params_.noise_scale_max);
  }
  PCL_DEBUG("[dynvo::%s::segment] noise gains: axial %.3f, lateral %.3f (%zu cells).\n",
            getClassName().c_str(), noise_gains_[0], noise_gains_[1], ratios[0].size());
}

template <typename PointT>
float
RigidMotionSegmentation<PointT>::focalLength() const
{
  return static_cast<float>(0.5 * (intrinsics_.fx + intrinsics_.fy));
}

} // namespace dynvo
