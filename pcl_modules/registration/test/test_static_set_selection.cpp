// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/common/rigid_fit.h>
#include <dynvo/registration/static_set_selection.h>

#include "registration_scene.h"

#include <pcl/point_types.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <vector>

namespace {

using dynvo::FlowGrid;
using dynvo::LABEL_NONE;
using dynvo::LABEL_STATIC;
using namespace dynvo::test;

constexpr std::uint8_t LABEL_OBJECT = 2;

std::size_t
count(const FlowGrid& grid, std::uint8_t label)
{
  return static_cast<std::size_t>(
      std::count(grid.labels.begin(), grid.labels.end(), label));
}

template <typename PointT> class StaticSetSelectionTest : public ::testing::Test {
protected:
  StaticSetSelectionTest()
      : scene_(BoxScene::make())
      , pair_(scene_)
  {
    pair_.feed(registration_);
    selection_.setInlierThreshold(3e-5);
    selection_.setMotionGuardTolerance(0.03);
    // H_pred = the true motion: a constant-velocity camera.
    selection_.setPredictedMotion(scene_.T_curr_prev.matrix());
  }

  /// The true labels: static cells 1, the moving box 2, cells without flow 0.
  FlowGrid trueLabels() const
  {
    FlowGrid labels = pair_.grid;
    for (std::size_t i = 0; i < labels.size(); ++i)
      labels.labels[i] = pair_.static_cells[i]       ? LABEL_STATIC
                         : (*pair_.flow)[i].valid_3d ? LABEL_OBJECT
                                                     : LABEL_NONE;
    return labels;
  }

  /// The true labels swapped: the moving box "static", the background an object.
  FlowGrid swappedLabels() const
  {
    FlowGrid labels = trueLabels();
    for (auto& label : labels.labels)
      label = label == LABEL_OBJECT   ? LABEL_STATIC
              : label == LABEL_STATIC ? LABEL_OBJECT
                                      : label;
    return labels;
  }

  Eigen::Matrix4d truth() const { return scene_.T_curr_prev.inverse().matrix(); }

  void expectTruth()
  {
    ASSERT_TRUE(registration_.hasConverged());
    EXPECT_LT(translationError(registration_.getFinalTransformation(), truth()),
              TRANSLATION_TOL);
    EXPECT_LT(rotationError(registration_.getFinalTransformation(), truth()),
              ROTATION_TOL);
  }

  /// The static set of the last align() is exactly the cells that see the static scene.
  void expectStaticSetIsTheScene() const
  {
    const FlowGrid& selected = selection_.getStaticCells();
    ASSERT_EQ(selected.size(), pair_.static_cells.size());
    for (std::size_t i = 0; i < selected.size(); ++i)
      EXPECT_EQ(selected.labels[i] == LABEL_STATIC, pair_.static_cells[i] == 1)
          << "cell " << i;
  }

  BoxScene scene_;
  FramePair<PointT> pair_;
  dynvo::StaticSceneRegistration<PointT> registration_;
  dynvo::StaticSetSelection<PointT> selection_;
};

using PointTypes = ::testing::Types<pcl::PointXYZRGB, pcl::PointXYZRGBA>;
TYPED_TEST_SUITE(StaticSetSelectionTest, PointTypes);

TYPED_TEST(StaticSetSelectionTest, SameFrameTwiceGivesIdentity)
{
  BoxScene& scene = this->scene_;
  scene.T_curr_prev.setIdentity();
  scene.object_motion.setIdentity();
  this->pair_ = FramePair<TypeParam>(scene);
  this->registration_.setInputSource(this->pair_.current.cloud);
  this->registration_.setInputTarget(this->pair_.current.cloud);
  this->registration_.setInputFlow(this->pair_.flow);
  this->selection_.setPredictedMotion(Eigen::Matrix4d::Identity());
  this->selection_.setCellLabels(this->trueLabels());
  ASSERT_TRUE(this->selection_.align(this->registration_));
  this->expectTruth();
  EXPECT_TRUE(this->selection_.getLabelsTrusted());
}

TYPED_TEST(StaticSetSelectionTest, KnownMotionForwardAndInverse)
{
  for (const bool inverse : {false, true}) {
    BoxScene scene = BoxScene::make();
    if (inverse)
      scene.T_curr_prev = scene.T_curr_prev.inverse();
    this->scene_ = scene;
    this->pair_ = FramePair<TypeParam>(scene);
    this->pair_.feed(this->registration_);
    this->selection_.setPredictedMotion(scene.T_curr_prev.matrix());
    this->selection_.setCellLabels(this->trueLabels());
    ASSERT_TRUE(this->selection_.align(this->registration_)) << inverse;
    this->expectTruth();
    // Exact flow: the consensus keeps exactly the static cells.
    EXPECT_EQ(count(this->selection_.getStaticCells(), LABEL_STATIC),
              this->pair_.staticCellCount())
        << inverse;
  }
}

using Selection = StaticSetSelectionTest<pcl::PointXYZRGB>;

TEST_F(Selection, ConsensusTakesBackTheBackgroundTheSegmentationSplitOff)
{
  // Only the left half of the background is labelled static; on the right half every other
  // static cell is unlabelled, the others are labelled as an object. The consensus takes the
  // unlabelled ones back and, the labels being trusted, leaves the object cells out even
  // though their flow agrees.
  constexpr std::uint8_t OTHER_OBJECT = 3;
  FlowGrid labels = trueLabels();
  std::vector<std::uint8_t> expected = pair_.static_cells;
  for (std::size_t i = 0; i < labels.size(); ++i)
    if (labels.labels[i] == LABEL_STATIC && i % labels.cols >= labels.cols / 2) {
      labels.labels[i] = i % 2 ? LABEL_NONE : OTHER_OBJECT;
      expected[i] = i % 2;
    }
  selection_.setCellLabels(labels);
  ASSERT_LT(count(labels, LABEL_STATIC), pair_.staticCellCount());
  ASSERT_TRUE(selection_.align(registration_));
  EXPECT_TRUE(selection_.getLabelsTrusted());
  expectTruth();
  const FlowGrid& selected = selection_.getStaticCells();
  ASSERT_EQ(selected.size(), expected.size());
  for (std::size_t i = 0; i < selected.size(); ++i)
    EXPECT_EQ(selected.labels[i] == LABEL_STATIC, expected[i] == 1) << "cell " << i;
  EXPECT_GT(count(selected, LABEL_STATIC), count(labels, LABEL_STATIC));
}

TEST_F(Selection, MotionGuardOverridesABackgroundLabelOnTheMovingBox)
{
  // Labels swapped: the moving box is "static", the background an object. The first fit
  // follows the box, 13 cm away from H_pred > tau_cv = 3 cm: the guard fits on the cells
  // that agree with H_pred instead and does not trust the labels.
  selection_.setCellLabels(swappedLabels());
  ASSERT_TRUE(selection_.align(registration_));
  EXPECT_FALSE(selection_.getLabelsTrusted());
  expectTruth();

  // With the consensus off, the first fit is the result: the box's motion.
  selection_.setStaticConsensus(0.0f);
  ASSERT_TRUE(selection_.align(registration_));
  EXPECT_GT(translationError(registration_.getFinalTransformation(), truth()), 0.03);
}

TEST_F(Selection, ANearBodyGivesWayToTheLargerSurface)
{
  // VGA, so that the moving box (0.6 m across at 1.6 m) covers about 140 cells and the room
  // (2-3.5 m) about 900: the room's surface (sum z^2) is over 10 times the box's. Only the box
  // is labelled static, the room is unlabelled, and the prediction is the box's motion, so
  // the first fit, the guard and the consensus all take the box (docs/algorithm.md §7.8).
  scene_ = BoxScene::make(640, 480);
  pair_ = FramePair<pcl::PointXYZRGB>(scene_);
  pair_.feed(registration_);
  FlowGrid labels = swappedLabels();
  for (std::uint8_t& label : labels.labels)
    label = label == LABEL_OBJECT ? LABEL_NONE : label;
  selection_.setCellLabels(labels);
  selection_.setStaticConsensus(0.0f);
  ASSERT_TRUE(selection_.align(registration_));
  const Eigen::Matrix4d T_prev_curr_box =
      registration_.getFinalTransformation().cast<double>();
  ASSERT_GT(translationError(registration_.getFinalTransformation(), truth()), 0.03);
  selection_.setPredictedMotion(dynvo::rigidInverse(T_prev_curr_box));
  selection_.setStaticConsensus(2.0f);
  ASSERT_TRUE(selection_.align(registration_));
  EXPECT_TRUE(selection_.getLabelsTrusted());
  // The cells the consensus left out move as one body, the room: it is the background.
  expectTruth();
  expectStaticSetIsTheScene();

  // Labelled an object, the room is not a rival: the box stays (the labels are trusted).
  selection_.setCellLabels(swappedLabels());
  ASSERT_TRUE(selection_.align(registration_));
  EXPECT_GT(translationError(registration_.getFinalTransformation(), truth()), 0.03);
}

TEST_F(Selection, MovingCellsAreLeftOutOfEveryFitWhateverTheirLabel)
{
  // The segmentation merged the moving box into the background (every valid cell labelled
  // static). Its first fit leans to the box and the guard distrusts the labels; with the box's
  // cells given as moving (MotionEvidence's, docs/algorithm.md §7.6) no fit uses them, the
  // first fit agrees with H_pred and the static set is exactly the background.
  FlowGrid merged = trueLabels();
  FlowGrid moving = pair_.grid;
  for (std::size_t i = 0; i < merged.size(); ++i) {
    moving.labels[i] = merged.labels[i] == LABEL_OBJECT ? LABEL_OBJECT : LABEL_NONE;
    if (merged.labels[i] == LABEL_OBJECT)
      merged.labels[i] = LABEL_STATIC;
  }
  selection_.setCellLabels(merged);
  ASSERT_TRUE(selection_.align(registration_));
  EXPECT_FALSE(selection_.getLabelsTrusted());

  selection_.setMovingCells(moving);
  ASSERT_TRUE(selection_.align(registration_));
  EXPECT_TRUE(selection_.getLabelsTrusted());
  expectTruth();
  expectStaticSetIsTheScene();

  // Without labels too (every other valid cell is static).
  selection_.clearCellLabels();
  ASSERT_TRUE(selection_.align(registration_));
  EXPECT_EQ(count(selection_.getStaticCells(), LABEL_STATIC), pair_.staticCellCount());

  // A grid that is not the flow's leaves no cell out.
  selection_.setMovingCells(FlowGrid(320, 240, 16));
  ASSERT_TRUE(selection_.align(registration_));
  EXPECT_GT(count(selection_.getStaticCells(), LABEL_STATIC), pair_.staticCellCount());
}

TEST_F(Selection, IntermediateFitsLeaveTheRefinementSettingAsItWas)
{
  // The first fit and the guard's fit choose cells with the metric fit; the registration's
  // information-weighted refinement is switched off for them and must be back for the
  // caller afterwards, whichever path align() took (swapped labels: the guard path).
  registration_.setInformationIterations(3);
  selection_.setCellLabels(swappedLabels());
  ASSERT_TRUE(selection_.align(registration_));
  EXPECT_FALSE(selection_.getLabelsTrusted());
  EXPECT_EQ(registration_.getInformationIterations(), 3);
  expectTruth();
  selection_.setCellLabels(trueLabels());
  ASSERT_TRUE(selection_.align(registration_));
  EXPECT_EQ(registration_.getInformationIterations(), 3);
  expectTruth();
}

TEST_F(Selection, WithoutLabelsEveryValidCellIsStatic)
{
  selection_.clearCellLabels();
  selection_.align(registration_);
  std::size_t valid = 0;
  for (const auto& f : *pair_.flow)
    valid += f.valid_3d;
  EXPECT_EQ(count(selection_.getStaticCells(), LABEL_STATIC), valid);
  EXPECT_GT(valid, pair_.staticCellCount()); // the moving box is in the set
  EXPECT_EQ(registration_.getNumberOfCorrespondences(), valid);
}

TEST_F(Selection, LabelsOfAFailedSegmentationAreNeverTrusted)
{
  // A segmentation that broke its contract leaves an empty grid: the first fit has no cell,
  // the guard's cells near H_pred take over.
  selection_.setCellLabels(FlowGrid());
  ASSERT_TRUE(selection_.align(registration_));
  EXPECT_FALSE(selection_.getLabelsTrusted());
  expectTruth();
}

TEST_F(Selection, MissingInputsAreTheRegistrationsToReport)
{
  dynvo::StaticSceneRegistration<pcl::PointXYZRGB> empty;
  ::testing::internal::CaptureStderr();
  EXPECT_FALSE(selection_.align(empty));
  EXPECT_NE(::testing::internal::GetCapturedStderr().find("StaticSceneRegistration"),
            std::string::npos);
  EXPECT_EQ(selection_.getStaticCells().size(), 0u);
}

TEST(StaticSetSelectionParameters, DefaultsAndBadValues)
{
  const dynvo::StaticSetSelectionParameters defaults;
  EXPECT_NO_THROW(defaults.validate());
  EXPECT_FLOAT_EQ(defaults.static_consensus, 2.0f);
  dynvo::StaticSetSelection<pcl::PointXYZRGB> selection;
  EXPECT_THROW(selection.setStaticConsensus(-1.0f), std::invalid_argument);
  EXPECT_FLOAT_EQ(selection.getStaticConsensus(), 2.0f);
  dynvo::StaticSetSelectionParameters bad;
  bad.static_consensus = std::numeric_limits<float>::infinity();
  EXPECT_THROW(selection.setParameters(bad), std::invalid_argument);
}

} // namespace
