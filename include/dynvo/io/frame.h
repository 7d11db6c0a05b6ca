// SPDX-License-Identifier: BSD-3-Clause
// One RGB-D frame: the organized cloud and the images it was made from.
#pragma once

#include <dynvo/common/camera.h>
#include <dynvo/common/export.h>
#include <dynvo/common/image.h>

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace dynvo {

class LensUndistortion;

/** \brief One RGB-D frame as delivered by a FrameSource. */
struct Frame {
  double timestamp = 0.0; ///< seconds; the colour image's stamp
  /// seconds; the depth image's stamp (= timestamp for sources with one stamp per frame)
  double depth_timestamp = 0.0;
  std::string name; ///< where the frame came from (file name), for messages
  pcl::PointCloud<pcl::PointXYZRGB>::Ptr
      cloud;        ///< organized, current camera frame (metres), NaN where no depth
  ColorImage color; ///< the colour image the cloud was made from
  DepthImage depth; ///< the depth image the cloud was made from (metres)
  /// How color and depth were undistorted from the recording's images; null when the
  /// camera has no lens distortion (the images are the recording's)
  std::shared_ptr<const LensUndistortion> undistortion;
};

/// Default frame-size limit of the readers (pixels, 4096 x 4096): a frame costs about
/// 40 bytes per pixel through the pipeline (0.7 GB here), and a small file whose header
/// claims more is refused before anything is allocated. Apps raise it with
/// -max_frame_pixels.
constexpr std::uint64_t DEFAULT_MAX_FRAME_PIXELS = 4096ULL * 4096ULL;

/** \brief Refuses a frame larger than the limit before it is allocated.
 * \param[in] name the file, for the message
 * \param[in] width columns (px)
 * \param[in] height rows (px)
 * \param[in] max_pixels the limit (DEFAULT_MAX_FRAME_PIXELS unless raised)
 * \throws pcl::IOException "<name>: frame of WxH px is over the frame-size limit ..."
 */
DYNVO_EXPORTS void checkFrameSize(const std::string& name,
                                  std::uint32_t width,
                                  std::uint32_t height,
                                  std::uint64_t max_pixels);

/** \brief Organized cloud from a colour and a depth image of equal size.
 * A pixel whose depth is NaN, zero or negative becomes a NaN point (its colour is kept).
 * \throws std::invalid_argument when the sizes differ
 */
DYNVO_EXPORTS pcl::PointCloud<pcl::PointXYZRGB>::Ptr
makeOrganizedCloud(const ColorImage& color,
                   const DepthImage& depth,
                   const CameraIntrinsics& intrinsics);

} // namespace dynvo
