// SPDX-License-Identifier: BSD-3-Clause
// Direct photometric alignment of two frames on their static cells (docs/algorithm.md §7.7),
// compiled once in src/direct_odometry.cpp so that OpenCV stays private (docs/style.md §2.9).
#pragma once

#include <dynvo/common/camera.h>
#include <dynvo/common/export.h>
#include <dynvo/common/flow_grid.h>
#include <dynvo/registration/static_mask_registration_parameters.h>

#include <Eigen/Core>

#include <cstdint>
#include <memory>
#include <vector>

namespace dynvo::detail {

/// One frame's grey and depth pyramids (LEVELS levels, each half the size of the one below).
class DYNVO_EXPORTS DirectFrame {
public:
  static constexpr int LEVELS = 3;

  DirectFrame();
  ~DirectFrame();

  /// Sizes the finest level for a width x height frame (buffers are reused).
  void resize(int width, int height);

  /// The finest level's grey levels and depths (metres, NaN where none), row-major, to fill
  /// after resize() and before buildPyramid().
  float* grey();
  float* depth();

  /// Fills the finest level from width x height grey levels (luma()) and depths (metres, NaN
  /// where none), row-major, after resize() and before buildPyramid().
  void assign(const std::uint8_t* grey, const float* depth);

  /// Builds the coarser levels from the finest.
  void buildPyramid();

  DirectFrame(const DirectFrame&) = delete;
  DirectFrame& operator=(const DirectFrame&) = delete;

  /// One level's images, and a target's samples per level: defined where they are used
  /// (src/direct_odometry.cpp, estimateDirectOdometry()).
  struct Level;
  struct SampleCache;

  /// Level l (0 = finest, < LEVELS).
  const Level& level(int l) const;

  /// The samples of this frame as the target of an alignment, per level: chosen once for a
  /// given mask, camera and depth limit (the step and its refit share them).
  const SampleCache& samples(const FlowGrid& cells,
                             const CameraIntrinsics& intrinsics,
                             float max_depth) const;

private:
  std::vector<Level> levels_;
  /// empty until samples(), reset by buildPyramid()
  mutable std::unique_ptr<SampleCache> samples_;
};

/** \brief The camera motion from source to target that best explains the target's textured
 * static pixels in the source image (photometric error with a brightness offset, Tukey
 * weights, inverse compositional Gauss-Newton from guess, coarse to fine; a step that raises
 * the cost ends its level).
 * \param[in] source frame k and its static cells
 * \param[in] target frame k-1 and its static cells (the pixels used are the target's)
 * \param[in] intrinsics pinhole model of both frames
 * \param[in] parameters rgbd_max_depth (farther target pixels are not used) and
 *            rgbd_max_depth_difference (a pixel whose source depth differs more is occluded)
 * \param[in] guess initial T_target_source (metres)
 * \param[in] threads worker threads of the residuals (>= 1; the same estimate for any count)
 * \param[out] T_target_source the estimate; written only on success
 * \return false when a level has fewer than 100 usable pixels or the system is singular
 */
DYNVO_EXPORTS bool
estimateDirectOdometry(const DirectFrame& source,
                       const FlowGrid& source_cells,
                       const DirectFrame& target,
                       const FlowGrid& target_cells,
                       const CameraIntrinsics& intrinsics,
                       const StaticMaskRegistrationParameters& parameters,
                       const Eigen::Matrix4f& guess,
                       unsigned threads,
                       Eigen::Matrix4f& T_target_source);

} // namespace dynvo::detail
