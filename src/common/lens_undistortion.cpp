// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/common/lens_undistortion.h>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>

namespace dynvo {

struct LensUndistortion::Maps {
  cv::Mat color_xy, color_fraction; ///< bilinear, fixed point (cv::convertMaps)
  cv::Mat depth_xy;                 ///< nearest pixel
  cv::Mat label_x, label_y;         ///< undistorted position of every recorded pixel
};

namespace {

void
checkSize(const char* what,
          std::uint32_t width,
          std::uint32_t height,
          std::uint32_t expected_width,
          std::uint32_t expected_height)
{
  if (width != expected_width || height != expected_height)
    throw std::invalid_argument(std::string("[dynvo::LensUndistortion] ") + what +
                                " is " + std::to_string(width) + "x" +
                                std::to_string(height) + ", the undistortion's size " +
                                std::to_string(expected_width) + "x" +
                                std::to_string(expected_height));
}

} // namespace

LensUndistortion::LensUndistortion(const CameraIntrinsics& intrinsics,
                                   std::uint32_t width,
                                   std::uint32_t height)
    : width_(width)
    , height_(height)
{
  intrinsics.validate();
  if (width == 0 || height == 0)
    throw std::invalid_argument("[dynvo::LensUndistortion] the image size is empty");
  const cv::Matx33d K(intrinsics.fx, 0.0, intrinsics.cx, 0.0, intrinsics.fy,
                      intrinsics.cy, 0.0, 0.0, 1.0);
  const cv::Mat distortion(intrinsics.distortion.size(), 1, CV_64F,
                           const_cast<double*>(intrinsics.distortion.data()));
  const cv::Size size(static_cast<int>(width), static_cast<int>(height));
  auto maps = std::make_unique<Maps>();
  cv::Mat map_x, map_y;
  cv::initUndistortRectifyMap(K, distortion, cv::noArray(), K, size, CV_32FC1, map_x,
                              map_y);
  cv::convertMaps(map_x, map_y, maps->color_xy, maps->color_fraction, CV_16SC2, false);
  cv::Mat unused;
  cv::convertMaps(map_x, map_y, maps->depth_xy, unused, CV_16SC2, true);
  // The inverse map: where each recorded pixel lies in the undistorted image.
  cv::Mat pixels(static_cast<int>(width * height), 1, CV_32FC2);
  for (int v = 0; v < size.height; ++v)
    for (int u = 0; u < size.width; ++u)
      pixels.at<cv::Vec2f>(v * size.width + u) =
          cv::Vec2f(static_cast<float>(u), static_cast<float>(v));
  cv::Mat undistorted;
  // Iterated until the step is below 0.001 px (OpenCV's default stops after 5 steps).
  cv::undistortPoints(pixels, undistorted, K, distortion, cv::noArray(), K,
                      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS,
                                       50,
                                       1e-3 / std::max(intrinsics.fx, intrinsics.fy)));
  cv::Mat xy[2];
  cv::split(undistorted.reshape(2, size.height), xy);
  maps->label_x = xy[0];
  maps->label_y = xy[1];
  maps_ = std::move(maps);
}

LensUndistortion::~LensUndistortion() = default;

void
LensUndistortion::undistort(ColorImage& color, DepthImage& depth) const
{
  checkSize("the colour image", color.width, color.height, width_, height_);
  checkSize("the depth image", depth.width, depth.height, width_, height_);
  const int rows = static_cast<int>(height_), cols = static_cast<int>(width_);
  const cv::Mat color_in(rows, cols, CV_8UC3, color.data.data());
  cv::Mat color_out;
  cv::remap(color_in, color_out, maps_->color_xy, maps_->color_fraction,
            cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar::all(0));
  color_out.copyTo(color_in);
  const cv::Mat depth_in(rows, cols, CV_32FC1, depth.data.data());
  cv::Mat depth_out;
  cv::remap(depth_in, depth_out, maps_->depth_xy, cv::noArray(), cv::INTER_NEAREST,
            cv::BORDER_CONSTANT,
            cv::Scalar::all(std::numeric_limits<float>::quiet_NaN()));
  depth_out.copyTo(depth_in);
}

Eigen::Vector2f
LensUndistortion::undistortedPixel(std::uint32_t u, std::uint32_t v) const
{
  const int row = static_cast<int>(v), col = static_cast<int>(u);
  return {maps_->label_x.at<float>(row, col), maps_->label_y.at<float>(row, col)};
}

LabelImage
LensUndistortion::distort(const LabelImage& labels) const
{
  checkSize("the label image", labels.width, labels.height, width_, height_);
  LabelImage out{width_, height_, std::vector<std::uint8_t>(labels.data.size())};
  const int rows = static_cast<int>(height_), cols = static_cast<int>(width_);
  const cv::Mat in(rows, cols, CV_8UC1, const_cast<std::uint8_t*>(labels.data.data()));
  cv::Mat result(rows, cols, CV_8UC1, out.data.data());
  cv::remap(in, result, maps_->label_x, maps_->label_y, cv::INTER_NEAREST,
            cv::BORDER_CONSTANT, cv::Scalar::all(0));
  return out;
}

} // namespace dynvo
