// SPDX-License-Identifier: BSD-3-Clause
// Dual-mode model, compensation, matching and tracking (docs/algorithm.md §4-§6).
#include <dynvo/common/rigid_fit.h>
#include <dynvo/motion_segmentation/dual_label_model.h>
#include <dynvo/motion_segmentation/rigid_motion_segmentation.h>
#include <dynvo/motion_segmentation/segment_tracker.h>

#include "support/pose_compare.h"
#include "support/synthetic_flow.h"

#include <pcl/point_types.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>
#include <thread>
#include <utility>
#include <vector>

namespace {

using Model = dynvo::DualLabelModel::Model;
constexpr float MAX_AGE = 5.0f;

/// Source pixels of the identity warp (every cell onto itself), 16 px cells.
std::vector<Eigen::Vector2f>
identitySources(int cols, int rows, Eigen::Vector2f shift = Eigen::Vector2f::Zero())
{
  std::vector<Eigen::Vector2f> sources;
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c)
      sources.emplace_back(Eigen::Vector2f(16.0f * c + 8.0f, 16.0f * r + 8.0f) + shift);
  return sources;
}

/// One frame on a single-cell model: identity compensation then update with `g`.
void
step(dynvo::DualLabelModel& model, std::uint8_t g)
{
  model.compensate(identitySources(1, 1), {1}, 16);
  model.update({g}, MAX_AGE);
}

TEST(DualLabelModel, StoppedObjectSwapsToStaticAfterMaxAgeFrames)
{
  dynvo::DualLabelModel model;
  model.reset(1, 1, 3);
  // An object (label 3) is seen for 7 frames: A = one-hot(3), age saturates at 5.
  for (int k = 0; k < 7; ++k)
    step(model, 3);
  EXPECT_FLOAT_EQ(model.age(Model::apparent, 0), 5.0f);
  EXPECT_FLOAT_EQ(model.probability(Model::apparent, 0, 3), 1.0f);
  EXPECT_EQ(model.readOut()[0], 3);
  // It stops: measured static (1). C grows 1, 2, 3, 4 while L stays 3 ...
  for (int k = 1; k <= 4; ++k) {
    step(model, 1);
    EXPECT_FLOAT_EQ(model.age(Model::candidate, 0), static_cast<float>(k));
    EXPECT_FLOAT_EQ(model.probability(Model::candidate, 0, 1), 1.0f);
    EXPECT_EQ(model.readOut()[0], 3) << "frame " << k;
  }
  // ... and at the 5th frame C reaches alpha_max: swap, candidate reset, L = 1.
  step(model, 1);
  EXPECT_EQ(model.readOut()[0], 1);
  EXPECT_FLOAT_EQ(model.age(Model::apparent, 0), 5.0f);
  EXPECT_FLOAT_EQ(model.probability(Model::apparent, 0, 1), 1.0f);
  EXPECT_FLOAT_EQ(model.age(Model::candidate, 0), 0.0f);
  EXPECT_FLOAT_EQ(model.probability(Model::candidate, 0, 3), 0.0f);
  // No measurement: nothing changes, L kept.
  step(model, 0);
  EXPECT_EQ(model.readOut()[0], 1);
  EXPECT_FLOAT_EQ(model.age(Model::apparent, 0), 5.0f);
}

TEST(DualLabelModel, YoungCandidateOvertakesYoungerApparent)
{
  dynvo::DualLabelModel model;
  model.reset(1, 1, 3);
  step(model, 1); // A = one-hot(1), age 1
  step(model, 2); // C = one-hot(2), age 1: not older than A
  EXPECT_EQ(model.readOut()[0], 1);
  EXPECT_FLOAT_EQ(model.age(Model::candidate, 0), 1.0f);
  step(model, 2); // C age 2 > A age 1: swap
  EXPECT_EQ(model.readOut()[0], 2);
  EXPECT_FLOAT_EQ(model.age(Model::apparent, 0), 2.0f);
  EXPECT_FLOAT_EQ(model.age(Model::candidate, 0), 0.0f);
}

TEST(DualLabelModel, LabelsNotInUseLeaveTheCandidatesOnly)
{
  dynvo::DualLabelModel model;
  model.reset(2, 1, 3);
  model.setModel(Model::apparent, 0, {1, 0, 0}, 5.0f);
  model.setModel(Model::candidate, 0, {0, 1, 0}, 2.0f);
  model.setModel(Model::apparent, 1, {0, 1, 0}, 3.0f);
  model.setModel(Model::candidate, 1, {0, 0.5f, 0.5f}, 2.0f);
  model.forgetCandidates({0, 1, 0, 1}); // labels 1 and 3 in use, 2 gone
  // Cell 0's candidate held only label 2: uninitialised. Cell 1's keeps label 3's share
  // and its age. The apparent models are not touched, even cell 1's label 2.
  EXPECT_FLOAT_EQ(model.age(Model::candidate, 0), 0.0f);
  EXPECT_EQ(model.argmax(Model::candidate, 0), 0);
  EXPECT_FLOAT_EQ(model.probability(Model::candidate, 1, 2), 0.0f);
  EXPECT_FLOAT_EQ(model.probability(Model::candidate, 1, 3), 0.5f);
  EXPECT_FLOAT_EQ(model.age(Model::candidate, 1), 2.0f);
  EXPECT_FLOAT_EQ(model.probability(Model::apparent, 1, 2), 1.0f);
  EXPECT_EQ(model.argmax(Model::apparent, 0), 1);
}

TEST(DualLabelModel, CompensatedModelIsUpdatedAsRunningAverage)
{
  dynvo::DualLabelModel model;
  model.reset(2, 1, 3);
  model.setModel(Model::apparent, 0, {1, 0, 0}, 2.0f);
  model.setModel(Model::apparent, 1, {0, 1, 0}, 4.0f);
  // Cell 0 takes its square from 4 px to the right: 3/4 of cell 0, 1/4 of cell 1.
  // Cell 1's source square lies 3/4 outside the grid: only cell 1 is left (weight 1).
  model.compensate(identitySources(2, 1, {4.0f, 0.0f}), {1, 1}, 16);
  EXPECT_FLOAT_EQ(model.age(Model::apparent, 0), 0.75f * 2.0f + 0.25f * 4.0f);
  EXPECT_FLOAT_EQ(model.probability(Model::apparent, 0, 1), 0.75f);
  EXPECT_FLOAT_EQ(model.probability(Model::apparent, 0, 2), 0.25f);
  EXPECT_FLOAT_EQ(model.age(Model::apparent, 1), 4.0f);
  // Measurement 1 = argmax: P = (2.5 P~ + e1) / 3.5, age 3.5.
  model.update({1, 0}, MAX_AGE);
  EXPECT_FLOAT_EQ(model.probability(Model::apparent, 0, 1),
                  (2.5f * 0.75f + 1.0f) / 3.5f);
  EXPECT_FLOAT_EQ(model.probability(Model::apparent, 0, 2), 2.5f * 0.25f / 3.5f);
  EXPECT_FLOAT_EQ(model.age(Model::apparent, 0), 3.5f);
  EXPECT_EQ(model.readOut()[0], 1);
}

