// SPDX-License-Identifier: BSD-3-Clause
// OpenCV's dense RGB-D odometry on plain buffers, compiled once in src/rgbd_odometry.cpp so
// that OpenCV stays a private dependency of the module (docs/style.md §2.9), and the one
// conversion of a cloud into its input (StaticMaskRegistration, the app's reference odometry).
#pragma once

#include <dynvo/common/camera.h>
#include <dynvo/common/export.h>
#include <dynvo/common/image.h>
#include <dynvo/registration/static_mask_registration_parameters.h>

#include <pcl/common/point_tests.h>
#include <pcl/point_cloud.h>

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

namespace dynvo::detail {

/// One RGB-D frame for cv::rgbd::RgbdOdometry, row-major, width x height each.
struct DYNVO_EXPORTS RgbdImage {
  std::size_t width = 0;          ///< columns (px)
  std::size_t height = 0;         ///< rows (px)
  std::vector<std::uint8_t> gray; ///< intensity 0..255
  std::vector<float> depth;       ///< z (metres), NaN where none
  std::vector<std::uint8_t> mask; ///< 255 where the pixel may be used, 0 elsewhere
};

/** \brief Gray image (ITU-R BT.601 luma, luma()), depth (z, NaN where the point is not
 * finite) and mask of an organized cloud.
 * \param[in] cloud organized frame (metres)
 * \param[in] mask one byte per point (255 = usable), moved into the result
 */
template <typename PointT>
RgbdImage
rgbdImageOf(const pcl::PointCloud<PointT>& cloud, std::vector<std::uint8_t> mask)
{
  RgbdImage image;
  image.width = cloud.width;
  image.height = cloud.height;
  image.gray.resize(cloud.size());
  image.depth.resize(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const PointT& p = cloud[i];
    image.gray[i] = luma(p.r, p.g, p.b);
    image.depth[i] =
        pcl::isXYZFinite(p) ? p.z : std::numeric_limits<float>::quiet_NaN();
  }
  image.mask = std::move(mask);
  return image;
}

/** \brief cv::rgbd::RgbdOdometry (photometric, four pyramid levels, OpenCV's iteration counts
 * and gradient thresholds) from source to target.
 * \param[in] source frame to move (frame k)
 * \param[in] target frame to align to (frame k-1), same size
 * \param[in] intrinsics pinhole model of both frames
 * \param[in] parameters rgbd_max_depth_difference and rgbd_max_depth are used
 * \param[in] guess initial T_target_source (metres)
 * \param[out] T_target_source the estimate; written only when OpenCV reports success
 * \return true when OpenCV reports success (false also for an empty mask)
 */
DYNVO_EXPORTS bool
estimateRgbdOdometry(const RgbdImage& source,
                     const RgbdImage& target,
                     const CameraIntrinsics& intrinsics,
                     const StaticMaskRegistrationParameters& parameters,
                     const Eigen::Matrix4f& guess,
                     Eigen::Matrix4f& T_target_source);

} // namespace dynvo::detail
