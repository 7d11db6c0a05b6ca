// SPDX-License-Identifier: BSD-3-Clause
// Point-type-independent core of GridSceneFlowEstimation (internal; keeps OpenCV private).
#pragma once

#include <dynvo/common/camera.h>
#include <dynvo/common/export.h>
#include <dynvo/common/point_types.h>
#include <dynvo/scene_flow/grid_scene_flow_parameters.h>

#include <pcl/point_cloud.h>

#include <Eigen/Core>

#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

namespace dynvo::detail {

/** \brief Frame store and grid tracker behind GridSceneFlowEstimation<PointT>.
 *
 * Holds, per frame slot, the preprocessed depth map and the grey LK pyramid (with derivatives),
 * so that the template only converts points to grey levels and depths. Not thread-safe.
 */
class DYNVO_EXPORTS GridFlowEngine {
public:
  /// When a frame's colour and depth images were taken (seconds; NaN: unknown, no offset).
  struct FrameStamps {
    double colour = std::numeric_limits<double>::quiet_NaN();
    double depth = std::numeric_limits<double>::quiet_NaN();
  };

  /// Which of the two stored frames an operation addresses.
  enum class Slot { current, previous };

  GridFlowEngine();
  ~GridFlowEngine();
  GridFlowEngine(const GridFlowEngine&) = delete;
  GridFlowEngine& operator=(const GridFlowEngine&) = delete;

  /** \brief Preprocess a frame's depth and build its pyramid into a slot.
   * \param[in] grey width * height grey levels, row-major
   * \param[in] depth width * height depths (metres, NaN = none), row-major
   * \param[in] width columns (px)
   * \param[in] height rows (px)
   * \param[in] params validated parameters (depth rules, LK window and levels)
   * \param[in] threads worker threads (>= 1)
   * \param[in] stamps when the colour and the depth image were taken (seconds; NaN: unknown)
   */
  void prepare(Slot slot,
               const std::vector<std::uint8_t>& grey,
               const std::vector<float>& depth,
               std::uint32_t width,
               std::uint32_t height,
               const GridSceneFlowParameters& params,
               unsigned threads,
               const FrameStamps& stamps);

  /// The current slot becomes the previous one (no copy); the current slot is then stale.
  void shiftCurrentToPrevious();

  /// The prepared current slot is also kept as the keyframe (shared, no copy) until the
  /// next call; preparing a slot that holds the keyframe gives that slot new buffers.
  void keepCurrentAsKeyframe();

  /// Drops the keyframe.
  void clearKeyframe();

  /// A keyframe is kept.
  bool hasKeyframe() const { return keyframe_ != nullptr; }

  /** \brief Grid scene flow from the previous to the current slot (docs/algorithm.md §1.2).
   * Both slots must have been prepared with the same size and params. When the prediction
   * moves the cells farther than the pyramid reaches ((window_size / 2) * 2^max_pyramid_level
   * px, median over the cells), every cell starts at its predicted position in the previous
   * frame, the projection of T_previous_current * b_i; otherwise every cell starts where it
   * is. Before that, when the image's own shift (phase correlation of the pyramids' top
   * levels) departs from the prediction's by more than that reach, the prediction is first
   * turned by the rotation that moves its shift onto the image's. Cells without depth at
   * c_i are not tracked. The whole pyramid is searched. The current slot keeps each cell's
   * image velocity (px/s) for the depth instants of later fits; a cell without a track
   * takes its nearest tracked cell's (docs/algorithm.md §1.2).
   * \param[out] flow organized (width / cell_size) x (height / cell_size) cloud
   * \return that rotation R (T_previous_current became [R 0; 0 1] * T_previous_current);
   * identity when the prediction was kept
   */
  Eigen::Matrix3f compute(const GridSceneFlowParameters& params,
                          const CameraIntrinsics& intrinsics,
                          unsigned threads,
                          const Eigen::Matrix4f& T_previous_current,
                          pcl::PointCloud<PointFlow>& flow);

  /** \brief Grid scene flow from the keyframe to the current slot, seeded (docs/algorithm.md
   * §7.3): each selected cell with depth b_i starts at the projection of
   * T_keyframe_current * b_i in the keyframe and is tracked on pyramid levels 0..max_level
   * only; other cells are not tracked. Same output as compute(), prev_* in the keyframe's
   * camera frame.
   * \param[in] selected per cell, non-zero to track it; empty: every cell
   * \param[in] max_level highest pyramid level used, clamped to params.max_pyramid_level
   */
  void computeToKeyframe(const GridSceneFlowParameters& params,
                         const CameraIntrinsics& intrinsics,
                         unsigned threads,
                         const Eigen::Matrix4f& T_keyframe_current,
                         const std::vector<std::uint8_t>& selected,
                         int max_level,
                         pcl::PointCloud<PointFlow>& flow) const;

  /// Preprocessed depth (metres, NaN = invalid) of a prepared slot, row-major.
  const std::vector<float>& depth(Slot slot) const;

private:
  struct Frame;

  /** Tracks the selected cells of the current slot into reference, each from its
   * predicted position under T_reference_current, and back-projects both ends at their
   * frames' depth instants: compute() (frame_to_frame: the prediction first turned onto
   * the image's shift, the rotation returned in shift_rotation; a cell starts from itself
   * when the prediction moves the cells by no more than the pyramid reaches, median over
   * the cells; the cell's image velocity is that of this track, returned in velocity) and
   * computeToKeyframe() (the velocities kept by each frame's compute()).
   */
  void track(const Frame& reference,
             const GridSceneFlowParameters& params,
             const CameraIntrinsics& intrinsics,
             unsigned threads,
             const Eigen::Matrix4f& T_reference_current,
             const std::vector<std::uint8_t>& selected,
             int max_level,
             bool frame_to_frame,
             pcl::PointCloud<PointFlow>& flow,
             std::vector<Eigen::Vector2f>& velocity,
             Eigen::Matrix3f* shift_rotation) const;

  std::shared_ptr<Frame> current_;
  std::shared_ptr<Frame> previous_;
  std::shared_ptr<const Frame> keyframe_; ///< shares one of the slots' frames, or none
};

} // namespace dynvo::detail