TEST(DualLabelModel, SubCellShiftGivesBilinearWeights)
{
  // 4 x 3 grid; previous cell j has age j + 1 and P = one-hot(j % 4 + 1) in A.
  constexpr int COLS = 4, ROWS = 3;
  dynvo::DualLabelModel model;
  model.reset(COLS, ROWS, 4);
  for (int j = 0; j < COLS * ROWS; ++j) {
    std::vector<float> p(4, 0.0f);
    p[j % 4] = 1.0f;
    model.setModel(Model::apparent, j, p, static_cast<float>(j + 1));
  }
  // Shift by (4, 8) px = (1/4, 1/2) cell: weights (1-fu)(1-fv) = 3/8, fu(1-fv) = 1/8,
  // (1-fu)fv = 3/8, fu fv = 1/8 on cells (a, b), (a+1, b), (a, b+1), (a+1, b+1).
  model.compensate(identitySources(COLS, ROWS, {4.0f, 8.0f}),
                   std::vector<std::uint8_t>(12, 1), 16);
  const auto age = [](int a, int b) {
    return static_cast<float>(b * COLS + a + 1);
  };
  // Interior cell (1, 0): all four sources inside.
  EXPECT_FLOAT_EQ(model.age(Model::apparent, 1),
                  0.375f * age(1, 0) + 0.125f * age(2, 0) + 0.375f * age(1, 1) +
                      0.125f * age(2, 1));
  // Labels: cell (1,0) -> label 2, (2,0) -> 3, (1,1) -> 2 (index 5 % 4 + 1), (2,1) -> 3.
  EXPECT_FLOAT_EQ(model.probability(Model::apparent, 1, 2), 0.75f);
  EXPECT_FLOAT_EQ(model.probability(Model::apparent, 1, 3), 0.25f);
  // Last column (3, 0): the a+1 sources are outside; the rest renormalised to 1/2, 1/2.
  EXPECT_FLOAT_EQ(model.age(Model::apparent, 3), 0.5f * age(3, 0) + 0.5f * age(3, 1));
  // Last row (1, 2): the b+1 sources are outside; weights 3/4 and 1/4.
  EXPECT_FLOAT_EQ(model.age(Model::apparent, 9), 0.75f * age(1, 2) + 0.25f * age(2, 2));
}

TEST(DualLabelModel, UninitialisedSourcesLowerAgeButKeepNormalisation)
{
  dynvo::DualLabelModel model;
  model.reset(2, 1, 2);
  model.setModel(Model::apparent, 0, {0, 1}, 4.0f); // cell 1 stays uninitialised
  model.compensate(identitySources(2, 1, {8.0f, 0.0f}), {1, 1}, 16);
  EXPECT_FLOAT_EQ(model.age(Model::apparent, 0), 2.0f); // 1/2 * 4 + 1/2 * 0
  EXPECT_FLOAT_EQ(model.probability(Model::apparent, 0, 2),
                  1.0f); // normalised over cell 0
}

TEST(DualLabelModel, ProbabilitiesStayNormalised)
{
  constexpr int COLS = 6, ROWS = 5, LABELS = 4;
  dynvo::DualLabelModel model;
  model.reset(COLS, ROWS, LABELS);
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> label(0, LABELS);
  std::uniform_real_distribution<float> shift(-12.0f, 12.0f);
  for (int k = 0; k < 40; ++k) {
    model.compensate(identitySources(COLS, ROWS, {shift(rng), shift(rng)}),
                     std::vector<std::uint8_t>(COLS * ROWS, 1), 16);
    std::vector<std::uint8_t> measurement(COLS * ROWS);
    for (auto& g : measurement)
      g = static_cast<std::uint8_t>(label(rng));
    model.update(measurement, MAX_AGE);
    for (int i = 0; i < COLS * ROWS; ++i)
      for (const Model m : {Model::apparent, Model::candidate}) {
        float sum = 0.0f;
        for (int l = 1; l <= LABELS; ++l)
          sum += model.probability(m, i, l);
        // A few dozen float multiply-adds per frame: rounding stays below 1e-5.
        if (model.age(m, i) > 0.0f)
          EXPECT_NEAR(sum, 1.0f, 1e-5f);
        else
          EXPECT_EQ(sum, 0.0f);
      }
  }
}

TEST(SegmentMatching, CorrelationByHand)
{
  const std::vector<std::uint8_t> segments = {1, 1, 1, 2, 2, 0};
  const std::vector<std::uint8_t> past = {1, 1, 0, 3, 3, 3};
  std::vector<double> C;
  const double score = dynvo::correlateLabelMaps(segments, past, 2, 3, C);
  // C_11 = 2 / sqrt(3 * 2), C_23 = 2 / sqrt(2 * 3); score = (3 C_11 + 2 C_23) / 5.
  EXPECT_NEAR(C[1 * 4 + 1], 2.0 / std::sqrt(6.0), 1e-12);
  EXPECT_NEAR(C[2 * 4 + 3], 2.0 / std::sqrt(6.0), 1e-12);
  EXPECT_EQ(C[1 * 4 + 3], 0.0);
  EXPECT_NEAR(score, 2.0 / std::sqrt(6.0), 1e-12);
}

/// A box translating 4 cm per frame to the right in front of a static background
/// (160 x 120, 4 px cells), fed frame by frame to one RigidMotionSegmentation.
class BoxSequence : public ::testing::Test {
protected:
  static constexpr int CELL = 4;

  std::vector<pcl::PointIndices> frame(int k, int box_col0, int box_width)
  {
    const Eigen::Matrix4d T_box =
        dynvo::test::makeMotion({0, 0, 1}, 0.0, {0.04, 0.0, 0.0});
    const auto synthetic = dynvo::test::makeSyntheticFlow(
        40, 30, CELL, dynvo::test::intrinsicsFor(160), Eigen::Matrix4d::Identity(),
        {{box_col0 + k, 8, box_col0 + k + box_width, 22, 1.2, T_box, 2}});
    truth = synthetic.truth;
    segmentation.setInputCloud(
        dynvo::test::cloudFromFlow<pcl::PointXYZRGB>(*synthetic.flow, CELL));
    segmentation.setInputFlow(synthetic.flow);
    std::vector<pcl::PointIndices> segments;
    segmentation.segment(segments);
    return segments;
  }

