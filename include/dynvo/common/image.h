// SPDX-License-Identifier: BSD-3-Clause
// Plain image types shared by every library: colour, depth (metres and raw), labels.
#pragma once

#include <cstdint>
#include <vector>

namespace dynvo {

/// Grey level of a colour: ITU-R BT.601 luma in 14-bit fixed point, the weights and
/// rounding of cv::cvtColor(RGB2GRAY). Every grey image of the project (scene flow, the
/// cv_rgbd backend, the pixel refinement) is made with it.
inline std::uint8_t
luma(std::uint8_t r, std::uint8_t g, std::uint8_t b)
{
  return static_cast<std::uint8_t>((4899u * r + 9617u * g + 1868u * b + 8192u) >> 14);
}

/// luma() of a PCL packed rgba word (b in the low byte, then g, r).
inline std::uint8_t
lumaOfPacked(std::uint32_t rgba)
{
  return luma(static_cast<std::uint8_t>(rgba >> 16 & 0xffu),
              static_cast<std::uint8_t>(rgba >> 8 & 0xffu),
              static_cast<std::uint8_t>(rgba & 0xffu));
}

/// 8-bit colour image, row-major, 3 bytes per pixel in R, G, B order.
struct ColorImage {
  std::uint32_t width = 0;        ///< columns (px)
  std::uint32_t height = 0;       ///< rows (px)
  std::vector<std::uint8_t> data; ///< width * height * 3 bytes
};

/// Depth image in metres, row-major; NaN marks a missing measurement.
struct DepthImage {
  std::uint32_t width = 0;  ///< columns (px)
  std::uint32_t height = 0; ///< rows (px)
  std::vector<float> data;  ///< width * height depths (metres)
};

/// Depth image in sensor units (as stored in a 16-bit PNG), row-major; 0 = missing.
/// The units per metre are not part of the image (TUM: 5000, ICSL-DE: 1000).
struct RawDepthImage {
  std::uint32_t width = 0;         ///< columns (px)
  std::uint32_t height = 0;        ///< rows (px)
  std::vector<std::uint16_t> data; ///< width * height raw depths
};

/// Per-pixel labels of one frame, row-major. Predicted labels: 0 no measurement,
/// 1 static background, 2.. moving objects; ground-truth labels: 0 static, k object k.
struct LabelImage {
  std::uint32_t width = 0;        ///< columns (px)
  std::uint32_t height = 0;       ///< rows (px)
  std::vector<std::uint8_t> data; ///< width * height labels
};

} // namespace dynvo
