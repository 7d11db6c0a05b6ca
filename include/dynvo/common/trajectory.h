// SPDX-License-Identifier: BSD-3-Clause
// A camera trajectory as plain data: stamped camera-to-world poses.
#pragma once

#include <dynvo/common/export.h>

#include <Eigen/Geometry>

#include <optional>
#include <vector>

namespace dynvo {

/// A camera pose at a time: T_world_camera maps camera coordinates to world (metres).
struct StampedPose {
  double timestamp = 0.0;                                           ///< seconds
  Eigen::Isometry3d T_world_camera = Eigen::Isometry3d::Identity(); ///< camera-to-world
};

/// Poses in time order (strictly increasing stamps when read from a file).
using Trajectory = std::vector<StampedPose>;

/** \brief The pose a share x of the way from a to b: linear in translation, slerp in rotation.
 * x in [0, 1] interpolates; x outside it extrapolates along the same motion (x = 2 repeats
 * the step from a to b once more).
 */
DYNVO_EXPORTS Eigen::Isometry3d
blendPose(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b, double x);

/** \brief Camera-to-world at `stamp`, interpolated between the two poses around it
 * (blendPose()).
 *
 * When the stamp lies outside the trajectory, or the two poses around it are more than
 * max_gap apart, only a pose exactly at `stamp` is returned.
 * \param[in] trajectory poses by increasing stamp
 * \param[in] stamp seconds
 * \param[in] max_gap longest gap interpolated across (seconds)
 * \return std::nullopt when there is no pose to give
 */
DYNVO_EXPORTS std::optional<Eigen::Isometry3d>
interpolatePose(const Trajectory& trajectory, double stamp, double max_gap);

} // namespace dynvo
