// SPDX-License-Identifier: BSD-3-Clause
// OpenCV's dense RGB-D odometry on plain buffers, compiled once in src/rgbd_odometry.cpp so
// that OpenCV stays a private dependency of the module (docs/style.md §2.9).
#pragma once

#include <dynvo/common/camera.h>
#include <dynvo/common/export.h>
#include <dynvo/registration/static_mask_registration_parameters.h>

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
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
