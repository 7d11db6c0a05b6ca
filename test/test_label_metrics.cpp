// SPDX-License-Identifier: BSD-3-Clause
// Segmentation scores on hand-made label images whose scores are counted by hand.
#include <dynvo/eval/label_metrics.h>

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

namespace {

using dynvo::LabelFrameCounts;
using dynvo::LabelImage;

/// A 4 x 3 label image from its 12 labels, row by row.
LabelImage
image4x3(std::vector<std::uint8_t> labels)
{
  return {4, 3, std::move(labels)};
}

const std::vector<std::uint8_t> ALL_VALID(12, 1);

/// Counts as given, for summarizeSegmentation() cases that need no image.
LabelFrameCounts
counts(std::size_t valid,
       std::size_t labelled,
       std::size_t predicted_static,
       std::size_t predicted_moving,
       std::size_t truth_static,
       std::size_t truth_moving,
       std::size_t static_hits,
       std::size_t moving_hits)
{
  LabelFrameCounts c;
  c.valid = valid;
  c.labelled = labelled;
  c.predicted_static = predicted_static;
  c.predicted_moving = predicted_moving;
  c.truth_static = truth_static;
  c.truth_moving = truth_moving;
  c.static_hits = static_hits;
  c.moving_hits = moving_hits;
  return c;
}

LabelFrameCounts
withObjects(std::vector<std::pair<std::uint8_t, std::uint8_t>> objects)
{
  LabelFrameCounts c;
  c.objects = std::move(objects);
  return c;
}

TEST(LabelMetrics, CountsOneFrameOnValidPixelsOnly)
{
  // truth      predicted   valid
  // 0 0 0 0    1 1 1 0     1 1 1 1
  // 0 0 1 1    1 2 2 1     1 1 1 1
  // 0 0 1 1    1 1 2 2     0 1 1 1
  const auto truth = image4x3({0, 0, 0, 0, 0, 0, 1, 1, 0, 0, 1, 1});
  const auto predicted = image4x3({1, 1, 1, 0, 1, 2, 2, 1, 1, 1, 2, 2});
  const std::vector<std::uint8_t> valid{1, 1, 1, 1, 1, 1, 1, 1, 0, 1, 1, 1};
  const LabelFrameCounts c = dynvo::countLabelFrame(predicted, truth, valid);
  EXPECT_EQ(c.valid, 11u);
  EXPECT_EQ(c.labelled, 10u);        // the one 0 in the top row is unlabelled
  EXPECT_EQ(c.predicted_static, 6u); // the invalid bottom-left 1 is not counted
  EXPECT_EQ(c.predicted_moving, 4u);
  EXPECT_EQ(c.truth_static, 7u);
  EXPECT_EQ(c.truth_moving, 4u);
  EXPECT_EQ(c.static_hits, 5u); // the 1 at the right of row 2 lies on the object
  EXPECT_EQ(c.moving_hits, 3u); // the 2 at column 1 of row 2 lies on the background
  EXPECT_EQ(c.movingUnion(), 5u);
  ASSERT_EQ(c.objects.size(), 1u);
  EXPECT_EQ(c.objects[0], std::make_pair(std::uint8_t{1}, std::uint8_t{2}));
}

TEST(LabelMetrics,
     BestOverlappingIdTakesTheLargerOverlapTheSmallerIdOnATieAndZeroForNone)
{
  // truth      predicted
  // 1 1 1 1    3 3 2 2     object 1: two pixels of 2 and two of 3 -> 2 (tie)
  // 2 2 2 2    4 4 4 5     object 2: three of 4, one of 5         -> 4
  // 3 3 0 0    1 0 1 1     object 3: a static and a none pixel    -> 0
  const auto truth = image4x3({1, 1, 1, 1, 2, 2, 2, 2, 3, 3, 0, 0});
  const auto predicted = image4x3({3, 3, 2, 2, 4, 4, 4, 5, 1, 0, 1, 1});
  const LabelFrameCounts c = dynvo::countLabelFrame(predicted, truth, ALL_VALID);
  const std::vector<std::pair<std::uint8_t, std::uint8_t>> expected{
      {1, 2}, {2, 4}, {3, 0}};
  EXPECT_EQ(c.objects, expected);
  EXPECT_EQ(c.moving_hits, 8u);
  EXPECT_EQ(c.truth_moving, 10u);
}

TEST(LabelMetrics, CountRejectsSizeMismatch)
{
  const auto truth = image4x3(std::vector<std::uint8_t>(12, 0));
  const LabelImage wide{6, 2, std::vector<std::uint8_t>(12, 1)};
  EXPECT_THROW(dynvo::countLabelFrame(wide, truth, ALL_VALID), std::invalid_argument);
  EXPECT_THROW(dynvo::countLabelFrame(truth, truth, std::vector<std::uint8_t>(11, 1)),
               std::invalid_argument);
}

TEST(LabelMetrics, ValidDepthMaskIsFinitePositiveDepth)
{
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const dynvo::DepthImage depth{5, 1, {1.5f, nan, 0.0f, -1.0f, 4.0f}};
  EXPECT_EQ(dynvo::validDepthMask(depth), (std::vector<std::uint8_t>{1, 0, 0, 0, 1}));
}

TEST(LabelMetrics, PerfectPredictionScoresOneAndNoSwitches)
{
  // An object moving right by one column per frame, predicted exactly with label 2.
  std::vector<LabelFrameCounts> frames;
  for (int f = 0; f < 3; ++f) {
    std::vector<std::uint8_t> truth(12, 0), predicted(12, 1);
    for (int row = 0; row < 3; ++row) {
      truth[4 * row + f] = 1;
      predicted[4 * row + f] = 2;
    }
    frames.push_back(
        dynvo::countLabelFrame(image4x3(predicted), image4x3(truth), ALL_VALID));
  }
  const auto s = dynvo::summarizeSegmentation(frames);
  EXPECT_DOUBLE_EQ(s.moving_iou, 1.0);
  EXPECT_DOUBLE_EQ(s.static_precision, 1.0);
  EXPECT_DOUBLE_EQ(s.static_recall, 1.0);
  EXPECT_DOUBLE_EQ(s.labelled, 1.0);
  EXPECT_DOUBLE_EQ(s.bg_ok, 1.0);
  EXPECT_DOUBLE_EQ(s.id_switch_rate, 0.0);
  EXPECT_DOUBLE_EQ(s.moving_share, 0.25);
  EXPECT_EQ(s.frames, 3u);
  EXPECT_EQ(s.moving_frames, 3u);
  EXPECT_EQ(s.id_pairs, 2u);
}

TEST(LabelMetrics, StaticScoresArePooledOverPixelsAndIouAveragedOverMovingFrames)
{
  const std::vector<LabelFrameCounts> frames{
      // The frame of CountsOneFrameOnValidPixelsOnly: IoU 3/5, precision 5/6.
      counts(11, 10, 6, 4, 7, 4, 5, 3),
      // No moving pixels: not in the IoU mean; half the pixels unlabelled.
      counts(100, 50, 50, 0, 100, 0, 50, 0),
      // IoU 5/15, every static prediction right.
      counts(20, 20, 10, 10, 10, 10, 10, 5),
  };
  const auto s = dynvo::summarizeSegmentation(frames);
  EXPECT_DOUBLE_EQ(s.moving_iou, (3.0 / 5.0 + 5.0 / 15.0) / 2.0);
  // Pooled, not the mean of the per-frame ratios (that would be 0.944 for precision).
  EXPECT_DOUBLE_EQ(s.static_precision, 65.0 / 66.0);
  EXPECT_DOUBLE_EQ(s.static_recall, 65.0 / 117.0);
  EXPECT_DOUBLE_EQ(s.labelled, 80.0 / 131.0);
  EXPECT_DOUBLE_EQ(s.moving_share, 14.0 / 80.0);
  // Frame 1's background is only 5/6 static.
  EXPECT_DOUBLE_EQ(s.bg_ok, 2.0 / 3.0);
  EXPECT_EQ(s.frames, 3u);
  EXPECT_EQ(s.moving_frames, 2u);
}

TEST(LabelMetrics, BackgroundIsOkFromNinetyFivePercentAndNeverWhenNothingIsStatic)
{
  const std::vector<LabelFrameCounts> frames{
      counts(100, 100, 100, 0, 95, 5, 95, 0),   // exactly 0.95 of it static: ok
      counts(100, 100, 100, 0, 94, 6, 94, 0),   // 0.94: not ok
      counts(100, 100, 0, 100, 0, 100, 0, 100), // no predicted background: not ok
  };
  EXPECT_DOUBLE_EQ(dynvo::summarizeSegmentation(frames).bg_ok, 1.0 / 3.0);
  EXPECT_DOUBLE_EQ(dynvo::summarizeSegmentation(frames, 0.9).bg_ok, 2.0 / 3.0);
  EXPECT_THROW(dynvo::summarizeSegmentation(frames, 1.5), std::invalid_argument);
}

TEST(LabelMetrics, IdSwitchesCountChangesBetweenConsecutiveFramesWhereTheObjectIsFound)
{
  const std::vector<LabelFrameCounts> frames{
      withObjects({{1, 2}, {2, 3}}),
      withObjects({{1, 2}, {2, 4}}), // object 1 kept (pair), object 2 switched (pair)
      withObjects({{1, 0}, {2, 4}}), // object 1 missed (no pair), object 2 kept (pair)
      withObjects({{1, 5}}),         // object 1 was missed before (no pair), 2 gone
      withObjects({{1, 6}, {2, 4}}), // object 1 switched (pair), 2 was absent (no pair)
  };
  const auto s = dynvo::summarizeSegmentation(frames);
  EXPECT_EQ(s.id_pairs, 4u);
  EXPECT_EQ(s.id_switches, 2u);
  EXPECT_DOUBLE_EQ(s.id_switch_rate, 0.5);
}

TEST(LabelMetrics, RenamingPredictedIdsConsistentlyChangesNothingAndPerFrameSwitches)
{
  // Two objects in the left and right halves of rows 0-1; row 2 is static.
  const auto truth = image4x3({1, 1, 2, 2, 1, 1, 2, 2, 0, 0, 0, 0});
  const auto as_predicted = [](std::uint8_t left, std::uint8_t right) {
    return image4x3({left, left, right, right, left, left, right, right, 1, 1, 1, 0});
  };
  const auto score = [&](std::vector<std::pair<std::uint8_t, std::uint8_t>> ids) {
    std::vector<LabelFrameCounts> frames;
    for (const auto& [left, right] : ids)
      frames.push_back(
          dynvo::countLabelFrame(as_predicted(left, right), truth, ALL_VALID));
    return dynvo::summarizeSegmentation(frames);
  };
  const auto stable = score({{2, 3}, {2, 3}, {2, 3}});
  const auto renamed = score({{7, 4}, {7, 4}, {7, 4}});
  const auto swapped = score({{2, 3}, {3, 2}, {2, 3}});
  EXPECT_DOUBLE_EQ(stable.id_switch_rate, 0.0);
  EXPECT_DOUBLE_EQ(renamed.id_switch_rate, 0.0);
  // Both objects change id at both transitions.
  EXPECT_DOUBLE_EQ(swapped.id_switch_rate, 1.0);
  for (const auto& s : {renamed, swapped}) {
    EXPECT_DOUBLE_EQ(s.moving_iou, stable.moving_iou);
    EXPECT_DOUBLE_EQ(s.static_precision, stable.static_precision);
    EXPECT_DOUBLE_EQ(s.labelled, stable.labelled);
  }
  EXPECT_DOUBLE_EQ(stable.moving_iou, 1.0);
  EXPECT_DOUBLE_EQ(stable.labelled, 11.0 / 12.0);
  EXPECT_DOUBLE_EQ(stable.static_recall, 3.0 / 4.0);
}

TEST(LabelMetrics, ScoresWithoutADenominatorAreUndefined)
{
  // A static sequence: no moving pixel, so no IoU and no id pair.
  const std::vector<LabelFrameCounts> still{counts(10, 10, 10, 0, 10, 0, 10, 0)};
  const auto s = dynvo::summarizeSegmentation(still);
  EXPECT_TRUE(std::isnan(s.moving_iou));
  EXPECT_TRUE(std::isnan(s.id_switch_rate));
  EXPECT_DOUBLE_EQ(s.static_precision, 1.0);
  EXPECT_DOUBLE_EQ(s.moving_share, 0.0);

  const auto none = dynvo::summarizeSegmentation({});
  EXPECT_EQ(none.frames, 0u);
  EXPECT_TRUE(std::isnan(none.labelled));
  EXPECT_TRUE(std::isnan(none.bg_ok));
}

TEST(LabelMetrics, FormatsTheLineAndJsonWithUndefinedValues)
{
  dynvo::SegmentationEvaluation result;
  result.scores = dynvo::summarizeSegmentation({counts(8, 6, 4, 2, 6, 2, 4, 1)});
  EXPECT_EQ(dynvo::formatSegmentationScores(result),
            "moving_iou=0.333333 static_precision=1.000000 static_recall=0.666667 "
            "labelled=0.750000 bg_ok=1.000000 id_switch_rate=nan frames=1");
  EXPECT_EQ(dynvo::formatSegmentationScores(result, true),
            "{\"moving_iou\": 0.333333, \"static_precision\": 1.000000, "
            "\"static_recall\": 0.666667, \"labelled\": 0.750000, \"bg_ok\": 1.000000, "
            "\"id_switch_rate\": null, \"frames\": 1}");
  result.has_truth_labels = false;
  EXPECT_EQ(dynvo::formatSegmentationScores(result),
            "moving_share=0.333333 labelled=0.750000 frames=1");
  EXPECT_EQ(dynvo::formatSegmentationScores(result, true),
            "{\"moving_share\": 0.333333, \"labelled\": 0.750000, \"frames\": 1}");
}

} // namespace
