// SPDX-License-Identifier: BSD-3-Clause
// Stripe-indexed work on an explicit thread count (private to dynvo_scene_flow).
#pragma once

#include <opencv2/core/utility.hpp>

namespace dynvo::detail {

/** \brief Runs body(s) for every stripe s in [0, stripes) on at most `stripes` threads.
 *
 * For work that a stripe chooses by its index (one task per stripe, or items dealt to the
 * stripes in turn); contiguous ranges of items take dynvo::forEachStripe()
 * (dynvo/common/parallel.h), whose rules hold here too: the stripes go through
 * cv::parallel_for_, so OpenCV calls made by body (LK, pyramids) stay on the stripe's own
 * thread, and with stripes == 1 everything runs on the caller's thread.
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

} // namespace dynvo::detail
