// SPDX-License-Identifier: BSD-3-Clause
// Explicit thread counts on top of cv::parallel_for_ (private to dynvo_scene_flow).
#pragma once

#include <opencv2/core/utility.hpp>

#include <cstddef>
#include <utility>

namespace dynvo::detail {

/** \brief Runs body(s) for every stripe s in [0, stripes) on at most `stripes` threads.
 *
 * cv::setNumThreads() is process-wide, so the thread count is passed here instead: the stripes
 * go through cv::parallel_for_, and OpenCV runs any parallel_for_ nested inside a running one
 * serially (OpenCV 4.x, core/src/parallel.cpp). OpenCV calls made by body (LK, pyramids) thus
 * stay on the stripe's own thread, and with stripes == 1 everything runs on the caller's thread.
 * Side effect: while a stripe region runs, OpenCV calls from other threads of the process run
 * serially too. The pool is OpenCV's, so fewer threads are used when cv::getNumThreads() is lower.
 */
template <typename Body>
void
runStripes(unsigned stripes, const Body& body)
{
  cv::parallel_for_(
      cv::Range(0, static_cast<int>(stripes)),
      [&body](const cv::Range& range) {
        for (int s = range.start; s < range.end; ++s)
          body(static_cast<unsigned>(s));
      },
      static_cast<double>(stripes));
}

/// Items [first, second) of stripe s when n items are cut into `stripes` contiguous parts.
inline std::pair<std::size_t, std::size_t>
stripeRange(std::size_t n, unsigned stripes, unsigned s)
{
  return {n * s / stripes, n * (s + 1) / stripes};
}

} // namespace dynvo::detail
