// SPDX-License-Identifier: BSD-3-Clause
// Contiguous stripes of work on an explicit number of threads (OpenCV's pool, kept private).
#pragma once

#include <dynvo/common/export.h>

#include <cstddef>
#include <functional>

namespace dynvo {

/** \brief Runs body(begin, end) on the items [0, n) cut into k = min(threads, n) contiguous
 * stripes, stripe s being [n s / k, n (s + 1) / k), each on its own thread (k == 1: on the
 * caller's thread). With n == threads every stripe holds one item, and begin is the
 * stripe's index: the form for work a stripe chooses by its index (one task per stripe, or
 * items dealt to the stripes in turn).
 *
 * cv::setNumThreads() is process-wide, so the thread count is passed here instead. The
 * stripes go through cv::parallel_for_ (a single one too), which runs any parallel_for_
 * nested inside a running one serially (OpenCV 4.x, core/src/parallel.cpp): OpenCV calls
 * made by body (LK, pyramids) stay on the stripe's own thread, and one thread is one thread.
 * Side effect: while the stripes run, OpenCV calls from other threads of the process run
 * serially too. Whatever the count, body sees the same items: work whose items are
 * independent gives the same result for any thread count.
 */
DYNVO_EXPORTS void
forEachStripe(std::size_t n,
              unsigned threads,
              const std::function<void(std::size_t, std::size_t)>& body);

} // namespace dynvo
