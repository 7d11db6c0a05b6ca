// SPDX-License-Identifier: BSD-3-Clause
// Motion segment tracking: matching, static-background guard, dual model (docs/algorithm.md §4-§6).
#pragma once

#include <dynvo/common/camera.h>
#include <dynvo/common/export.h>
#include <dynvo/motion_segmentation/dual_label_model.h>
#include <dynvo/motion_segmentation/grid_flow_data.h>
#include <dynvo/motion_segmentation/patch_match.h>
#include <dynvo/motion_segmentation/rigid_motion_segmentation_parameters.h>
#include <dynvo/motion_segmentation/spatial_segmentation.h>

#include <Eigen/Core>

#include <cstdint>
#include <deque>
#include <vector>

namespace dynvo {

/** \brief Correlation matching of segments against one past label map (paper eqs. 3-7).
 *
 * C_ij = N_ij / sqrt(N_i N_j) for segment i of `segments` (1..g) and label j of `past`
 * (1..n_obj); id 0 never pairs.
 * \param[in] segments G per cell (0..g)
 * \param[in] past a past label map warped into the current grid (0..n_obj)
 * \param[in] segment_count g
 * \param[in] labels n_obj
 * \param[out] correlation (g + 1) x (n_obj + 1) row-major, row/column 0 unused (0)
 * \return score(k, l) = sum_i N_i max_j C_ij / sum_i N_i (0 when no cell is labelled)
 */
DYNVO_EXPORTS double correlateLabelMaps(const std::vector<std::uint8_t>& segments,
                                        const std::vector<std::uint8_t>& past,
                                        int segment_count,
                                        int labels,
                                        std::vector<double>& correlation);

/** \brief Tracker turning per-frame segments into persistent labels (docs/algorithm.md §4-§6).
 *
 * Per frame: warps the buffered label maps and the models into the current grid with the
 * scene flow, matches the segments (label 1 = static background, guarded by the
 * constant-velocity prediction), updates the dual-mode model and reads out the labels.
 * Outputs per cell: the tracked measurement Ghat (trackedLabels), the model read-out L
 * (modelLabels) and their fusion (labels): an object id from either wins, otherwise Ghat,
 * so a cell is static only when measured static and not held as an object by the model.
 */
class DYNVO_EXPORTS SegmentTracker {
public:
  /// Forgets the sequence: empty buffer, uninitialised models, no background yet.
  void reset();

  /** \brief Processes one frame.
   * \param[in] grid scene flow k-1 -> k
   * \param[in] spatial the two-frame segmentation of the frame (§3)
   * \param[in] T_pred H_pred, the constant-velocity prediction of the ego-motion T_curr_prev
   * \param[in] intrinsics current-frame intrinsics (§6 reprojection fallback)
   * \param[in] params validated parameters
   * \param[in] colours frames k-1 and k for the ambiguity test (§4.1); none: no test
   */
  void update(const GridFlowData& grid,
              const SpatialSegmentationResult& spatial,
              const Eigen::Matrix4d& T_pred,
              const CameraIntrinsics& intrinsics,
              const RigidMotionSegmentationParameters& params,
              const FramePairColours& colours = {});

  /// Ghat per cell: tracked id of the cell's segment this frame (0 = no measurement).
  const std::vector<std::uint8_t>& trackedLabels() const { return tracked_; }

  /// L per cell: the dual model's read-out (0 = unknown).
  const std::vector<std::uint8_t>& modelLabels() const { return model_.readOut(); }

  /// Fused output label per cell (see the class doc).
  const std::vector<std::uint8_t>& labels() const { return fused_; }

  /** \brief Consecutive frames in which `id` was measured (in trackedLabels()) while it
   * is younger than object_birth_frames: a frame in which only the model or the label buffer
   * holds it starts the count again; from object_birth_frames on, frames without a
   * measurement keep the count. An id that appears over cells that mostly held one object in
   * the previous frame continues that object's count (the object under a new id).
   * std::numeric_limits<int>::max() for the objects measured clearly apart from the
   * background (object_birth_ratio, clearlyApart()) and those continuing them.
   */
  int age(std::uint8_t id) const { return ages_.empty() ? 0 : ages_[id]; }

  /** True when the image leaves the tracks of object `id`'s segment this frame ambiguous
   * (findAmbiguousObjects()): the background's motion explains its appearance as well.
   */
  bool ambiguous(std::uint8_t id) const { return !ambiguous_.empty() && ambiguous_[id]; }

  /// Output ids: 1 first, then every object id present in labels(), ascending.
  const std::vector<std::uint8_t>& ids() const { return ids_; }

  /// T_curr_prev of each id in ids() (the matched segment's motion, else a fit on the cells).
  const std::vector<Eigen::Matrix4d>& motions() const { return motions_; }

  /// The dual-mode model after this frame.
  const DualLabelModel& model() const { return model_; }

private:
  /// p_i per cell with the §6 fallbacks (reprojection with H_pred, neighbour median, zero).
  void sourcePixels(const GridFlowData& grid,
                    const Eigen::Matrix4d& T_pred,
                    const CameraIntrinsics& intrinsics);

  /// Nearest-cell warp of a previous-grid map into the current grid through each cell's
  /// source pixel (sourcePixels(), computed first in update()).
  std::vector<std::uint8_t> warpNearest(const std::vector<std::uint8_t>& map,
                                        const GridFlowData& grid) const;

