// SPDX-License-Identifier: BSD-3-Clause
// PNG files of the plain image types: 8-bit colour and 16-bit raw depth.
#pragma once

#include <dynvo/common/export.h>
#include <dynvo/common/image.h>
#include <dynvo/io/frame.h>

#include <cstdint>

#include <string>

namespace dynvo {

/// Reads an 8-bit colour PNG with 3 or 4 channels (alpha dropped) as R, G, B; a PNG
/// larger than max_pixels or truncated is refused before decoding.
/// \throws pcl::IOException naming the file when it is missing, corrupt or of another type
DYNVO_EXPORTS ColorImage readColorImage(
    const std::string& path, std::uint64_t max_pixels = DEFAULT_MAX_FRAME_PIXELS);

/// Reads a 16-bit single-channel depth PNG as stored (sensor units, 0 = missing), with
/// the checks of readColorImage.
/// \throws pcl::IOException naming the file when it is missing, corrupt or of another type
DYNVO_EXPORTS RawDepthImage readRawDepthImage(
    const std::string& path, std::uint64_t max_pixels = DEFAULT_MAX_FRAME_PIXELS);

/// Writes a colour image as an 8-bit 3-channel PNG (zlib level 1: fast; camera images
/// and synthetic textures compress poorly at any level). \throws pcl::IOException
DYNVO_EXPORTS void writeColorImage(const std::string& path, const ColorImage& color);

/// Writes a raw depth image as a 16-bit single-channel PNG (zlib level 1).
/// \throws pcl::IOException
DYNVO_EXPORTS void writeRawDepthImage(const std::string& path,
                                      const RawDepthImage& depth);

/** \brief Raw depth of a metric depth image: round(z * units_per_metre), saturated to
 * [0, 65535]; NaN (no measurement) becomes 0.
 * \param[in] depth metres
 * \param[in] units_per_metre raw units per metre (TUM: 5000)
 */
DYNVO_EXPORTS RawDepthImage quantizeDepth(const DepthImage& depth,
                                          double units_per_metre);

} // namespace dynvo