  void SetUp() override
  {
    segmentation.setCameraIntrinsics(dynvo::test::intrinsicsFor(160));
    // The paper's metric tests and first-pair rules: a noise-free 160 x 120 flow whose box
    // moves 4 cm, within the sensor model's 4-sigma radius for 0.6 px at f = 131 px.
    segmentation.setResidualModel(dynvo::ResidualModel::paper);
  }

  dynvo::RigidMotionSegmentation<pcl::PointXYZRGB> segmentation;
  std::vector<int> truth;
};

TEST_F(BoxSequence, BoxKeepsOneIdAndBackgroundIsFirst)
{
  for (int k = 0; k < 8; ++k) {
    const auto segments = frame(k, 4, 8);
    ASSERT_EQ(segments.size(), 2u) << "frame " << k;
    EXPECT_EQ(segmentation.getSegmentLabels(), (std::vector<std::uint8_t>{1, 2}));
    // The measurement Ghat is the box; the output also keeps the cells the box has just
    // left (the model holds them for up to alpha_max frames), so it covers the box.
    EXPECT_GE(dynvo::test::cellIoU(segmentation.getTracker().trackedLabels(),
                                   std::uint8_t{2}, truth, 2),
              0.9);
    for (std::size_t i = 0; i < truth.size(); ++i)
      if (truth[i] == 2)
        EXPECT_EQ(segmentation.getCellLabels()[i], 2);
    // The box's motion: 4 cm along x (float storage, far below 1 mm).
    EXPECT_NEAR(segmentation.getMotions()[1](0, 3), 0.04f, 1e-3f);
  }
  // reset() starts a new sequence: ids are given afresh (first-pair rule).
  segmentation.reset();
  EXPECT_EQ(frame(0, 20, 8).size(), 2u);
  EXPECT_EQ(segmentation.getSegmentLabels(), (std::vector<std::uint8_t>{1, 2}));
  EXPECT_GE(
      dynvo::test::cellIoU(segmentation.getCellLabels(), std::uint8_t{2}, truth, 2),
      0.9);
}

TEST_F(BoxSequence, BoxCoveringMostOfTheImageDoesNotTakeTheBackgroundLabel)
{
  // The box covers 28 of 40 columns over the full height: 840 of 1200 cells.
  const Eigen::Matrix4d T_box =
      dynvo::test::makeMotion({0, 0, 1}, 0.0, {0.04, 0.0, 0.0});
  const auto synthetic = dynvo::test::makeSyntheticFlow(
      40, 30, CELL, dynvo::test::intrinsicsFor(160), Eigen::Matrix4d::Identity(),
      {{2, 0, 30, 30, 1.2, T_box, 2}});
  segmentation.setInputCloud(
      dynvo::test::cloudFromFlow<pcl::PointXYZRGB>(*synthetic.flow, CELL));
  segmentation.setInputFlow(synthetic.flow);
  std::vector<pcl::PointIndices> segments;
  segmentation.segment(segments); // H_pred = identity: the static camera's prediction
  ASSERT_EQ(segments.size(), 2u);
  // The box (840 cells) is the largest segment, but the background agrees with H_pred.
  EXPECT_EQ(dynvo::test::cellIoU(segmentation.getCellLabels(), std::uint8_t{1},
                                 synthetic.truth, 1),
            1.0);
  EXPECT_TRUE(segmentation.getMotions()[0].isIdentity(1e-4f));
}

/// Sets frame k of a box (cells [col0, col1) x [row0, row1) of `box` at 1.2 m, 160 x 120,
/// 4 px cells) moving `step` metres along x before a static background, with flow noise 0.5
/// mm per axis (a new draw every frame), as the input; returns the true label of each cell.
/// Without `box_measured` the box's cells keep their 2D track but have no 3D flow.
std::vector<int>
setRegionFrame(dynvo::RigidMotionSegmentation<pcl::PointXYZRGB>& segmentation,
               const std::array<int, 4>& box,
               double step,
               std::size_t k,
               bool box_measured = true,
               bool box_tracked = true)
{
  constexpr int CELL = 4;
  const auto synthetic = dynvo::test::makeSyntheticFlow(
      40, 30, CELL, dynvo::test::intrinsicsFor(160), Eigen::Matrix4d::Identity(),
      {{box[0], box[1], box[2], box[3], 1.2,
        dynvo::test::makeMotion({0, 0, 1}, 0.0, {step, 0.0, 0.0}), 2}},
      5e-4, static_cast<std::uint32_t>(k + 1));
  if (!box_measured || !box_tracked)
    for (std::size_t i = 0; i < synthetic.truth.size(); ++i)
      if (synthetic.truth[i] == 2) {
        dynvo::PointFlow& cell = (*synthetic.flow)[i];
        const float none = std::numeric_limits<float>::quiet_NaN();
        cell.prev_x = cell.prev_y = cell.prev_z = none;
        cell.valid_3d = 0;
        cell.weight = 0.0f;
        if (!box_tracked) {
          cell.prev_u = cell.prev_v = none;
          cell.valid_2d = 0;
        }
      }
  segmentation.setInputCloud(
      dynvo::test::cloudFromFlow<pcl::PointXYZRGB>(*synthetic.flow, CELL));
  segmentation.setInputFlow(synthetic.flow);
  return synthetic.truth;
}

/// setRegionFrame() with the box of 8 x 14 cells from column col0, rows 8-21.
std::vector<int>
setBoxFrame(dynvo::RigidMotionSegmentation<pcl::PointXYZRGB>& segmentation,
            int col0,
            double step,
            std::size_t k)
{
  return setRegionFrame(segmentation, {col0, 8, col0 + 8, 22}, step, k);
}

/// Segments the frame of setBoxFrame(); returns the segments and the true label of each cell.
std::pair<std::vector<pcl::PointIndices>, std::vector<int>>
segmentBoxFrame(dynvo::RigidMotionSegmentation<pcl::PointXYZRGB>& segmentation,
                int col0,
                double step,
                std::size_t k)
{
  std::vector<int> truth = setBoxFrame(segmentation, col0, step, k);
  std::vector<pcl::PointIndices> segments;
  segmentation.segment(segments);
  return {segments, truth};
}

