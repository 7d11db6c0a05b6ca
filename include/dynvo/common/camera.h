// SPDX-License-Identifier: BSD-3-Clause
// Camera intrinsics (pinhole and lens distortion) with the presets of the TUM RGB-D and
// ICSL-DE datasets.
#pragma once

#include <dynvo/common/export.h>

#include <Eigen/Core>

#include <array>
#include <string>
#include <vector>

namespace dynvo {

/** \brief Pinhole intrinsics (pixels) and the lens distortion of the images they describe.
 *
 * Back-projection of pixel (u, v) at depth z (metres) is
 * x = [(u - cx) z / fx, (v - cy) z / fy, z], in the OpenCV optical frame. It holds for
 * undistorted images: a reader undistorts the images of a camera with distortion
 * (LensUndistortion, docs/algorithm.md §0) before anything else sees them.
 */
struct DYNVO_EXPORTS CameraIntrinsics {
  double fx = 525.0; ///< focal length along x (px)
  double fy = 525.0; ///< focal length along y (px)
  double cx = 319.5; ///< principal point x (px)
  double cy = 239.5; ///< principal point y (px)
  /// Brown-Conrady lens distortion k1, k2, p1, p2, k3 (OpenCV's order); zeros: none
  std::array<double, 5> distortion{};

  /** \brief Intrinsics of a named preset.
   * \param[in] name one of presetNames(): "default" (525, 525, 319.5, 239.5),
   *            "fr1", "fr2", "fr3" (TUM RGB-D calibrations, fr1 and fr2 with their lens
   *            distortion), "icsl" (ICSL-DE Xtion)
   * \throws std::invalid_argument for an unknown name
   */
  static CameraIntrinsics fromPreset(const std::string& name);

  /// Names accepted by fromPreset(), in a fixed order.
  static std::vector<std::string> presetNames();

  /// Throws std::invalid_argument unless fx, fy > 0 and all values are finite.
  void validate() const;

  /// Whether any distortion coefficient is non-zero.
  bool distorted() const;

  /// 3D point (metres) seen at pixel (u, v) with depth z (metres).
  Eigen::Vector3f backproject(float u, float v, float z) const
  {
    return {static_cast<float>((u - cx) * z / fx),
            static_cast<float>((v - cy) * z / fy), z};
  }

  /// Pixel (u, v) where point p (metres, z > 0) projects.
  Eigen::Vector2f project(const Eigen::Vector3f& p) const
  {
    return {static_cast<float>(fx * p.x() / p.z() + cx),
            static_cast<float>(fy * p.y() / p.z() + cy)};
  }
};

} // namespace dynvo
