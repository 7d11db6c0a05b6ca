// SPDX-License-Identifier: BSD-3-Clause
// Template bodies of StaticMaskRegistration (compiled in src/ for XYZRGB and XYZRGBA).
#pragma once

#include <dynvo/common/conventions.h>
#include <dynvo/registration/direct_odometry.h>
#include <dynvo/registration/rgbd_odometry.h>
#include <dynvo/registration/rigid_refinement.h>
#include <dynvo/registration/static_mask_registration.h>

#include <pcl/common/point_tests.h>
#include <pcl/console/print.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace dynvo {

namespace detail {

/// Per pixel of the grid's image: 255 in the cells labelled LABEL_STATIC, else 0.
inline std::vector<std::uint8_t>
staticPixelMask(const FlowGrid& cells)
{
  std::vector<std::uint8_t> mask(
      static_cast<std::size_t>(cells.image_width) * cells.image_height, 0);
  for (std::size_t i = 0; i < cells.size(); ++i)
    if (cells.labels[i] == LABEL_STATIC)
      cells.forEachPixel(i, [&mask](std::size_t index) {
        mask[index] = 255;
      });
  return mask;
}

/// The finite masked points of a cloud on every stride-th row and column, as plain XYZ.
template <typename PointT>
pcl::PointCloud<pcl::PointXYZ>::Ptr
maskedLatticePoints(const pcl::PointCloud<PointT>& cloud,
                    const std::vector<std::uint8_t>& mask,
                    std::size_t stride)
{
  pcl::PointCloud<pcl::PointXYZ>::Ptr points(new pcl::PointCloud<pcl::PointXYZ>);
  for (std::size_t v = 0; v < cloud.height; v += stride)
    for (std::size_t u = 0; u < cloud.width; u += stride) {
      const std::size_t index = v * cloud.width + u;
      const PointT& p = cloud[index];
      if (mask[index] && pcl::isXYZFinite(p))
        points->push_back(pcl::PointXYZ(p.x, p.y, p.z));
    }
  return points;
}

} // namespace detail

template <typename PointT>
bool
StaticMaskRegistration<PointT>::covers(const FlowGrid& cells, const PointCloud& cloud)
{
  return cells.cell_size > 0 && cells.image_width == cloud.width &&
         cells.image_height == cloud.height && cells.labels.size() == cells.size();
}

template <typename PointT>
bool
StaticMaskRegistration<PointT>::validateInputs() const
{
  const auto fail = [this](const char* problem) {
    PCL_ERROR("[dynvo::%s::align] %s.\n", class_name_.c_str(), problem);
    return false;
  };
  if (!source_ || !target_)
    return fail("source and target must be set");
  if (!source_->isOrganized() || !target_->isOrganized())
    return fail("source and target must be organized clouds");
  if (source_->width != target_->width || source_->height != target_->height)
    return fail("source and target must have the same size");
  if (!covers(source_cells_, *source_) || !covers(target_cells_, *source_))
    return fail(
        "the static cells of both frames must be grids over the clouds' images");
  return true;
}

template <typename PointT>
bool
StaticMaskRegistration<PointT>::enoughPoints(std::size_t source_count,
                                             std::size_t target_count) const
{
  if (source_count >= MIN_POINTS && target_count >= MIN_POINTS)
    return true;
  PCL_DEBUG("[dynvo::%s::align] %zu source / %zu target masked points.\n",
            class_name_.c_str(), source_count, target_count);
  return false;
}

template <typename PointT>
StaticMaskRegistrationStatus
StaticMaskRegistration<PointT>::alignPoints(const Eigen::Matrix4f& guess,
                                            Eigen::Matrix4f& T_prev_curr)
{
  const auto stride = static_cast<std::size_t>(params_.icp_stride);
  const auto source = detail::maskedLatticePoints(
      *source_, detail::staticPixelMask(source_cells_), stride);
  const auto target = detail::maskedLatticePoints(
      *target_, detail::staticPixelMask(target_cells_), stride);
  if (!enoughPoints(source->size(), target->size()))
    return Status::too_few_points;
  return detail::refineRigidTransformation(source, target, params_, guess, T_prev_curr)
             ? Status::converged
             : Status::not_converged;
}

template <typename PointT>
StaticMaskRegistrationStatus
StaticMaskRegistration<PointT>::alignImages(const Eigen::Matrix4f& guess,
                                            Eigen::Matrix4f& T_prev_curr)
{
  const detail::RgbdImage source =
      detail::rgbdImageOf(*source_, detail::staticPixelMask(source_cells_));
  const detail::RgbdImage target =
      detail::rgbdImageOf(*target_, detail::staticPixelMask(target_cells_));
  const auto masked = [](const detail::RgbdImage& image) {
    return static_cast<std::size_t>(
        std::count(image.mask.begin(), image.mask.end(), std::uint8_t{255}));
  };
  if (!enoughPoints(masked(source), masked(target)))
    return Status::too_few_points;
  return detail::estimateRgbdOdometry(source, target, intrinsics_, params_, guess,
                                      T_prev_curr)
             ? Status::converged
             : Status::not_converged;
}