TEST(CellAndPixelStages, PixelStageOnAnotherThreadGivesTheOutputOfSegment)
{
  // segmentCells() then computeSegments() on a second thread, while this one reads the cell
  // stage's results (as the pipeline's fits do), must give what segment() gives on every
  // frame of a tracked sequence: the box moves 4 cm per frame from frame 2, so the frames
  // hold one and then two segments, and the tracker's state is carried between them.
  dynvo::RigidMotionSegmentation<pcl::PointXYZRGB> split, whole;
  for (auto* segmentation : {&split, &whole})
    segmentation->setCameraIntrinsics(dynvo::test::intrinsicsFor(160));
  int col0 = 4;
  for (std::size_t k = 0; k < 6; ++k) {
    const double step = k >= 2 ? 0.04 : 0.0;
    col0 += step > 0.0 ? 1 : 0;
    const auto [expected, truth] = segmentBoxFrame(whole, col0, step, k);
    setBoxFrame(split, col0, step, k);
    split.segmentCells();
    EXPECT_TRUE(split.getPixelLabels().empty()) << "frame " << k;
    std::vector<pcl::PointIndices> segments;
    std::thread pixel_stage([&] {
      split.computeSegments(segments);
    });
    const bool background = split.hasBackground();
    const std::vector<std::uint8_t> cells = split.getCellGrid().labels;
    const std::vector<std::uint8_t> ids = split.getSegmentLabels();
    pixel_stage.join();
    EXPECT_EQ(background, whole.hasBackground()) << "frame " << k;
    EXPECT_EQ(cells, whole.getCellLabels()) << "frame " << k;
    EXPECT_EQ(ids, whole.getSegmentLabels()) << "frame " << k;
    EXPECT_EQ(split.getPixelLabels(), whole.getPixelLabels()) << "frame " << k;
    ASSERT_EQ(segments.size(), expected.size()) << "frame " << k;
    for (std::size_t s = 0; s < segments.size(); ++s)
      EXPECT_EQ(segments[s].indices, expected[s].indices) << "frame " << k;
  }
  // Not vacuous: the moving box is an object by the last frame.
  EXPECT_EQ(whole.getSegmentLabels(), (std::vector<std::uint8_t>{1, 2}));
  // A cell stage without input gives no pixel stage either.
  dynvo::RigidMotionSegmentation<pcl::PointXYZRGB> empty;
  empty.segmentCells();
  std::vector<pcl::PointIndices> segments(2);
  empty.computeSegments(segments);
  EXPECT_TRUE(segments.empty());
  EXPECT_TRUE(empty.getPixelLabels().empty());
}

/// A segmentation of setRegionFrame()'s frames: an object is output from its
/// `birth_frames`-th consecutive frame, with the ratio exemption `birth_ratio` (0: none).
void
setUpBirth(dynvo::RigidMotionSegmentation<pcl::PointXYZRGB>& segmentation,
           int birth_frames,
           float birth_ratio = 0.0f)
{
  segmentation.setCameraIntrinsics(dynvo::test::intrinsicsFor(160));
  segmentation.setObjectBirthFrames(birth_frames);
  segmentation.setObjectBirthRatio(birth_ratio);
}

/// setRegionFrame(), then segment(): the ids output for the frame.
std::vector<std::uint8_t>
segmentRegionFrame(dynvo::RigidMotionSegmentation<pcl::PointXYZRGB>& segmentation,
                   const std::array<int, 4>& box,
                   double step,
                   std::size_t k,
                   bool box_measured = true,
                   bool box_tracked = true)
{
  setRegionFrame(segmentation, box, step, k, box_measured, box_tracked);
  std::vector<pcl::PointIndices> segments;
  segmentation.segment(segments);
  return segmentation.getSegmentLabels();
}

/// Output ids per frame while the box of segmentBoxFrame() (from column 4) moves 4 cm per
/// frame along x in the frames where `moving` is set and stands still (part of the
/// background) in the others; also checks that its cells stay out of the fit's static set
/// while it moves.
std::vector<std::vector<std::uint8_t>>
newObjectOutputs(const std::vector<bool>& moving, int birth_frames, float birth_ratio)
{
  dynvo::RigidMotionSegmentation<pcl::PointXYZRGB> segmentation;
  setUpBirth(segmentation, birth_frames, birth_ratio);
  std::vector<std::vector<std::uint8_t>> outputs;
  for (std::size_t k = 0; k < moving.size(); ++k) {
    const auto [segments, truth] =
        segmentBoxFrame(segmentation, 4, moving[k] ? 0.04 : 0.0, k);
    EXPECT_EQ(segments.size(), segmentation.getSegmentLabels().size());
    if (moving[k])
      for (std::size_t i = 0; i < truth.size(); ++i)
        if (truth[i] == 2)
          EXPECT_NE(segmentation.getCellLabels()[i], 1)
              << "frame " << k << " cell " << i;
    outputs.push_back(segmentation.getSegmentLabels());
  }
  return outputs;
}

TEST(ObjectBirth, NewObjectIsOutputFromItsThirdFrame)
{
  // Still for 3 frames, then moving: the motion is measured from frame 3 on (4 cm per
  // frame against 0.5 mm of flow noise), so the box is a new object there. Without the
  // ratio exemption it is output from its third consecutive frame, frame 5, and kept out
  // of the ego-motion fit from frame 3.
  const std::vector<bool> moving{false, false, false, true, true, true, true};
  const auto held = newObjectOutputs(moving, 3, 0.0f);
  for (int k = 0; k < 5; ++k)
    EXPECT_EQ(held[k], (std::vector<std::uint8_t>{1})) << "frame " << k;
  for (int k = 5; k < 7; ++k)
    EXPECT_EQ(held[k], (std::vector<std::uint8_t>{1, 2})) << "frame " << k;
  // object_birth_frames 1: output as soon as it is measured.
  const auto immediate = newObjectOutputs(moving, 1, 0.0f);
  EXPECT_EQ(immediate[2], (std::vector<std::uint8_t>{1}));
  EXPECT_EQ(immediate[3], (std::vector<std::uint8_t>{1, 2}));
  // Defaults (3 frames, ratio 5): its cells fit the background's motion about 46 times
  // worse (RMS: sqrt(40^2 + 0.75) / sqrt(0.75) mm) than their own, so it is output at once.
  const auto apart = newObjectOutputs(moving, 3, 5.0f);
  EXPECT_EQ(apart[2], (std::vector<std::uint8_t>{1}));
  for (int k = 3; k < 7; ++k)
    EXPECT_EQ(apart[k], (std::vector<std::uint8_t>{1, 2})) << "frame " << k;
}

