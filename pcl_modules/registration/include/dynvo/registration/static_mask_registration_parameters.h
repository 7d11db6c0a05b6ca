// SPDX-License-Identifier: BSD-3-Clause
// The ego-motion backend and its knobs (docs/algorithm.md §7, the paper's Table III).
#pragma once

#include <dynvo/common/export.h>
#include <dynvo/common/parameter_table.h>

namespace dynvo {

/// The method estimating the ego-motion on the static mask (StaticMaskRegistration).
enum class RegistrationBackend {
  flow,    ///< the trimmed flow-correspondence fit is the result (the paper's method)
  cv_rgbd, ///< OpenCV's dense RGB-D odometry (cv::rgbd::RgbdOdometry) on the static pixels
  icp,     ///< pcl::IterativeClosestPoint (point-to-point) on the static points
  gicp, ///< pcl::GeneralizedIterativeClosestPoint (plane-to-plane) on the static points
  direct ///< direct photometric alignment on the static pixels (and the keyframe fit)
};

/** \brief Parameters of StaticMaskRegistration (the single source of the defaults).
 *
 * Every backend but flow starts from the flow estimate; the icp_* fields matter for icp and
 * gicp, the rgbd_* fields for cv_rgbd and direct.
 */
struct DYNVO_EXPORTS StaticMaskRegistrationParameters {
  RegistrationBackend backend = RegistrationBackend::flow; ///< the method
  double icp_max_correspondence_distance =
      0.05; ///< (metres, > 0): ICP/GICP pairs farther apart are ignored
  int icp_max_iterations = 30; ///< (>= 1): ICP/GICP iteration cap
  double icp_transformation_epsilon =
      1e-8; ///< (m^2, >= 0): ICP/GICP stop when the squared translation step is smaller
  int icp_stride =
      4; ///< (px, >= 1): ICP/GICP use every stride-th row and column of both masks (19,200 points at VGA)
  float rgbd_max_depth_difference =
      0.07f; ///< (metres, > 0): cv_rgbd and direct drop pixel pairs whose depths differ more (OpenCV's default)
  float rgbd_max_depth =
      4.0f; ///< (metres, > 0): cv_rgbd and direct ignore farther pixels (OpenCV's default)

  /// Names, units and ranges of the fields above, in file order (ParameterTable).
  static const ParameterTable<StaticMaskRegistrationParameters>& table();

  /// \throws std::invalid_argument naming the first field out of the range stated above
  void validate() const;
};

} // namespace dynvo
