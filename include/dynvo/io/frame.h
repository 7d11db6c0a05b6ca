// SPDX-License-Identifier: BSD-3-Clause
// One RGB-D frame: the organized cloud and the images it was made from.
#pragma once

#include <dynvo/common/camera.h>
#include <dynvo/common/export.h>
#include <dynvo/common/image.h>

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <cstdint>
#include <string>
#include <vector>

namespace dynvo {

/** \brief One RGB-D frame as delivered by a FrameSource. */
struct Frame {
  double timestamp = 0.0; ///< seconds; the colour image's stamp
  std::string name;       ///< where the frame came from (file name), for messages
  pcl::PointCloud<pcl::PointXYZRGB>::Ptr
      cloud;        ///< organized, current camera frame (metres), NaN where no depth
  ColorImage color; ///< the colour image the cloud was made from
  DepthImage depth; ///< the depth image the cloud was made from (metres)
};

/** \brief Organized cloud from a colour and a depth image of equal size.
 * A pixel whose depth is NaN, zero or negative becomes a NaN point (its colour is kept).
 * \throws std::invalid_argument when the sizes differ
 */
DYNVO_EXPORTS pcl::PointCloud<pcl::PointXYZRGB>::Ptr
makeOrganizedCloud(const ColorImage& color,
                   const DepthImage& depth,
                   const CameraIntrinsics& intrinsics);

} // namespace dynvo