TEST(ObjectBirth, ObjectOfTwoFramesIsNeverOutput)
{
  // Two frames of motion, as the spurious objects of a real static scene (most last one to
  // three frames): never among the outputs, and out of the fit while it lasts.
  const auto outputs =
      newObjectOutputs({false, false, false, true, true, false, false, false}, 3, 0.0f);
  for (std::size_t k = 0; k < outputs.size(); ++k)
    EXPECT_EQ(outputs[k], (std::vector<std::uint8_t>{1})) << "frame " << k;
}

TEST(ObjectBirth, ObjectMeasuredEveryOtherFrameIsNeverOutput)
{
  // A spurious object of a real static scene comes back every other frame on cells whose
  // flow seldom passes its checks (a dark monitor, a keyboard's repeated texture): in
  // between they have no 3D flow, and the dual model keeps the id on them. An object is
  // output from its third consecutive measured frame, so this one never is (counting every
  // measured frame output it on frame 7). The box's cells: no 3D flow on frames 0-2 (their
  // models stay empty) and on the even frames, 4 cm of motion on frames 3, 5, 7, 9.
  dynvo::RigidMotionSegmentation<pcl::PointXYZRGB> segmentation;
  setUpBirth(segmentation, 3);
  for (std::size_t k = 0; k < 11; ++k) {
    const bool measured = k >= 3 && k % 2 == 1;
    EXPECT_EQ(segmentRegionFrame(segmentation, {4, 8, 12, 22}, measured ? 0.04 : 0.0, k,
                                 measured),
              (std::vector<std::uint8_t>{1}))
        << "frame " << k;
    // Not vacuous: the tracker holds the object's id throughout, on at least half of the
    // box's 112 cells (on the frames without 3D flow the model keeps 70-98 of them).
    if (k >= 3)
      EXPECT_GT(std::count(segmentation.getCellLabels().begin(),
                           segmentation.getCellLabels().end(), std::uint8_t{2}),
                56)
          << "frame " << k;
  }
}

TEST(SegmentTracking, ObjectKeepsItsIdOverAFrameWithoutTracksOnItsCells)
{
  // The box moves 4 cm per frame from frame 3; on frame 6 none of its cells has a 2D track
  // (a blurred frame, a depth hole). The past label maps are warped into each frame through
  // every cell's source (docs/algorithm.md §4, §6): without a track, the reprojection of b_i
  // through H_pred, here onto the cell itself. The box is matched on frame 7 against the
  // map of frame 5 and keeps its id; warped through tracks only, the maps lost the box's
  // cells on frame 6 and it came back as a new object.
  dynvo::RigidMotionSegmentation<pcl::PointXYZRGB> segmentation;
  setUpBirth(segmentation, 1);
  for (std::size_t k = 0; k < 9; ++k) {
    const bool moving = k >= 3, tracked = k != 6;
    const std::vector<std::uint8_t> expected = moving && tracked
                                                   ? std::vector<std::uint8_t>{1, 2}
                                                   : std::vector<std::uint8_t>{1};
    EXPECT_EQ(segmentRegionFrame(segmentation, {4, 8, 12, 22}, moving ? 0.04 : 0.0, k,
                                 tracked, tracked),
              expected)
        << "frame " << k;
  }
}

TEST(ObjectBirth, ShortLivedObjectsDoNotUseUpTheLabels)
{
  // Twenty objects one after another, each in its own place, as the spurious objects of a
  // real static scene: a box of 5 x 5 cells moves 4 cm for two frames, then stands still
  // for twelve (more than the buffer's 5 frames and alpha_max's 5, after which no apparent
  // model and no buffered map holds its id). Each is a new object with an id; with 14 ids
  // for objects, the ids of gone objects must come free. Its cells keep candidate evidence
  // of its id (two measurements against a static apparent model of age 5 never swap), and
  // that evidence alone must not reserve the id.
  dynvo::RigidMotionSegmentation<pcl::PointXYZRGB> segmentation;
  setUpBirth(segmentation, 1);
  std::size_t k = 0;
  const auto frame = [&](int col0, int row0, double step) {
    return segmentRegionFrame(segmentation, {col0, row0, col0 + 5, row0 + 5}, step,
                              k++);
  };
  for (int still = 0; still < 3; ++still) // the background first
    frame(2, 2, 0.0);
  for (int object = 0; object < 20; ++object) {
    const int col0 = 2 + 7 * (object % 5), row0 = 2 + 7 * (object / 5);
    const std::vector<std::uint8_t> ids = frame(col0, row0, 0.04);
    ASSERT_EQ(ids.size(), 2u) << "object " << object;
    EXPECT_EQ(ids[0], 1) << "object " << object;
    EXPECT_GE(ids[1], 2) << "object " << object;
    frame(col0, row0, 0.04);
    for (int still = 0; still < 12; ++still)
      frame(col0, row0, 0.0);
  }
}

TEST(ObjectBirth, NoObjectIsOutputOnAFrameWithoutBackground)
{
  // The box moves 4 cm per frame along x; the camera is still. On frame 4 the prediction is
  // 10 cm off along y (a jerk the constant-velocity model missed): the background departs from
  // it by 10 cm, the box by about 11 cm, both beyond tau_cv = 3 cm, so no segment is the
  // background. Nothing was measured to move against a background there, so no object is
  // output and no pixel is labelled as one; the tracker keeps the box's id, which is output
  // again on the next frame.
  dynvo::RigidMotionSegmentation<pcl::PointXYZRGB> segmentation;
  segmentation.setCameraIntrinsics(dynvo::test::intrinsicsFor(160));
  for (std::size_t k = 0; k < 7; ++k) {
    segmentation.setPredictedMotion(
        k == 4
            ? Eigen::Matrix4f(dynvo::test::makeMotion({0, 0, 1}, 0.0, {0.0, 0.10, 0.0})
                                  .cast<float>())
            : Eigen::Matrix4f::Identity());
    const auto [segments, truth] = segmentBoxFrame(segmentation, 4, 0.04, k);
    const std::vector<std::uint8_t>& pixels = segmentation.getPixelLabels();
    const auto objects =
        std::count_if(pixels.begin(), pixels.end(), [](std::uint8_t label) {
          return label > 1;
        });
    if (k == 4) {
      EXPECT_EQ(segmentation.getSegmentLabels(), (std::vector<std::uint8_t>{1}));
      EXPECT_EQ(segments.size(), 1u);
      EXPECT_EQ(objects, 0);
      const std::vector<std::uint8_t>& cells = segmentation.getCellLabels();
      EXPECT_EQ(std::count(cells.begin(), cells.end(), 1), 0);
      EXPECT_GT(std::count(cells.begin(), cells.end(), 2), 0);
    }
    else if (k > 0) { // frame 0 starts the sequence: not checked here
      EXPECT_EQ(segmentation.getSegmentLabels(), (std::vector<std::uint8_t>{1, 2}))
          << "frame " << k;
      EXPECT_GT(objects, 0) << "frame " << k;
    }
  }
}

