// SPDX-License-Identifier: BSD-3-Clause
// Image files read through OpenCV with the checks OpenCV and libpng leave out (internal).
#pragma once

#include <opencv2/core.hpp>

#include <cstdint>
#include <string>

namespace dynvo {

/** \brief Decodes an image file (cv::IMREAD_UNCHANGED).
 *
 * A PNG is checked first: its header size against the frame-size limit (before anything
 * is allocated) and its last chunk (IEND), so a truncated file is refused by name
 * instead of libpng printing its own line.
 * \param[in] path the file
 * \param[in] what e.g. "colour image", for messages
 * \param[in] max_pixels frame-size limit (see checkFrameSize())
 * \throws pcl::IOException "<path>: <problem>"
 */
cv::Mat readImageFile(const std::string& path,
                      const std::string& what,
                      std::uint64_t max_pixels);

} // namespace dynvo
