// SPDX-License-Identifier: BSD-3-Clause
// Trajectory plots (VTK charts, off screen): estimate vs ground truth, and error over time.
#pragma once

#include <dynvo/common/export.h>
#include <dynvo/common/trajectory.h>

#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace dynvo {

/// The two world axes of a top-down trajectory plot (horizontal, vertical).
enum class PlotPlane {
  xy, ///< for a z-up world, e.g. TUM motion-capture ground truth
  xz, ///< for the camera-0 optical world of dynvo estimates (y points down)
};

/// Settings of writeTrajectoryPlot().
struct DYNVO_EXPORTS TrajectoryPlotOptions {
  PlotPlane plane = PlotPlane::xz; ///< top-down plane
  std::uint32_t width = 1280; ///< PNG columns (px); the charts share it side by side
  std::uint32_t height = 480; ///< PNG rows (px)
  double max_time_difference =
      0.02; ///< stamp association for the error curve (seconds)
  std::array<std::uint8_t, 3> estimate_color{31, 119,
                                             180}; ///< estimate curve (R, G, B)
  std::array<std::uint8_t, 3> groundtruth_color{214, 39,
                                                40}; ///< ground-truth curve (R, G, B)

  /// Throws std::invalid_argument naming the first field out of range.
  void validate() const;
};

/** \brief Writes a PNG of VTK charts: the top-down path of the estimate (and of the ground
 * truth when given) and, with ground truth, the translational error |t_est - t_gt| (metres)
 * over time since the first estimated pose (seconds), at the stamps that associate within
 * options.max_time_difference. Positions are plotted as given: express both trajectories in
 * one frame first (e.g. apply computeAte()'s T_groundtruth_estimate to the estimate).
 * \param[in] estimate estimated poses, non-empty
 * \param[in] groundtruth ground-truth poses; may be empty (then only the path chart is drawn)
 * \param[in] out_png destination file; its folder must exist
 * \param[in] options plane, size, association and colours
 * \param[in] objects (label id, object-to-world trajectory) pairs in the
 *            estimate's frame (dynvo_odometry -objects_dir): each is drawn in the path
 *            chart in its label's colour (LabelRenderer::labelColor()); may be empty
 * \return true when the PNG was written; false (with a PCL_ERROR or, without a display, a
 *         PCL_WARN) otherwise
 * \throws std::invalid_argument when options.validate() fails
 */
DYNVO_EXPORTS bool
writeTrajectoryPlot(const Trajectory& estimate,
                    const Trajectory& groundtruth,
                    const std::string& out_png,
                    const TrajectoryPlotOptions& options = {},
                    const std::vector<std::pair<int, Trajectory>>& objects = {});

} // namespace dynvo
