// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/io/frame.h>

#include <pcl/exceptions.h>

#include <cmath>
#include <limits>
#include <stdexcept>

namespace dynvo {

void
checkFrameSize(const std::string& name,
               std::uint32_t width,
               std::uint32_t height,
               std::uint64_t max_pixels)
{
  if (std::uint64_t{width} * height > max_pixels)
    throw pcl::IOException(
        name + ": frame of " + std::to_string(width) + "x" + std::to_string(height) +
        " px is over the frame-size limit of " + std::to_string(max_pixels) +
        " px (-max_frame_pixels raises it)");
}

pcl::PointCloud<pcl::PointXYZRGB>::Ptr
makeOrganizedCloud(const ColorImage& color,
                   const DepthImage& depth,
                   const CameraIntrinsics& intrinsics)
{
  if (color.width != depth.width || color.height != depth.height)
    throw std::invalid_argument(
        "[dynvo::makeOrganizedCloud] colour image is " + std::to_string(color.width) +
        "x" + std::to_string(color.height) + " but depth image is " +
        std::to_string(depth.width) + "x" + std::to_string(depth.height));
  auto cloud =
      pcl::make_shared<pcl::PointCloud<pcl::PointXYZRGB>>(color.width, color.height);
  cloud->is_dense = false;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (std::uint32_t v = 0; v < color.height; ++v) {
    for (std::uint32_t u = 0; u < color.width; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * color.width + u;
      pcl::PointXYZRGB& p = (*cloud)[i];
      p.r = color.data[3 * i];
      p.g = color.data[3 * i + 1];
      p.b = color.data[3 * i + 2];
      const float z = depth.data[i];
      if (std::isfinite(z) && z > 0.0f)
        p.getVector3fMap() =
            intrinsics.backproject(static_cast<float>(u), static_cast<float>(v), z);
      else
        p.x = p.y = p.z = nan;
    }
  }
  return cloud;
}

} // namespace dynvo