TEST(BackgroundGuard, ResegmentAgainstTheMeasuredMotionRecoversTheFrame)
{
  // The frame of the test above: the prediction is 10 cm off, so no segment is the
  // background. resegment() with the camera's measured motion (identity: it is still) runs
  // the tracking of that frame again from the state before it: the output, the cell labels
  // and the state carried to the next frames must be those of a run whose prediction was
  // right all along (the tracker's state is restored, not updated twice).
  const auto still = Eigen::Matrix4f::Identity().eval();
  const Eigen::Matrix4f jerk =
      dynvo::test::makeMotion({0, 0, 1}, 0.0, {0.0, 0.10, 0.0}).cast<float>();
  dynvo::RigidMotionSegmentation<pcl::PointXYZRGB> resegmented, reference;
  for (auto* segmentation : {&resegmented, &reference})
    segmentation->setCameraIntrinsics(dynvo::test::intrinsicsFor(160));
  for (std::size_t k = 0; k < 7; ++k) {
    resegmented.setPredictedMotion(k == 4 ? jerk : still);
    reference.setPredictedMotion(still);
    auto segments = segmentBoxFrame(resegmented, 4, 0.04, k).first;
    const auto expected = segmentBoxFrame(reference, 4, 0.04, k).first;
    if (k == 4) {
      EXPECT_FALSE(resegmented.hasBackground());
      resegmented.setPredictedMotion(still);
      resegmented.resegment(segments);
      EXPECT_TRUE(resegmented.hasBackground());
    }
    ASSERT_EQ(segments.size(), expected.size()) << "frame " << k;
    for (std::size_t s = 0; s < segments.size(); ++s)
      EXPECT_EQ(segments[s].indices, expected[s].indices) << "frame " << k;
    EXPECT_EQ(resegmented.getSegmentLabels(), reference.getSegmentLabels())
        << "frame " << k;
    EXPECT_EQ(resegmented.getCellLabels(), reference.getCellLabels()) << "frame " << k;
    EXPECT_EQ(resegmented.getNoiseGains(), reference.getNoiseGains()) << "frame " << k;
    const dynvo::DualLabelModel& model = resegmented.getTracker().model();
    const dynvo::DualLabelModel& expected_model = reference.getTracker().model();
    for (std::size_t cell = 0; cell < resegmented.getCellLabels().size(); ++cell)
      for (const auto m : {dynvo::DualLabelModel::Model::apparent,
                           dynvo::DualLabelModel::Model::candidate})
        ASSERT_EQ(model.age(m, cell), expected_model.age(m, cell))
            << "frame " << k << " cell " << cell;
    if (k > 0)
      EXPECT_EQ(resegmented.getSegmentLabels(), (std::vector<std::uint8_t>{1, 2}))
          << "frame " << k;
  }
}

TEST(BackgroundGuard, ResegmentWithoutASegmentGivesNothing)
{
  dynvo::RigidMotionSegmentation<pcl::PointXYZRGB> segmentation;
  std::vector<pcl::PointIndices> segments(2);
  segmentation.resegment(segments);
  EXPECT_TRUE(segments.empty());
  EXPECT_FALSE(segmentation.hasBackground());
}

/// Majority output label over the box's cells while a box (8 x 14 cells at 1.2 m) moves by
/// `steps[k]` metres along x in frame k: one cell column per frame while fast (4 cm at 1.2 m is
/// 4.4 px), in place when slow. Flow noise 0.5 mm per axis, a new draw every frame.
std::vector<int>
boxLabels(const std::vector<double>& steps, float separation_ratio, float hold = 1.15f)
{
  dynvo::RigidMotionSegmentation<pcl::PointXYZRGB> segmentation;
  segmentation.setCameraIntrinsics(dynvo::test::intrinsicsFor(160));
  segmentation.setObjectSeparationRatio(separation_ratio);
  if (separation_ratio > 0.0f)
    segmentation.setObjectSeparationHold(hold);
  std::vector<int> labels;
  int col0 = 4;
  for (std::size_t k = 0; k < steps.size(); ++k) {
    col0 += steps[k] >= 0.02 ? 1 : 0;
    const std::vector<int> truth =
        segmentBoxFrame(segmentation, col0, steps[k], k).second;
    std::array<int, 256> votes{};
    for (std::size_t i = 0; i < truth.size(); ++i)
      if (truth[i] == 2)
        ++votes[segmentation.getCellLabels()[i]];
    labels.push_back(
        static_cast<int>(std::max_element(votes.begin(), votes.end()) - votes.begin()));
  }
  return labels;
}

TEST(ObjectSeparation, SlowObjectStaysApartUntilItStops)
{
  // 4 cm per frame for 3 frames, then 4 mm per frame for 5 frames: within the 5.5 mm inlier
  // radius, so the segmentation puts box and background in one segment, but the box's cells
  // fit the background's motion about 4.7 times worse (RMS: sqrt(16 + 0.75) / sqrt(0.75) mm
  // with 0.5 mm noise per axis) than their own. Then 1.5 mm per frame for 8 frames (ratio
  // about 2: below the entry ratio 3, above the hold 1.15), then still for 10 frames.
  std::vector<double> steps(3, 0.04);
  steps.insert(steps.end(), 5, 0.004);
  steps.insert(steps.end(), 8, 0.0015);
  steps.insert(steps.end(), 10, 0.0);
  const std::vector<int> kept = boxLabels(steps, 3.0f);
  for (int k = 1; k < 16; ++k)
    EXPECT_EQ(kept[k], 2) << "frame " << k;
  // Once still, its ratio is about 1: it becomes background after alpha_max (5) frames, as
  // the dual model intends (one frame of slack for the warped model).
  for (int k = 16 + 6; k < 26; ++k)
    EXPECT_EQ(kept[k], 1) << "frame " << k;
  // Without the hold the box merges during the 1.5 mm stretch; without the rule at all,
  // already during the 4 mm one.
  EXPECT_EQ(boxLabels(steps, 3.0f, 3.0f)[8 + 6], 1);
  EXPECT_EQ(boxLabels(steps, 0.0f)[3 + 6], 1);
}

