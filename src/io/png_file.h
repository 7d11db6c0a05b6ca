// SPDX-License-Identifier: BSD-3-Clause
// PNG decoding shared by the io readers (OpenCV stays private to dynvo_io).
#pragma once

#include <opencv2/core/mat.hpp>

#include <string>

namespace dynvo::detail {

/// The image as stored (cv::IMREAD_UNCHANGED).
/// \throws pcl::IOException "<path>: cannot read <what> (missing or corrupt)"
cv::Mat readPngUnchanged(const std::string& path, const std::string& what);

} // namespace dynvo::detail
