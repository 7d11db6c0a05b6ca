// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/io/frame.h>
#include <dynvo/io/label_io.h>
#include <dynvo/io/partial_file.h>

#include "image_file.h"

#include <pcl/exceptions.h>
#include <pcl/common/io.h>
#include <pcl/io/pcd_io.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <Eigen/Geometry>

#include <cstdio>
#include <stdexcept>

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
  std::vector<std::uint8_t> png;
  try {
    if (!cv::imencode(".png", image, png))
      throw pcl::IOException(path + ": cannot encode label image");
  }
  catch (const cv::Exception& e) {
    throw pcl::IOException(path + ": cannot encode label image (" + e.err + ")");
  }
  replaceFile(path, std::string(png.begin(), png.end()));
}

LabelImage
readLabelImage(const std::string& path)
{
  const cv::Mat image = readImageFile(path, "label image", DEFAULT_MAX_FRAME_PIXELS);
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

void
writeLabelledCloud(const std::string& path,
                   const pcl::PointCloud<pcl::PointXYZRGB>& cloud,
                   const std::vector<std::uint8_t>& labels)
{
  if (labels.size() != cloud.size())
    throw std::invalid_argument("[dynvo::writeLabelledCloud] " +
                                std::to_string(labels.size()) + " labels for " +
                                std::to_string(cloud.size()) + " points");
  pcl::PointCloud<pcl::PointXYZRGBL> labelled;
  pcl::copyPointCloud(cloud, labelled);
  for (std::size_t i = 0; i < labels.size(); ++i)
    labelled[i].label = labels[i];
  PartialFile file(path);
  if (pcl::io::savePCDFileBinaryCompressed(file.partialPath(), labelled) != 0)
    throw pcl::IOException(path + ": cannot write the labelled cloud");
  file.commit();
}

} // namespace dynvo
