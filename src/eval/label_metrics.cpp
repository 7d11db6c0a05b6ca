// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/eval/label_metrics.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace dynvo {

namespace {

constexpr std::size_t LABELS = 256;

double
ratio(std::size_t numerator, std::size_t denominator)
{
  return denominator == 0 ? SegmentationScores::UNDEFINED
                          : static_cast<double>(numerator) / denominator;
}

/// "0.123456" with 6 decimals, or the undefined marker ("nan", JSON "null").
std::string
formatValue(double value, bool json)
{
  if (std::isnan(value))
    return json ? "null" : "nan";
  char text[64];
  std::snprintf(text, sizeof(text), "%.6f", value);
  return text;
}

} // namespace

std::vector<std::uint8_t>
validDepthMask(const DepthImage& depth)
{
  std::vector<std::uint8_t> valid(depth.data.size());
  std::transform(depth.data.begin(), depth.data.end(), valid.begin(), [](float z) {
    return std::isfinite(z) && z > 0.0f ? 1 : 0;
  });
  return valid;
}

LabelFrameCounts
countLabelFrame(const LabelImage& predicted,
                const LabelImage& truth,
                const std::vector<std::uint8_t>& valid)
{
  const std::size_t pixels = predicted.data.size();
  if (predicted.width != truth.width || predicted.height != truth.height ||
      pixels != std::size_t{predicted.width} * predicted.height ||
      truth.data.size() != pixels || valid.size() != pixels)
    throw std::invalid_argument("[dynvo::countLabelFrame] predicted labels, truth "
                                "labels and valid mask must have the same size");
  // joint[truth * LABELS + predicted]: valid pixels with that pair of labels.
  std::vector<std::size_t> joint(LABELS * LABELS, 0);
  for (std::size_t i = 0; i < pixels; ++i)
    if (valid[i])
      ++joint[truth.data[i] * LABELS + predicted.data[i]];

  LabelFrameCounts counts;
  for (std::size_t t = 0; t < LABELS; ++t) {
    const std::size_t* row = joint.data() + t * LABELS;
    std::size_t in_row = 0, best_pixels = 0;
    std::uint8_t best_id = 0;
    for (std::size_t p = 0; p < LABELS; ++p) {
      const std::size_t n = row[p];
      in_row += n;
      if (p != 0)
        counts.labelled += n;
      if (p == 1)
        counts.predicted_static += n;
      if (p >= 2) {
        counts.predicted_moving += n;
        if (t >= 1)
          counts.moving_hits += n;
        if (n > best_pixels) {
          best_pixels = n;
          best_id = static_cast<std::uint8_t>(p);
        }
      }
    }
    counts.valid += in_row;
    if (t == 0) {
      counts.truth_static = in_row;
      counts.static_hits = row[1];
    }
    else if (in_row > 0) {
      counts.truth_moving += in_row;
      counts.objects.emplace_back(static_cast<std::uint8_t>(t), best_id);
    }
  }
  return counts;
}

SegmentationScores
summarizeSegmentation(const std::vector<LabelFrameCounts>& frames,
                      double background_precision)
{
  if (!(background_precision >= 0.0 && background_precision <= 1.0))
    throw std::invalid_argument("[dynvo::summarizeSegmentation] background precision "
                                "must be in [0, 1], got " +
                                std::to_string(background_precision));
  LabelFrameCounts total;
  SegmentationScores scores;
  scores.frames = frames.size();
  double iou_sum = 0.0;
  std::size_t background_ok = 0;
  for (std::size_t f = 0; f < frames.size(); ++f) {
    const LabelFrameCounts& frame = frames[f];
    total.valid += frame.valid;
    total.labelled += frame.labelled;
    total.predicted_static += frame.predicted_static;
    total.predicted_moving += frame.predicted_moving;
    total.truth_static += frame.truth_static;
    total.static_hits += frame.static_hits;
    if (frame.truth_moving > 0) {
      ++scores.moving_frames;
      iou_sum += static_cast<double>(frame.moving_hits) / frame.movingUnion();
    }
    if (frame.predicted_static > 0 &&
        frame.static_hits >= background_precision * frame.predicted_static)
      ++background_ok;
    if (f == 0)
      continue;
    for (const auto& [id, best] : frame.objects) {
      const auto& before = frames[f - 1].objects;
      const auto previous =
          std::find_if(before.begin(), before.end(), [id = id](const auto& object) {
            return object.first == id;
          });
      if (best == 0 || previous == before.end() || previous->second == 0)
        continue;
      ++scores.id_pairs;
      if (previous->second != best)
        ++scores.id_switches;
    }
  }
  if (scores.moving_frames > 0)
    scores.moving_iou = iou_sum / scores.moving_frames;
  scores.static_precision = ratio(total.static_hits, total.predicted_static);
  scores.static_recall = ratio(total.static_hits, total.truth_static);
  scores.labelled = ratio(total.labelled, total.valid);
  scores.bg_ok = ratio(background_ok, frames.size());
  scores.id_switch_rate = ratio(scores.id_switches, scores.id_pairs);
  scores.moving_share = ratio(total.predicted_moving, total.labelled);
  return scores;
}

std::string
formatSegmentationScores(const SegmentationEvaluation& result, bool json)
{
  const SegmentationScores& s = result.scores;
  std::vector<std::pair<const char*, std::string>> fields;
  if (result.has_truth_labels)
    fields = {{"moving_iou", formatValue(s.moving_iou, json)},
              {"static_precision", formatValue(s.static_precision, json)},
              {"static_recall", formatValue(s.static_recall, json)},
              {"labelled", formatValue(s.labelled, json)},
              {"bg_ok", formatValue(s.bg_ok, json)},
              {"id_switch_rate", formatValue(s.id_switch_rate, json)}};
  else
    fields = {{"moving_share", formatValue(s.moving_share, json)},
              {"labelled", formatValue(s.labelled, json)}};
  fields.emplace_back("frames", std::to_string(s.frames));
  std::string line = json ? "{" : "";
  for (std::size_t k = 0; k < fields.size(); ++k) {
    if (k > 0)
      line += json ? ", " : " ";
    line += json ? "\"" + std::string(fields[k].first) + "\": " + fields[k].second
                 : std::string(fields[k].first) + "=" + fields[k].second;
  }
  return json ? line + "}" : line;
}

} // namespace dynvo
