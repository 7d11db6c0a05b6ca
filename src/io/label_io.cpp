// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/io/label_io.h>

#include "png_file.h"

#include <pcl/exceptions.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <Eigen/Geometry>

#include <cstdio>

namespace dynvo {

LabelImage
paintLabelImage(const std::vector<pcl::PointIndices>& segments,
                const std::vector<std::uint8_t>& labels,
                std::uint32_t width,
                std::uint32_t height)
{
  LabelImage image{width, height,
                   std::vector<std::uint8_t>(std::size_t{width} * height, 0)};
  for (std::size_t s = 0; s < segments.size() && s < labels.size(); ++s)
    for (const auto index : segments[s].indices)
      image.data.at(index) = labels[s];
  return image;
}

std::string
formatStamp(double timestamp)
{
  char text[64];
  std::snprintf(text, sizeof(text), "%.6f", timestamp);
  return text;
}

std::string
stampedPngName(double timestamp)
{
  return formatStamp(timestamp) + ".png";
}

void
writeLabelImage(const std::string& path, const LabelImage& labels)
{
  if (labels.data.size() != static_cast<std::size_t>(labels.width) * labels.height)
    throw pcl::IOException(path + ": label image data does not match its size");
  const cv::Mat image(static_cast<int>(labels.height), static_cast<int>(labels.width),
                      CV_8UC1, const_cast<std::uint8_t*>(labels.data.data()));
  bool written = false;
  try {
    written = cv::imwrite(path, image);
  }
  catch (const cv::Exception& e) {
    throw pcl::IOException(path + ": cannot write label image (" + e.err + ")");
  }
  if (!written)
    throw pcl::IOException(path + ": cannot write label image");
}

LabelImage
readLabelImage(const std::string& path)
{
  const cv::Mat image = detail::readPngUnchanged(path, "label image");
  if (image.type() != CV_8UC1)
    throw pcl::IOException(path + ": label image must be 8-bit single channel");
  LabelImage labels;
  labels.width = image.cols;
  labels.height = image.rows;
  labels.data.assign(image.datastart, image.dataend);
  return labels;
}

std::string
formatObjectMotionLine(double timestamp,
                       int id,
                       std::size_t pixels,
                       const Eigen::Matrix4f& T_curr_prev)
{
  const Eigen::Matrix3d R = T_curr_prev.topLeftCorner<3, 3>().cast<double>();
  Eigen::Quaterniond q(R);
  q.normalize();
  if (q.w() < 0.0)
    q.coeffs() = -q.coeffs();
  const Eigen::Vector3f t = T_curr_prev.topRightCorner<3, 1>();
  char line[256];
  std::snprintf(line, sizeof(line), "%.6f %d %zu %.6f %.6f %.6f %.9f %.9f %.9f %.9f",
                timestamp, id, pixels, t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w());
  return line;
}

} // namespace dynvo
