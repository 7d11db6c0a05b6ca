// SPDX-License-Identifier: BSD-3-Clause
// Images of a camera with lens distortion turned into images of its pinhole model, and label
// images turned back.
#pragma once

#include <dynvo/common/camera.h>
#include <dynvo/common/export.h>
#include <dynvo/common/image.h>

#include <Eigen/Core>

#include <cstdint>
#include <memory>

namespace dynvo {

/** \brief Undistorts the colour and depth images of one camera and image size
 * (docs/algorithm.md §0).
 *
 * The undistorted image has the camera's own fx, fy, cx, cy and no distortion, so every
 * later stage may back-project with CameraIntrinsics::backproject(). Colour is interpolated
 * bilinearly; depth takes the nearest pixel, so no depth is mixed across an edge. A pixel
 * that sees nothing of the distorted image (a frame of 6-27 px around a fr1 image) is black
 * with no depth. distort() takes a label
 * image of the undistorted geometry back to the recording's pixels, so masks lie on the
 * images the user has.
 */
class DYNVO_EXPORTS LensUndistortion {
public:
  /// \throws std::invalid_argument for invalid intrinsics or an empty size
  LensUndistortion(const CameraIntrinsics& intrinsics,
                   std::uint32_t width,
                   std::uint32_t height);
  ~LensUndistortion();
  LensUndistortion(const LensUndistortion&) = delete;
  LensUndistortion& operator=(const LensUndistortion&) = delete;

  std::uint32_t width() const { return width_; }
  std::uint32_t height() const { return height_; }

  /// Both images undistorted in place. \throws std::invalid_argument unless both have
  /// this size
  void undistort(ColorImage& color, DepthImage& depth) const;

  /// Where the recording's pixel (u, v) (u < width(), v < height()) lies in the
  /// undistorted image (px).
  Eigen::Vector2f undistortedPixel(std::uint32_t u, std::uint32_t v) const;

  /// Labels of the undistorted geometry at the recording's pixels (nearest; 0 where a
  /// pixel falls outside). \throws std::invalid_argument unless labels has this size
  LabelImage distort(const LabelImage& labels) const;

private:
  struct Maps;
  std::uint32_t width_, height_;
  std::unique_ptr<const Maps> maps_;
};

} // namespace dynvo