/// Tracked labels (Ghat) of the second frame of a static camera whose box at 1.2 m (cell
/// columns [col0, col1), rows [row0, row1); by default 8 x 8 cells) moves with T_box in both
/// frames, when the second frame's prediction is `T_pred` (the first pair has none).
/// 160 x 120, 4 px cells, 0.5 mm of flow noise per axis.
std::pair<std::vector<std::uint8_t>, std::vector<int>>
guardedLabels(const Eigen::Matrix4d& T_box,
              const Eigen::Matrix4d& T_pred,
              std::array<int, 4> box = {16, 11, 24, 19})
{
  constexpr int CELL = 4;
  dynvo::RigidMotionSegmentation<pcl::PointXYZRGB> segmentation;
  segmentation.setCameraIntrinsics(dynvo::test::intrinsicsFor(160));
  std::vector<int> truth;
  for (std::uint32_t k = 0; k < 2; ++k) {
    const auto synthetic = dynvo::test::makeSyntheticFlow(
        40, 30, CELL, dynvo::test::intrinsicsFor(160), Eigen::Matrix4d::Identity(),
        {{box[0], box[1], box[2], box[3], 1.2, T_box, 2}}, 5e-4, k + 1);
    truth = synthetic.truth;
    segmentation.setInputCloud(
        dynvo::test::cloudFromFlow<pcl::PointXYZRGB>(*synthetic.flow, CELL));
    segmentation.setInputFlow(synthetic.flow);
    segmentation.setPredictedMotion(k == 0 ? Eigen::Matrix4f::Identity()
                                           : Eigen::Matrix4f(T_pred.cast<float>()));
    std::vector<pcl::PointIndices> segments;
    segmentation.segment(segments);
  }
  return {segmentation.getTracker().trackedLabels(), truth};
}

TEST(BackgroundGuard, MotionsAreComparedWithThePredictionOverTheWholeScene)
{
  // The prediction is 5 cm off the static background (a dropped frame, a jerk), beyond
  // tau_cv = 3 cm, so the background's segment fails the guard. The box turns 0.1 rad per
  // frame about the optical axis, which runs through it, after moving 5 cm along x: on its
  // own cells (within 13 cm of the axis) that departs from the prediction by about 1 cm
  // RMS, over the scene (the background plane reaches 1.5 m from the axis) by about 10 cm.
  // It must not become the background.
  const Eigen::Matrix4d T_pred = dynvo::test::makeMotion({0, 0, 1}, 0.0, {0.05, 0, 0});
  const Eigen::Matrix4d T_turning =
      dynvo::test::makeMotion({0, 0, 1}, 0.1, {0, 0, 0}) * T_pred;
  const auto [turning, truth] = guardedLabels(T_turning, T_pred);
  EXPECT_EQ(std::count(turning.begin(), turning.end(), 1), 0);
  // A box that moves exactly as predicted agrees everywhere. Covering 20 x 22 cells (440,
  // against 760 for the background it replaces: more than half), it takes label 1: the
  // guard still moves the background label to a segment that agrees with the prediction.
  const auto [large, truth_large] = guardedLabels(T_pred, T_pred, {4, 4, 24, 26});
  std::size_t box_cells = 0;
  for (std::size_t i = 0; i < truth_large.size(); ++i)
    if (truth_large[i] == 2) {
      ++box_cells;
      EXPECT_EQ(large[i], 1) << "cell " << i;
    }
  EXPECT_EQ(box_cells, 440u);
  // The 8 x 8-cell box (64 cells against 1136) agrees as well, but a background does not
  // lose half of itself in one frame: label 1 does not move to it, and the frame has no
  // background (the pipeline then segments it again against its measured step).
  const auto [small, truth_small] = guardedLabels(T_pred, T_pred);
  EXPECT_EQ(std::count(small.begin(), small.end(), 1), 0);
  EXPECT_GT(std::count(truth_small.begin(), truth_small.end(), 2), 0);
}

/** The two-frame segmentation given by hand: segment c holds the cells with 3D flow whose
 * region id (makeSyntheticFlow's truth) is c, ids above `count` joining segment 1, each with
 * the motion fitted on its cells; no motions when a fit fails.
 */
dynvo::SpatialSegmentationResult
segmentsOfRegions(const dynvo::GridFlowData& grid,
                  const std::vector<int>& region,
                  int count,
                  const dynvo::RigidMotionSegmentationParameters& params)
{
  dynvo::SpatialSegmentationResult spatial;
  spatial.labels.assign(grid.size(), 0);
  spatial.sizes.assign(count, 0);
  std::vector<dynvo::RigidFitAccumulator> fits(count);
  for (std::size_t i = 0; i < grid.size(); ++i)
    if (grid.valid_3d[i]) {
      const int c = region[i] >= 1 && region[i] <= count ? region[i] : 1;
      spatial.labels[i] = static_cast<std::uint8_t>(c);
      ++spatial.sizes[c - 1];
      fits[c - 1].add(grid.a[i].cast<double>(), grid.b[i].cast<double>());
    }
  for (const dynvo::RigidFitAccumulator& fit : fits) {
    Eigen::Matrix4d H;
    if (fit.solve(H) != dynvo::RigidFitStatus::ok) {
      spatial.motions.clear();
      break;
    }
    spatial.motions.push_back(H);
  }
  spatial.inlier_threshold = params.inlier_chi2;
  return spatial;
}

