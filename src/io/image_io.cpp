// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/io/image_io.h>

#include "image_file.h"

#include <pcl/exceptions.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <cmath>

namespace dynvo {

namespace {

/// zlib level 1: the images are mostly noise, so higher levels buy little.
constexpr int PNG_COMPRESSION = 1;

void
writePng(const std::string& path, const cv::Mat& image)
{
  bool written = false;
  try {
    written = cv::imwrite(path, image, {cv::IMWRITE_PNG_COMPRESSION, PNG_COMPRESSION});
  }
  catch (const cv::Exception& e) {
    throw pcl::IOException(path + ": cannot write PNG (" + e.what() + ")");
  }
  if (!written)
    throw pcl::IOException(path + ": cannot write PNG");
}

std::string
describe(const cv::Mat& image)
{
  return std::to_string(8 * image.elemSize1()) + "-bit with " +
         std::to_string(image.channels()) + " channel(s)";
}

} // namespace

ColorImage
readColorImage(const std::string& path, std::uint64_t max_pixels)
{
  const cv::Mat image = readImageFile(path, "colour image", max_pixels);
  if (image.depth() != CV_8U || (image.channels() != 3 && image.channels() != 4))
    throw pcl::IOException(path +
                           ": colour image must be 8-bit with 3 or 4 channels, got " +
                           describe(image));
  ColorImage color;
  color.width = image.cols;
  color.height = image.rows;
  color.data.resize(3 * image.total());
  const int channels = image.channels();
  for (int v = 0; v < image.rows; ++v) {
    const std::uint8_t* row = image.ptr<std::uint8_t>(v);
    std::uint8_t* out =
        color.data.data() + 3 * static_cast<std::size_t>(v) * image.cols;
    for (int u = 0; u < image.cols; ++u) {
      // OpenCV stores BGR(A).
      out[3 * u] = row[channels * u + 2];
      out[3 * u + 1] = row[channels * u + 1];
      out[3 * u + 2] = row[channels * u];
    }
  }
  return color;
}

RawDepthImage
readRawDepthImage(const std::string& path, std::uint64_t max_pixels)
{
  const cv::Mat image = readImageFile(path, "depth image", max_pixels);
  if (image.type() != CV_16UC1)
    throw pcl::IOException(path + ": depth image must be 16-bit single channel, got " +
                           describe(image));
  RawDepthImage depth;
  depth.width = image.cols;
  depth.height = image.rows;
  depth.data.resize(image.total());
  for (int v = 0; v < image.rows; ++v) {
    const std::uint16_t* row = image.ptr<std::uint16_t>(v);
    std::copy(row, row + image.cols,
              depth.data.begin() + static_cast<std::size_t>(v) * image.cols);
  }
  return depth;
}

void
writeColorImage(const std::string& path, const ColorImage& color)
{
  if (color.data.size() != 3 * static_cast<std::size_t>(color.width) * color.height)
    throw pcl::IOException(path + ": colour image data does not match its size");
  cv::Mat bgr(static_cast<int>(color.height), static_cast<int>(color.width), CV_8UC3);
  for (int v = 0; v < bgr.rows; ++v) {
    std::uint8_t* out = bgr.ptr<std::uint8_t>(v);
    const std::uint8_t* in =
        color.data.data() + 3 * static_cast<std::size_t>(v) * bgr.cols;
    for (int u = 0; u < bgr.cols; ++u)
      for (int channel = 0; channel < 3; ++channel) // OpenCV stores BGR
        out[3 * u + channel] = in[3 * u + 2 - channel];
  }
  writePng(path, bgr);
}

void
writeRawDepthImage(const std::string& path, const RawDepthImage& depth)
{
  if (depth.data.size() != static_cast<std::size_t>(depth.width) * depth.height)
    throw pcl::IOException(path + ": depth image data does not match its size");
  const cv::Mat image(static_cast<int>(depth.height), static_cast<int>(depth.width),
                      CV_16UC1, const_cast<std::uint16_t*>(depth.data.data()));
  writePng(path, image);
}

RawDepthImage
quantizeDepth(const DepthImage& depth, double units_per_metre)
{
  RawDepthImage raw{depth.width, depth.height,
                    std::vector<std::uint16_t>(depth.data.size(), 0)};
  for (std::size_t i = 0; i < depth.data.size(); ++i) {
    const float z = depth.data[i];
    raw.data[i] =
        std::isnan(z)
            ? 0
            : cv::saturate_cast<std::uint16_t>(std::round(z * units_per_metre));
  }
  return raw;
}

} // namespace dynvo
