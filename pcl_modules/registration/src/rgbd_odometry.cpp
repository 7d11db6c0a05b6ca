// SPDX-License-Identifier: BSD-3-Clause
// The only translation unit that includes OpenCV's rgbd module.
#include <dynvo/registration/rgbd_odometry.h>

#include <opencv2/core.hpp>
#include <opencv2/rgbd/depth.hpp>

namespace dynvo::detail {

namespace {

/// Views a buffer of the image as a cv::Mat (no copy; OpenCV only reads it).
template <typename T>
cv::Mat
view(const RgbdImage& image, const std::vector<T>& buffer, int type)
{
  return cv::Mat(static_cast<int>(image.height), static_cast<int>(image.width), type,
                 const_cast<T*>(buffer.data()));
}

bool
isUsable(const RgbdImage& image)
{
  const std::size_t n = image.width * image.height;
  return n > 0 && image.gray.size() == n && image.depth.size() == n &&
         image.mask.size() == n &&
         cv::countNonZero(view(image, image.mask, CV_8UC1)) > 0;
}

} // namespace

bool
estimateRgbdOdometry(const RgbdImage& source,
                     const RgbdImage& target,
                     const CameraIntrinsics& intrinsics,
                     const StaticMaskRegistrationParameters& parameters,
                     const Eigen::Matrix4f& guess,
                     Eigen::Matrix4f& T_target_source)
{
  if (!isUsable(source) || !isUsable(target) || source.width != target.width ||
      source.height != target.height)
    return false;
  const cv::Mat camera = (cv::Mat_<double>(3, 3) << intrinsics.fx, 0.0, intrinsics.cx,
                          0.0, intrinsics.fy, intrinsics.cy, 0.0, 0.0, 1.0);
  // Every textured pixel of the mask (max points part 1): OpenCV's default keeps a random 7 %,
  // too few at 160x120 once the mask has removed the moving objects.
  const cv::rgbd::RgbdOdometry odometry(camera, cv::rgbd::Odometry::DEFAULT_MIN_DEPTH(),
                                        parameters.rgbd_max_depth,
                                        parameters.rgbd_max_depth_difference,
                                        std::vector<int>(), std::vector<float>(), 1.0f);
  cv::Mat init(4, 4, CV_64FC1);
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c)
      init.at<double>(r, c) = guess(r, c);
  cv::Mat Rt;
  const bool ok = odometry.compute(
      view(source, source.gray, CV_8UC1), view(source, source.depth, CV_32FC1),
      view(source, source.mask, CV_8UC1), view(target, target.gray, CV_8UC1),
      view(target, target.depth, CV_32FC1), view(target, target.mask, CV_8UC1), Rt,
      init);
  if (!ok || Rt.rows != 4 || Rt.cols != 4)
    return false;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c)
      T_target_source(r, c) = static_cast<float>(Rt.at<double>(r, c));
  return true;
}

} // namespace dynvo::detail