TEST(ObjectSeparation, ObjectMergedWholeIntoTheBackgroundKeepsItsId)
{
  // A box (8 x 14 cells at 1.2 m) before a static background moves 4 cm per frame, then 3
  // mm; flow noise 0.5 mm per axis. The two-frame segmentation is given by hand: the box is
  // its own segment on every frame, tracked under its own id while fast. At 3 mm its residual
  // under the background's motion is within the sensor model's noise at gains 1 (median E at
  // most th_chi2 / 2), so the noise-split merge hands its whole segment to the background;
  // that segment holds none of the background's former cells. Its cells still fit the
  // background's motion about 3.6 times worse (RMS: sqrt(9 + 0.75) / sqrt(0.75) mm) than
  // their own: measured against the background's former cells elsewhere, the box stays apart.
  constexpr int CELL = 4, COLS = 40, ROWS = 30;
  const dynvo::CameraIntrinsics intrinsics = dynvo::test::intrinsicsFor(160);
  const dynvo::RigidMotionSegmentationParameters params;
  dynvo::SegmentTracker tracker;
  dynvo::GridFlowData grid;
  std::vector<int> truth;
  for (std::uint32_t k = 0; k < 3; ++k) {
    const int col0 = k == 0 ? 8 : 9;
    const double step = k < 2 ? 0.04 : 0.003;
    const auto synthetic = dynvo::test::makeSyntheticFlow(
        COLS, ROWS, CELL, intrinsics, Eigen::Matrix4d::Identity(),
        {{col0, 8, col0 + 8, 22, 1.2,
          dynvo::test::makeMotion({0, 0, 1}, 0.0, {step, 0.0, 0.0}), 2}},
        5e-4, k + 1);
    truth = synthetic.truth;
    dynvo::FlowGrid geometry;
    ASSERT_TRUE(
        dynvo::FlowGrid::fromFlow(*synthetic.flow, COLS * CELL, ROWS * CELL, geometry));
    grid.assign(*synthetic.flow, geometry);
    grid.setSensorNoise(params.noise, intrinsics.fx, 1.0f, 1.0f);
    // Segment 1 the background, 2 the box, each with the motion fitted on its cells.
    const dynvo::SpatialSegmentationResult spatial =
        segmentsOfRegions(grid, truth, 2, params);
    ASSERT_EQ(spatial.motions.size(), 2u);
    tracker.update(grid, spatial, Eigen::Matrix4d::Identity(), intrinsics, params);
  }
  // The premise: the box's cells fit the background's motion within the noise-split merge's
  // bound.
  const Eigen::Matrix3f R = Eigen::Matrix3f::Identity();
  const Eigen::Vector3f t = Eigen::Vector3f::Zero();
  std::vector<float> box_errors;
  std::size_t box_cells = 0, kept = 0;
  for (std::size_t i = 0; i < grid.size(); ++i)
    if (truth[i] == 2 && grid.valid_3d[i]) {
      box_errors.push_back(grid.error(i, R, t));
      ++box_cells;
      kept += tracker.trackedLabels()[i] == 2 ? 1 : 0;
    }
  std::nth_element(box_errors.begin(), box_errors.begin() + box_errors.size() / 2,
                   box_errors.end());
  ASSERT_LE(box_errors[box_errors.size() / 2], 0.5f * params.inlier_chi2);
  // Every box cell keeps the box's id (before: all of them became background).
  EXPECT_EQ(kept, box_cells);
}

TEST(AmbiguousTracks, TracksOnRepeatedTextureMakeTheObjectAmbiguous)
{
  // A still camera over a still scene; in one block of 6 x 6 cells (A) the texture repeats
  // every 12 px along x (a row of keys) and every track settled one copy over, 12 px off;
  // another block (B), of unique texture, truly moves 12 px. The two-frame segmentation is
  // given by hand: background, A, B, each with the motion fitted on its cells (A's and B's
  // alike). The background's motion puts A's cells where their patches match exactly, as
  // well as their own tracks do: A is ambiguous. B's cells do not match there: B is not.
  // With the test off (radius 0) nothing is. Both stay objects in the tracker.
  constexpr int CELL = 16, COLS = 20, ROWS = 15, W = COLS * CELL, H = ROWS * CELL;
  constexpr int PERIOD = 12;
  const dynvo::CameraIntrinsics intrinsics = dynvo::test::intrinsicsFor(W);
  const double depth = 1.2;
  // 12 px at 1.2 m; the blocks' depth grows by 1 cm per column, so the tracks lie 11.5-12 px
  // off, within the 1 px the own track is searched over.
  const Eigen::Matrix4d shift = dynvo::test::makeMotion(
      {0, 0, 1}, 0.0, {-PERIOD * depth / intrinsics.fx, 0.0, 0.0});
  const auto synthetic = dynvo::test::makeSyntheticFlow(
      COLS, ROWS, CELL, intrinsics, Eigen::Matrix4d::Identity(),
      {{3, 4, 9, 10, depth, shift, 2}, {12, 4, 18, 10, depth, shift, 3}});
  // Frame k-1: unique texture, repeated around A; frame k: the same, but B's pixels moved.
  std::mt19937 random(3);
  std::uniform_int_distribution<int> level(0, 255);
  const auto packed = [](int g) {
    const auto v = static_cast<std::uint32_t>(std::clamp(g, 0, 255));
    return v << 16 | v << 8 | v;
  };
  std::vector<std::uint32_t> previous(std::size_t{W} * H), current(previous.size());
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const bool keys = x >= 40 && x < 150 && y >= 56 && y < 168;
      previous[std::size_t(y) * W + x] = packed(
          keys ? 128 + static_cast<int>(60.0 * std::sin(2.0 * M_PI * x / PERIOD)) +
                     y * 37 % 29
               : level(random));
    }
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const bool moved = x >= 186 && x < 280 && y >= 60 && y < 164;
      current[std::size_t(y) * W + x] =
          previous[std::size_t(y) * W + x + (moved ? PERIOD : 0)];
    }
  const dynvo::FramePairColours colours{previous.data(), current.data(), 1, W, H};

  dynvo::FlowGrid geometry;
  ASSERT_TRUE(dynvo::FlowGrid::fromFlow(*synthetic.flow, W, H, geometry));
  dynvo::GridFlowData grid;
  grid.assign(*synthetic.flow, geometry);
  dynvo::RigidMotionSegmentationParameters params;
  grid.setSensorNoise(params.noise, intrinsics.fx, 1.0f, 1.0f);
  const dynvo::SpatialSegmentationResult spatial =
      segmentsOfRegions(grid, synthetic.truth, 3, params);
  ASSERT_EQ(spatial.motions.size(), 3u);

  // Whether the block's cells are one object with the same id, and that id is ambiguous.
  const auto ambiguousBlock = [&](int radius, int block) {
    params.ambiguity_search_radius = radius;
    dynvo::SegmentTracker tracker;
    tracker.update(grid, spatial, Eigen::Matrix4d::Identity(), intrinsics, params, colours);
    std::vector<std::uint8_t> ids;
    for (std::size_t i = 0; i < grid.size(); ++i)
      if (synthetic.truth[i] == block)
        ids.push_back(tracker.trackedLabels()[i]);
    EXPECT_EQ(ids.size(), 36u);
    EXPECT_GT(ids.front(), 1);
    EXPECT_EQ(std::count(ids.begin(), ids.end(), ids.front()),
              static_cast<std::ptrdiff_t>(ids.size()));
    return tracker.ambiguous(ids.front());
  };
  EXPECT_TRUE(ambiguousBlock(3, 2));
  EXPECT_FALSE(ambiguousBlock(3, 3));
  EXPECT_FALSE(ambiguousBlock(0, 2));
}

} // namespace
