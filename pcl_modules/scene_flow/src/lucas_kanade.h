// SPDX-License-Identifier: BSD-3-Clause
// Pyramidal Lucas-Kanade on the grid's cells (internal to the scene flow module).
#pragma once

#include <opencv2/core.hpp>

#include <cstdint>
#include <vector>

namespace dynvo::detail {

/// The settings of trackLucasKanade, in cv::calcOpticalFlowPyrLK's terms.
struct LucasKanadeSettings {
  int window = 16;                   ///< side of the square window (px, >= 3)
  int max_level = 2;                 ///< coarsest level searched (0: the finest only)
  int max_iterations = 8;            ///< iteration cap per level
  double epsilon = 0.03;             ///< an update shorter than this (px) ends a level
  double min_eigen_threshold = 1e-4; ///< a smaller window eigenvalue fails the track
  /// 256-bit kernels where the CPU has AVX2 and the window is a multiple of 16 px (the
  /// same results; false: the 128-bit kernels, which OpenCV runs)
  bool wide = true;
};

/** \brief Sparse pyramidal Lucas-Kanade with the arithmetic of OpenCV 4.6's
 * cv::calcOpticalFlowPyrLK with OPTFLOW_USE_INITIAL_FLOW: the same fixed-point
 * interpolation and the same order of every floating-point sum, so that it returns the same
 * points and status bit for bit (test_lucas_kanade checks it on real frames).
 *
 * \param[in] from_pyramid cv::buildOpticalFlowPyramid output with derivatives
 * \param[in] to_pyramid the same for the image tracked into (its derivatives are not read)
 * \param[in] from the points (finest-level px)
 * \param[in] settings window, levels and stopping rules
 * \param[in,out] to the first guesses in, the tracked points out (finest-level px)
 * \param[out] status 1 where the track succeeded
 * \throws std::invalid_argument when a pyramid has no level or to and from differ in size
 */
void trackLucasKanade(const std::vector<cv::Mat>& from_pyramid,
                      const std::vector<cv::Mat>& to_pyramid,
                      const std::vector<cv::Point2f>& from,
                      const LucasKanadeSettings& settings,
                      std::vector<cv::Point2f>& to,
                      std::vector<std::uint8_t>& status);

} // namespace dynvo::detail
