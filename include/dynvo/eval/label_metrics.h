// SPDX-License-Identifier: BSD-3-Clause
// Segmentation scores of predicted label images against a sequence's ground-truth labels.
#pragma once

#include <dynvo/common/export.h>
#include <dynvo/common/image.h>

#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace dynvo {

/** \brief Pixel counts of one frame, taken over the pixels with valid ground-truth depth.
 *
 * Predicted labels are those of dynvo_odometry (0 none, 1 static, 2.. objects); truth
 * labels are those of dynvo_synthesize (0 static, k >= 1 moving object k). Every count is
 * of valid pixels only.
 */
struct LabelFrameCounts {
  std::size_t valid = 0;            ///< pixels with valid ground-truth depth
  std::size_t labelled = 0;         ///< predicted != 0
  std::size_t predicted_static = 0; ///< predicted 1
  std::size_t predicted_moving = 0; ///< predicted >= 2
  std::size_t truth_static = 0;     ///< truth 0
  std::size_t truth_moving = 0;     ///< truth >= 1
  std::size_t static_hits = 0;      ///< predicted 1 and truth 0
  std::size_t moving_hits = 0;      ///< predicted >= 2 and truth >= 1
  /// (truth id k, best-overlapping predicted id) for each truth object with valid pixels,
  /// by increasing k. The best id is the predicted object label (>= 2) sharing the most
  /// pixels with object k (the smaller label on a tie), or 0 when none overlaps it.
  std::vector<std::pair<std::uint8_t, std::uint8_t>> objects;

  /// Pixels predicted moving or truly moving (the IoU's union).
  std::size_t movingUnion() const
  {
    return predicted_moving + truth_moving - moving_hits;
  }
};

/// Valid-pixel mask of a depth image: 1 where the depth is finite and positive, else 0.
DYNVO_EXPORTS std::vector<std::uint8_t> validDepthMask(const DepthImage& depth);

/** \brief Counts one frame.
 * \param[in] predicted predicted labels (0 none, 1 static, 2.. objects)
 * \param[in] truth ground-truth labels (0 static, k moving object k), same size
 * \param[in] valid one entry per pixel, non-zero where the ground-truth depth is valid
 * \throws std::invalid_argument when the sizes differ
 */
DYNVO_EXPORTS LabelFrameCounts countLabelFrame(const LabelImage& predicted,
                                               const LabelImage& truth,
                                               const std::vector<std::uint8_t>& valid);

/** \brief Segmentation scores over a sequence. A score whose denominator is zero is NaN
 * (printed "nan", JSON null): it is undefined, not 0 or 1.
 */
struct SegmentationScores {
  static constexpr double UNDEFINED = std::numeric_limits<double>::quiet_NaN();

  double moving_iou = UNDEFINED;       ///< mean per-frame IoU of moving pixels
  double static_precision = UNDEFINED; ///< pooled static_hits / predicted_static
  double static_recall = UNDEFINED;    ///< pooled static_hits / truth_static
  double labelled = UNDEFINED;         ///< pooled labelled / valid
  double bg_ok = UNDEFINED;            ///< share of frames with a good background
  double id_switch_rate = UNDEFINED;   ///< id_switches / id_pairs
  double moving_share = UNDEFINED;     ///< pooled predicted_moving / labelled
  std::size_t frames = 0;              ///< frames scored
  std::size_t moving_frames = 0;       ///< frames whose truth has valid moving pixels
  std::size_t id_pairs = 0;            ///< (object, consecutive frame pair) checked
  std::size_t id_switches = 0;         ///< of those, pairs whose best id changed
};

/// bg_ok threshold: a frame's background is good when at least this share of its
/// predicted-static pixels is truly static.
constexpr double BACKGROUND_OK_PRECISION = 0.95;

/** \brief Scores of a sequence from its frames' counts, given in time order.
 *
 * - moving_iou: for each frame with truth_moving > 0, moving_hits / movingUnion()
 *   (IoU of "predicted >= 2" against "truth >= 1"), averaged over those frames.
 * - static_precision, static_recall, labelled, moving_share: the counts summed over all
 *   frames first (pooled over all pixels of all frames), then divided.
 * - bg_ok: the share of all frames with predicted_static > 0 and
 *   static_hits >= background_precision * predicted_static; a frame without predicted-static
 *   pixels has no background and is not ok.
 * - id_switch_rate: for each pair of consecutive frames (f-1, f) and each truth object k
 *   present in both with a non-zero best-overlapping predicted id in both, one pair; it is
 *   a switch when the two ids differ. The rate is switches / pairs. A frame in which the
 *   object has no overlapping prediction ends the chain (a miss is scored by moving_iou,
 *   not as a switch).
 * \param[in] frames per-frame counts in time order
 * \param[in] background_precision bg_ok threshold, default BACKGROUND_OK_PRECISION
 */
DYNVO_EXPORTS SegmentationScores
summarizeSegmentation(const std::vector<LabelFrameCounts>& frames,
                      double background_precision = BACKGROUND_OK_PRECISION);

/// Options of app::evaluateSegmentation() (the folder reader, include/dynvo/app).
struct SegmentationEvaluationOptions {
  double max_difference = 0.005; ///< stamp pairing tolerance (seconds)
  double background_precision = BACKGROUND_OK_PRECISION; ///< bg_ok threshold
};

/// Scores of a predicted label folder against a sequence folder
/// (app::evaluateSegmentation()).
struct SegmentationEvaluation {
  SegmentationScores scores;       ///< over the paired frames
  bool has_truth_labels = true;    ///< false: no labels/ folder, every pixel is static
  std::size_t sequence_frames = 0; ///< colour frames of the sequence with a depth image
  std::size_t predictions = 0;     ///< predicted label PNGs in the folder
};

/** \brief The result line of dynvo_evaluate -labels, values with 6 decimals ("nan" when
 * undefined), no trailing newline. With truth labels:
 * "moving_iou=<x> static_precision=<x> static_recall=<x> labelled=<x> bg_ok=<x>
 * id_switch_rate=<x> frames=<n>"; without: "moving_share=<x> labelled=<x> frames=<n>".
 * With json, the same fields as one JSON object (undefined values are null).
 */
DYNVO_EXPORTS std::string formatSegmentationScores(const SegmentationEvaluation& result,
                                                   bool json = false);

} // namespace dynvo
