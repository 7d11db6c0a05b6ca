// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/app/reference_odometry.h>
#include <dynvo/app/run_report.h>
#include <dynvo/registration/rgbd_odometry.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <sstream>

namespace dynvo::app {

namespace {

using Clock = std::chrono::steady_clock;

/// The one method -bench_reference accepts, and the name its lines carry.
const char* const METHOD = "cv_rgbd";

/// 255 where the image has depth, 0 elsewhere: OpenCV's whole image, nothing masked out.
void
maskEveryPixelWithDepth(detail::RgbdImage& image)
{
  image.mask.resize(image.depth.size());
  std::transform(image.depth.begin(), image.depth.end(), image.mask.begin(),
                 [](float z) -> std::uint8_t {
                   return std::isfinite(z) ? 255 : 0;
                 });
}

} // namespace

ReferenceOdometry::ReferenceOdometry(const CameraIntrinsics& intrinsics,
                                     const StaticMaskRegistrationParameters& parameters)
    : intrinsics_(intrinsics)
    , parameters_(parameters)
{
  parameters_.validate();
}

ReferenceOdometry::~ReferenceOdometry() = default;

void
ReferenceOdometry::add(const Frame& frame)
{
  const auto start = Clock::now();
  const bool first = trajectory_.empty();
  const auto& cloud = frame.cloud;
  const bool usable = cloud && cloud->isOrganized() && !cloud->empty() &&
                      (!previous_ || (previous_->width == cloud->width &&
                                      previous_->height == cloud->height));
  bool registered = false;
  if (usable) {
    auto current = std::make_unique<detail::RgbdImage>(detail::rgbdImageOf(*cloud, {}));
    maskEveryPixelWithDepth(*current);
    Eigen::Matrix4f T_prev_curr = Eigen::Matrix4f::Identity();
    if (previous_ &&
        detail::estimateRgbdOdometry(*current, *previous_, intrinsics_, parameters_,
                                     T_prev_curr_.cast<float>(), T_prev_curr)) {
      T_prev_curr_ = T_prev_curr.cast<double>();
      registered = true;
    }
    previous_ = std::move(current);
  }
  // Lost: T_prev_curr_ stays the previous motion, the constant-velocity prediction.
  if (!first) {
    times_ms_.push_back(
        std::chrono::duration<double, std::milli>(Clock::now() - start).count());
    lost_ += registered ? 0 : 1;
    T_world_curr_ = T_world_curr_ * T_prev_curr_;
  }
  StampedPose pose;
  pose.timestamp = frame.timestamp;
  pose.T_world_camera = Eigen::Isometry3d(T_world_curr_);
  trajectory_.push_back(pose);
}

double
ReferenceOdometry::medianMs() const
{
  return median(times_ms_);
}

std::string
ReferenceOdometry::summary(double pipeline_median_ms) const
{
  const double reference_median_ms = medianMs();
  const double ratio = reference_median_ms > 0.0 && pipeline_median_ms > 0.0
                           ? pipeline_median_ms / reference_median_ms
                           : std::numeric_limits<double>::quiet_NaN();
  char line[256];
  std::snprintf(line, sizeof(line),
                "reference=%s frames=%zu lost=%zu median_ms=%.2f speed_ratio=%.3f",
                METHOD, frames(), lost(), reference_median_ms, ratio);
  return line;
}

std::string
ReferenceOdometry::accuracy(const Trajectory& groundtruth) const
{
  const std::string line = RunReport::accuracy(groundtruth, trajectory_);
  if (line.rfind("rpe_trans_rmse=", 0) != 0)
    return "reference " + line; // "accuracy not available: ..."
  std::istringstream words(line);
  std::string prefixed;
  for (std::string word; words >> word;)
    prefixed += (prefixed.empty() ? "reference_" : " reference_") + word;
  return prefixed;
}

void
ReferenceOdometry::printSummary(double pipeline_median_ms,
                                const Trajectory& groundtruth) const
{
  if (!groundtruth.empty())
    std::printf("%s\n", accuracy(groundtruth).c_str());
  std::printf("%s\n", summary(pipeline_median_ms).c_str());
}

Option
referenceOdometryOption()
{
  return {"bench_reference", METHOD,
          "after the run, print the figures of OpenCV's RGB-D odometry frame to frame "
          "over the whole image on the same frames (reference= and reference_ lines)"};
}

std::unique_ptr<ReferenceOdometry>
referenceOdometryFromArguments(const Arguments& args,
                               const CameraIntrinsics& intrinsics)
{
  if (!args.has("bench_reference"))
    return nullptr;
  const std::string method = args.string("bench_reference");
  if (method != METHOD)
    throw UsageError(std::string("-bench_reference must be ") + METHOD + ", got '" +
                     method + "'");
  return std::make_unique<ReferenceOdometry>(intrinsics);
}

} // namespace dynvo::app