  /// §4: tracked id of each segment (index 1..g; 0 = none).
  std::vector<int> matchSegments(const GridFlowData& grid,
                                 const SpatialSegmentationResult& spatial,
                                 const RigidMotionSegmentationParameters& params) const;

  /// True when a buffered label map holds a label (not the first pair of a sequence).
  bool hasHistory() const;

  /// Segment (1..g) whose motion has the most valid cells within the inlier threshold.
  int widestConsensus(const GridFlowData& grid,
                      const SpatialSegmentationResult& spatial) const;

  /// §4 static-background guard on the segment ids.
  void guardBackground(const GridFlowData& grid,
                       const SpatialSegmentationResult& spatial,
                       const Eigen::Matrix4d& T_pred,
                       const RigidMotionSegmentationParameters& params,
                       std::vector<int>& ids) const;

  /** \brief [D] Sensor model: a segment whose typical cell the background's motion explains
   * (median E_i under the label-1 segment's motion <= th_chi2 / 2, 2.8 sigma) is the
   * background split by noise (near and far parts, colour and depth not taken at one
   * instant); it takes label 1. Paper model: no change.
   */
  void mergeNoiseSplits(const GridFlowData& grid,
                        const SpatialSegmentationResult& spatial,
                        const RigidMotionSegmentationParameters& params,
                        std::vector<int>& ids) const;

  /** \brief [D] The objects whose tracks the image leaves ambiguous this frame
   * (ambiguous(), docs/algorithm.md §4.1).
   *
   * Repeated texture (a keyboard's keys) lets Lucas-Kanade settle on a neighbouring copy,
   * and the cells that do so move together, far from the background's motion: a spurious
   * object. A cell's background position in frame k-1 is its own track p_i moved by the
   * pixel difference between its 3D end b_i taken back by the inverse of the label-1
   * segment `background`'s motion and a_i (both ends are at their depth instants, the
   * track at the colour instant). A cell is far when that position lies more than 2 r px
   * (ambiguity_search_radius) from p_i, and ambiguous when it is far and
   * trackIsAmbiguous(). The id of a segment at least half of whose cells are far, and at
   * least half of those ambiguous, is ambiguous: the background's motion explains its
   * cells as well as their own tracks.
   */
  void findAmbiguousObjects(const GridFlowData& grid,
                            const SpatialSegmentationResult& spatial,
                            const std::vector<int>& ids,
                            int background,
                            const CameraIntrinsics& intrinsics,
                            const FramePairColours& colours,
                            const RigidMotionSegmentationParameters& params);

  /** Marks the ids in use (used_): the static label, the ids of the buffered maps and the
   * argmax of every initialised apparent model. Candidate evidence for any other id is
   * cleared (DualLabelModel::forgetCandidates()): its object is gone.
   */
  void collectUsedIds(int labels);

  /// Smallest id in 2..n_obj neither in used_ nor in `taken`; 0 if none.
  int freeId(const std::vector<int>& taken) const;

  /** \brief [D] Undoes the merge of a tracked object into the background segment.
   *
   * The segmentation cannot separate motions closer than its inlier radius (5.5 mm), so a
   * slow object joins the background segment, and after alpha_max frames the dual model
   * makes it background: a box covering 80 % of the image then took label 1 when it sped up
   * again. Within each label-1 segment, the cells whose previous label is object m keep m
   * when their residual under the background cells' fit is at least object_separation_ratio
   * times (RMS) their residual under m's motion (its segment's, else a fit on them); cells
   * without a previous label then take whichever of these motions fits them best. An object
   * kept apart, and present since (kept apart or as its own segment), needs only
   * object_separation_hold times, so a large object turning round slowly stays an object.
   */
  void keepObjectsApart(const GridFlowData& grid,
                        const SpatialSegmentationResult& spatial,
                        const std::vector<int>& ids,
                        const RigidMotionSegmentationParameters& params);
  /// ages_ after this frame's outputs (see age()).
  void updateAges(const GridFlowData& grid,
                  const RigidMotionSegmentationParameters& params);

  /// The cells of output id `id` fit the background's motion `ratio` times worse (RMS) than
  /// the id's own motion (discounted by its fit's 6 degrees of freedom).
  bool clearlyApart(const GridFlowData& grid, std::uint8_t id, double ratio) const;

  /// Output ids and one motion per id.
  void collectOutputs(const GridFlowData& grid,
                      const SpatialSegmentationResult& spatial,
                      const std::vector<int>& segment_ids,
                      const Eigen::Matrix4d& T_pred);

  std::deque<std::vector<std::uint8_t>>
      buffer_;                          ///< Ghat of past frames, warped, newest first
  DualLabelModel model_;                ///< apparent / candidate models
  std::vector<Eigen::Vector2f> source_; ///< p_i used for compensation
  std::vector<std::uint8_t> tracked_;   ///< Ghat
  std::vector<std::uint8_t> fused_;     ///< output labels
  std::vector<std::uint8_t> previous_fused_; ///< output labels of the previous frame
  std::vector<char> separated_;   ///< per id: kept apart from the background lately
  bool labels_exhausted_ = false; ///< the running-out-of-labels warning was given
  std::vector<std::uint8_t> ids_; ///< output ids
  std::vector<Eigen::Matrix4d> motions_; ///< motion per output id
  std::vector<char> used_;               ///< ids taken at the start of the frame
  std::vector<int> ages_;                ///< per id: see age()
  std::vector<char> ambiguous_;          ///< per id: see ambiguous()
};

} // namespace dynvo
