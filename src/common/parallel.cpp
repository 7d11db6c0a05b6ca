// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/common/parallel.h>

#include <opencv2/core/utility.hpp>

#include <algorithm>

namespace dynvo {

void
forEachStripe(std::size_t n,
              unsigned threads,
              const std::function<void(std::size_t, std::size_t)>& body)
{
  const std::size_t stripes = std::min<std::size_t>(threads, n);
  if (stripes == 0)
    return;
  // One stripe goes through parallel_for_ too: OpenCV runs it on the caller's thread, and
  // the OpenCV calls body makes inside it serially (not on OpenCV's whole pool).
  cv::parallel_for_(
      cv::Range(0, static_cast<int>(stripes)),
      [&](const cv::Range& range) {
        for (int s = range.start; s < range.end; ++s) {
          const auto k = static_cast<std::size_t>(s);
          body(n * k / stripes, n * (k + 1) / stripes);
        }
      },
      static_cast<double>(stripes));
}

} // namespace dynvo