template <typename PointT>
const detail::DirectFrame*
StaticMaskRegistration<PointT>::builtFrameOf(const PointCloudConstPtr& cloud) const
{
  for (const DirectEntry& entry : direct_frames_)
    if (entry.cloud == cloud && entry.stamp == cloud->header.stamp)
      return entry.frame.get();
  return nullptr;
}

template <typename PointT>
detail::DirectFrame&
StaticMaskRegistration<PointT>::claimDirectFrame(const PointCloudConstPtr& cloud,
                                                 const PointCloudConstPtr& keep)
{
  DirectEntry& entry = direct_frames_[keep && direct_frames_[0].cloud == keep ? 1 : 0];
  entry.cloud = cloud;
  entry.stamp = cloud->header.stamp;
  if (!entry.frame)
    entry.frame = std::make_unique<detail::DirectFrame>();
  entry.frame->resize(static_cast<int>(cloud->width), static_cast<int>(cloud->height));
  return *entry.frame;
}

template <typename PointT>
const detail::DirectFrame&
StaticMaskRegistration<PointT>::directFrameOf(const PointCloudConstPtr& cloud,
                                              const PointCloudConstPtr& keep)
{
  if (const detail::DirectFrame* built = builtFrameOf(cloud))
    return *built;
  detail::DirectFrame& frame = claimDirectFrame(cloud, keep);
  float* grey = frame.grey();
  float* depth = frame.depth();
  for (std::size_t i = 0; i < cloud->size(); ++i) {
    const PointT& p = (*cloud)[i];
    grey[i] = luma(p.r, p.g, p.b);
    depth[i] = std::isfinite(p.z) ? p.z : std::numeric_limits<float>::quiet_NaN();
  }
  frame.buildPyramid();
  return frame;
}

template <typename PointT>
void
StaticMaskRegistration<PointT>::setInputSource(const PointCloudConstPtr& cloud,
                                               const std::vector<std::uint8_t>& grey,
                                               const std::vector<float>& depth)
{
  if (cloud && (grey.size() != cloud->size() || depth.size() != cloud->size())) {
    setInputSource(cloud);
    return;
  }
  if (cloud && params_.backend == RegistrationBackend::direct && !builtFrameOf(cloud)) {
    detail::DirectFrame& frame = claimDirectFrame(cloud, source_);
    frame.assign(grey.data(), depth.data());
    frame.buildPyramid();
  }
  source_ = cloud;
}

template <typename PointT>
void
StaticMaskRegistration<PointT>::precomputeTarget()
{
  if (params_.backend != RegistrationBackend::direct || !target_ ||
      !target_->isOrganized() || !covers(target_cells_, *target_))
    return;
  directFrameOf(target_, source_)
      .samples(target_cells_, intrinsics_, params_.rgbd_max_depth);
}

template <typename PointT>
StaticMaskRegistrationStatus
StaticMaskRegistration<PointT>::alignDirect(const Eigen::Matrix4f& guess,
                                            Eigen::Matrix4f& T_prev_curr)
{
  const auto staticPixels = [](const FlowGrid& cells) {
    return static_cast<std::size_t>(
               std::count(cells.labels.begin(), cells.labels.end(), LABEL_STATIC)) *
           cells.cell_size * cells.cell_size;
  };
  if (!enoughPoints(staticPixels(source_cells_), staticPixels(target_cells_)))
    return Status::too_few_points;
  const detail::DirectFrame& source = directFrameOf(source_, target_);
  const detail::DirectFrame& target = directFrameOf(target_, source_);
  return detail::estimateDirectOdometry(source, source_cells_, target, target_cells_,
                                        intrinsics_, params_, guess, threads_,
                                        T_prev_curr)
             ? Status::converged
             : Status::not_converged;
}

template <typename PointT>
bool
StaticMaskRegistration<PointT>::align(const Eigen::Matrix4f& guess,
                                      Eigen::Matrix4f& T_prev_curr)
{
  T_prev_curr = guess;
  if (params_.backend == RegistrationBackend::flow) {
    status_ = Status::flow;
    return true;
  }
  if (!validateInputs()) {
    status_ = Status::invalid_input;
    return false;
  }
  Eigen::Matrix4f estimate = guess;
  switch (params_.backend) {
  case RegistrationBackend::cv_rgbd:
    status_ = alignImages(guess, estimate);
    break;
  case RegistrationBackend::direct:
    status_ = alignDirect(guess, estimate);
    break;
  default:
    status_ = alignPoints(guess, estimate);
  }
  if (status_ == Status::converged)
    T_prev_curr = estimate;
  return status_ == Status::converged;
}

} // namespace dynvo
