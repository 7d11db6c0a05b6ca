// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/registration/static_scene_registration.h>

#include "registration_scene.h"

#include <pcl/point_types.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

using dynvo::StaticRegistrationStatus;
using namespace dynvo::test;

template <typename PointT> class StaticSceneRegistrationTyped : public ::testing::Test {
};
using PointTypes = ::testing::Types<pcl::PointXYZRGB, pcl::PointXYZRGBA>;
TYPED_TEST_SUITE(StaticSceneRegistrationTyped, PointTypes);

TYPED_TEST(StaticSceneRegistrationTyped, SameFrameTwiceGivesIdentity)
{
  BoxScene scene = BoxScene::make();
  scene.T_curr_prev.setIdentity();
  scene.object_motion.setIdentity();
  const FramePair<TypeParam> pair(scene);
  dynvo::StaticSceneRegistration<TypeParam> registration;
  registration.setInputSource(pair.current.cloud);
  registration.setInputTarget(pair.current.cloud);
  registration.setIndices(pair.staticPixels());
  registration.setInputFlow(pair.flow);
  pcl::PointCloud<TypeParam> aligned;
  registration.align(aligned);
  ASSERT_TRUE(registration.hasConverged());
  EXPECT_EQ(registration.getStatus(), StaticRegistrationStatus::converged);
  EXPECT_LT(
      rotationError(registration.getFinalTransformation(), Eigen::Matrix4d::Identity()),
      ROTATION_TOL);
  EXPECT_LT(translationError(registration.getFinalTransformation(),
                             Eigen::Matrix4d::Identity()),
            TRANSLATION_TOL);
  EXPECT_EQ(registration.getNumberOfCorrespondences(), pair.staticCellCount());
  EXPECT_EQ(registration.getNumberOfInliers(), pair.staticCellCount());
  // Residuals are float round-off only: (1e-5 m)^2 bounds it with a wide margin.
  EXPECT_LT(registration.getMeanSquaredResidual(), 1e-10);
  // align() returns the static points, unorganized (PCL's rule once indices are set).
  EXPECT_EQ(aligned.size(), pair.staticPixels()->indices.size());
  EXPECT_EQ(aligned.height, 1u);
}

TYPED_TEST(StaticSceneRegistrationTyped, RecoversAKnownMotionForwardAndInverse)
{
  for (const bool inverse : {false, true}) {
    BoxScene scene = BoxScene::make();
    if (inverse)
      scene.T_curr_prev = scene.T_curr_prev.inverse();
    const FramePair<TypeParam> pair(scene);
    dynvo::StaticSceneRegistration<TypeParam> registration;
    pair.feed(registration);
    registration.setIndices(pair.staticPixels());
    pcl::PointCloud<TypeParam> aligned;
    registration.align(aligned);
    ASSERT_TRUE(registration.hasConverged()) << "inverse " << inverse;
    // getFinalTransformation() is T_prev_curr, the inverse of the paper's H_k = T_curr_prev.
    const Eigen::Matrix4d truth = scene.T_curr_prev.inverse().matrix();
    EXPECT_LT(rotationError(registration.getFinalTransformation(), truth), ROTATION_TOL)
        << "inverse " << inverse;
    EXPECT_LT(translationError(registration.getFinalTransformation(), truth),
              TRANSLATION_TOL)
        << "inverse " << inverse;
    // The moving box's cells were never selected, so nothing was trimmed.
    EXPECT_EQ(registration.getNumberOfInliers(), pair.staticCellCount());
    // Exact correspondences: the mean squared residual is round-off, below (10 um)^2.
    EXPECT_LT(registration.getMeanSquaredResidual(), 1e-10) << "inverse " << inverse;
  }
}

TYPED_TEST(StaticSceneRegistrationTyped, TooFewStaticCellsDoNotConverge)
{
  const BoxScene scene = BoxScene::make();
  const FramePair<TypeParam> pair(scene);
  // Keep 5 static cells: one fewer than min_correspondences = 6.
  std::vector<std::uint8_t> few(pair.static_cells.size(), 0);
  std::size_t kept = 0;
  for (std::size_t i = 0; i < few.size() && kept < 5; ++i)
    if (pair.static_cells[i]) {
      few[i] = 1;
      ++kept;
    }
  dynvo::StaticSceneRegistration<TypeParam> registration;
  pair.feed(registration);
  registration.setIndices(pair.pixels(few));
  Eigen::Matrix4f prediction = Eigen::Matrix4f::Identity();
  prediction(0, 3) = 0.25f;
  pcl::PointCloud<TypeParam> aligned;
  registration.align(aligned, prediction);
  EXPECT_FALSE(registration.hasConverged());
  EXPECT_EQ(registration.getStatus(),
            StaticRegistrationStatus::too_few_correspondences);
  EXPECT_EQ(registration.getNumberOfCorrespondences(), 5u);
  EXPECT_EQ(registration.getFinalTransformation(), prediction);
  EXPECT_EQ(registration.getMeanSquaredResidual(), std::numeric_limits<double>::max());
  EXPECT_TRUE(aligned.empty());
  // Lowering the minimum to 5 turns the same input into a converged estimate.
  registration.setMinCorrespondences(5);
  registration.align(aligned, prediction);
  EXPECT_TRUE(registration.hasConverged());
}

using Point = pcl::PointXYZRGB;

class StaticSceneRegistrationTest : public ::testing::Test {
protected:
  StaticSceneRegistrationTest()
      : scene_(BoxScene::make())
      , pair_(scene_)
  {
    pair_.feed(registration_);
    registration_.setIndices(pair_.staticPixels());
  }

  Eigen::Matrix4d truth() const { return scene_.T_curr_prev.inverse().matrix(); }

  /// Runs align() and returns stderr, where PCL_ERROR writes.
  std::string alignCapturingErrors()
  {
    ::testing::internal::CaptureStderr();
    registration_.align(aligned_);
    return ::testing::internal::GetCapturedStderr();
  }

  BoxScene scene_;
  FramePair<Point> pair_;
  dynvo::StaticSceneRegistration<Point> registration_;
  pcl::PointCloud<Point> aligned_;
};

TEST_F(StaticSceneRegistrationTest, CellCentresAndWholeCellsSelectTheSameCells)
{
  pcl::PointIndices::Ptr centres(new pcl::PointIndices);
  for (std::size_t i = 0; i < pair_.static_cells.size(); ++i)
    if (pair_.static_cells[i]) {
      centres->indices.push_back(static_cast<int>(pair_.grid.centreIndex(i)));
    }
  registration_.setIndices(centres);
  registration_.align(aligned_);
  ASSERT_TRUE(registration_.hasConverged());
  EXPECT_EQ(registration_.getNumberOfCorrespondences(), pair_.staticCellCount());
  EXPECT_LT(translationError(registration_.getFinalTransformation(), truth()),
            TRANSLATION_TOL);
  EXPECT_EQ(aligned_.size(), centres->indices.size());
}

TEST_F(StaticSceneRegistrationTest, StaticCellsSelectWhatTheirPixelsSelect)
{
  registration_.align(aligned_);
  ASSERT_TRUE(registration_.hasConverged());
  const Eigen::Matrix4f by_pixels = registration_.getFinalTransformation();
  // Cells take precedence: the indices now name a single pixel, which alone is too few.
  pcl::PointIndices::Ptr one(new pcl::PointIndices);
  one->indices = {0};
  registration_.setIndices(one);
  registration_.setStaticCells(pair_.cells(pair_.static_cells));
  registration_.align(aligned_);
  ASSERT_TRUE(registration_.hasConverged());
  EXPECT_EQ(registration_.getNumberOfCorrespondences(), pair_.staticCellCount());
  // The same cells in the same order: the same fit, bit for bit.
  EXPECT_EQ(registration_.getFinalTransformation(), by_pixels);
  // The output: the centres of the static cells, moved.
  EXPECT_EQ(aligned_.size(), pair_.staticCellCount());

  registration_.setStaticCells(dynvo::FlowGrid());
  registration_.align(aligned_);
  EXPECT_EQ(registration_.getStatus(),
            StaticRegistrationStatus::too_few_correspondences);
}

TEST_F(StaticSceneRegistrationTest, StaticCellsOnAnotherGridAreRejected)
{
  registration_.setStaticCells(dynvo::FlowGrid(scene_.width, scene_.height, CELL / 2));
  const std::string log = alignCapturingErrors();
  EXPECT_NE(log.find("not on the flow's grid"), std::string::npos) << log;
  EXPECT_FALSE(registration_.hasConverged());
  EXPECT_EQ(registration_.getStatus(), StaticRegistrationStatus::invalid_input);
}

TEST_F(StaticSceneRegistrationTest, WithoutIndicesEveryValidCellCounts)
{
  std::size_t valid = 0;
  for (const auto& f : *pair_.flow)
    valid += f.valid_3d;
  registration_.setIndices(pcl::IndicesPtr());
  registration_.align(aligned_);
  EXPECT_EQ(registration_.getNumberOfCorrespondences(), valid);
  EXPECT_GT(valid, pair_.staticCellCount()); // the moving box is in S now
}

TEST_F(StaticSceneRegistrationTest, OutliersInTheStaticSetAreTrimmed)
{
  // Five static cells get a 5 cm error in the same direction (a bad depth or track):
  // E = 2.5e-3 m^2 >> 4 th_inlier = 1.2e-4 m^2, so the trimming drops exactly these.
  pcl::PointCloud<dynvo::PointFlow>::Ptr corrupted(
      new pcl::PointCloud<dynvo::PointFlow>(*pair_.flow));
  int outliers = 0;
  for (std::size_t i = 0; i < corrupted->size() && outliers < 5; i += 7)
    if (pair_.static_cells[i]) {
      (*corrupted)[i].prev_x += 0.05f;
      ++outliers;
    }
  ASSERT_EQ(outliers, 5);
  registration_.setInputFlow(corrupted);
  registration_.setTrimRounds(0);
  registration_.align(aligned_);
  ASSERT_TRUE(registration_.hasConverged());
  const double untrimmed =
      translationError(registration_.getFinalTransformation(), truth());
  EXPECT_GT(untrimmed, TRANSLATION_TOL)
      << "the outliers must matter for this test to mean anything";
  registration_.setTrimRounds(2);
  registration_.align(aligned_);
  ASSERT_TRUE(registration_.hasConverged());
  EXPECT_LT(rotationError(registration_.getFinalTransformation(), truth()),
            ROTATION_TOL);
  EXPECT_LT(translationError(registration_.getFinalTransformation(), truth()),
            TRANSLATION_TOL);
  EXPECT_EQ(registration_.getNumberOfInliers(), pair_.staticCellCount() - 5);
  // The kept cells are exact, so the fitness is round-off, below (10 um)^2.
  EXPECT_LT(registration_.getMeanSquaredResidual(), 1e-10);
}

TEST_F(StaticSceneRegistrationTest, CollinearStaticCellsAreDegenerate)
{
  // Cells of the top row that see the back wall: their points lie on the intersection of the
  // wall with the viewing plane of that image row, a straight line.
  std::vector<std::uint8_t> row(pair_.static_cells.size(), 0);
  std::size_t n = 0;
  for (std::uint32_t col = 0; col < pair_.grid.cols; ++col) {
    const std::uint32_t u = col * CELL + CELL / 2;
    if (pair_.current.ids[CELL / 2 * scene_.width + u] == 0) { // box 0 = back wall
      row[col] = 1;
      ++n;
    }
  }
  ASSERT_GE(n, 6u);
  registration_.setIndices(pair_.pixels(row));
  registration_.align(aligned_);
  EXPECT_FALSE(registration_.hasConverged());
  EXPECT_EQ(registration_.getStatus(), StaticRegistrationStatus::degenerate);
  EXPECT_EQ(registration_.getNumberOfCorrespondences(), n);
}

// --- contract ---------------------------------------------------------------------------

constexpr const char* PREFIX = "[dynvo::StaticSceneRegistration::align]";

TEST_F(StaticSceneRegistrationTest, MissingInputsAreLoggedAndNotConverged)
{
  registration_.align(aligned_);
  ASSERT_TRUE(registration_.hasConverged()); // a good run first: nothing may stay stale

  // No source or target: pcl::Registration::align() reports it and computes nothing.
  dynvo::StaticSceneRegistration<Point> empty;
  ::testing::internal::CaptureStderr();
  empty.align(aligned_);
  EXPECT_NE(::testing::internal::GetCapturedStderr().find("StaticSceneRegistration"),
            std::string::npos);
  EXPECT_FALSE(empty.hasConverged());
  EXPECT_EQ(empty.getStatus(), StaticRegistrationStatus::not_computed);

  registration_.setInputFlow(nullptr);
  const std::string log = alignCapturingErrors();
  EXPECT_NE(log.find(PREFIX), std::string::npos) << log;
  EXPECT_NE(log.find("flow"), std::string::npos) << log;
  EXPECT_FALSE(registration_.hasConverged());
  EXPECT_EQ(registration_.getStatus(), StaticRegistrationStatus::invalid_input);
  EXPECT_EQ(registration_.getNumberOfCorrespondences(), 0u);
  EXPECT_EQ(registration_.getFinalTransformation(), Eigen::Matrix4f::Identity());
  EXPECT_TRUE(aligned_.empty());

  // pcl::Registration::setInputTarget dereferences its argument, so "no target" is a fresh
  // instance with only the source and the flow set.
  dynvo::StaticSceneRegistration<Point> no_target;
  no_target.setInputSource(pair_.current.cloud);
  no_target.setInputFlow(pair_.flow);
  ::testing::internal::CaptureStderr();
  no_target.align(aligned_);
  const std::string target_log = ::testing::internal::GetCapturedStderr();
  EXPECT_NE(target_log.find("StaticSceneRegistration"), std::string::npos)
      << target_log;
  EXPECT_NE(target_log.find("target"), std::string::npos) << target_log;
  EXPECT_FALSE(no_target.hasConverged());
}

TEST_F(StaticSceneRegistrationTest, UnorganizedInputsAreRejected)
{
  const auto unorganized = [](auto cloud) {
    auto copy = pcl::make_shared<typename std::decay_t<decltype(*cloud)>>(*cloud);
    copy->width = static_cast<std::uint32_t>(copy->size());
    copy->height = 1;
    return copy;
  };
  registration_.setInputSource(unorganized(pair_.current.cloud));
  EXPECT_NE(alignCapturingErrors().find(PREFIX), std::string::npos);
  EXPECT_FALSE(registration_.hasConverged());

  registration_.setInputSource(pair_.current.cloud);
  registration_.setInputTarget(unorganized(pair_.previous.cloud));
  EXPECT_NE(alignCapturingErrors().find(PREFIX), std::string::npos);
  EXPECT_FALSE(registration_.hasConverged());

  registration_.setInputTarget(pair_.previous.cloud);
  registration_.setInputFlow(unorganized(pair_.flow));
  EXPECT_NE(alignCapturingErrors().find(PREFIX), std::string::npos);
  EXPECT_FALSE(registration_.hasConverged());
}

TEST_F(StaticSceneRegistrationTest, MismatchedSizesAndBadIndicesAreRejected)
{
  const BoxScene other = BoxScene::make(96, 64);
  registration_.setInputTarget(other.render<Point>(false).cloud);
  EXPECT_NE(alignCapturingErrors().find(PREFIX), std::string::npos);
  EXPECT_FALSE(registration_.hasConverged());

  // A 10x10 grid cannot tile 160x120 (cell size 16 gives 7 rows).
  registration_.setInputTarget(pair_.previous.cloud);
  registration_.setInputFlow(
      pcl::make_shared<pcl::PointCloud<dynvo::PointFlow>>(10, 10));
  EXPECT_NE(alignCapturingErrors().find(PREFIX), std::string::npos);
  EXPECT_FALSE(registration_.hasConverged());

  // Bad indices are rejected when set, before pcl::Registration::align() could copy them,
  // and reported again by align().
  registration_.setInputFlow(pair_.flow);
  pcl::PointIndices::Ptr bad(new pcl::PointIndices);
  bad->indices = {0, static_cast<int>(pair_.current.cloud->size())};
  ::testing::internal::CaptureStderr();
  registration_.setIndices(bad);
  EXPECT_NE(::testing::internal::GetCapturedStderr().find(
                "[dynvo::StaticSceneRegistration::setIndices]"),
            std::string::npos);
  EXPECT_NE(alignCapturingErrors().find(PREFIX), std::string::npos);
  EXPECT_FALSE(registration_.hasConverged());
  EXPECT_EQ(registration_.getStatus(), StaticRegistrationStatus::invalid_input);
  bad->indices = {-1};
  ::testing::internal::CaptureStderr();
  registration_.setIndices(bad);
  ::testing::internal::GetCapturedStderr();
  EXPECT_NE(alignCapturingErrors().find(PREFIX), std::string::npos);
  EXPECT_FALSE(registration_.hasConverged());
  // Rejected indices select nothing; the source they were meant for takes them back.
  EXPECT_TRUE(registration_.getIndices()->empty());
  bad->indices = {0, static_cast<int>(pair_.current.cloud->size())};
  ::testing::internal::CaptureStderr();
  registration_.setIndices(bad);
  ::testing::internal::GetCapturedStderr();
  registration_.setInputSource(BoxScene::make(320, 240).render<Point>(true).cloud);
  EXPECT_EQ(registration_.getIndices()->size(), 2u);
}

TEST(StaticSceneRegistrationAsPcl, WorksThroughAPclRegistrationPointer)
{
  // Everything but the flow goes through pcl::Registration: inputs, indices, align() and
  // PCL's fitness score.
  const BoxScene scene = BoxScene::make();
  const FramePair<Point> pair(scene);
  auto registration = pcl::make_shared<dynvo::StaticSceneRegistration<Point>>();
  registration->setInputFlow(pair.flow);
  pcl::Registration<Point, Point, float>* base = registration.get();
  base->setInputSource(pair.current.cloud);
  base->setInputTarget(pair.previous.cloud);
  base->setIndices(pair.staticPixels());
  pcl::PointCloud<Point> aligned;
  base->align(aligned);
  ASSERT_TRUE(base->hasConverged());
  const Eigen::Matrix4d truth = scene.T_curr_prev.inverse().matrix();
  EXPECT_LT(translationError(base->getFinalTransformation(), truth), TRANSLATION_TOL);
  EXPECT_LT(rotationError(base->getFinalTransformation(), truth), ROTATION_TOL);
  EXPECT_EQ(aligned.size(), pair.staticPixels()->indices.size());
  // PCL's fitness: nearest target points of the moved source. The exact static points land
  // on the same surfaces, between target samples at most a pixel apart (<= 3 cm at 3.5 m and
  // 160x120), so the mean squared distance stays below (3 cm)^2; the moving box's points,
  // 13 cm away from where they were, are left out by a 5 cm max_range.
  const double fitness = base->getFitnessScore(0.05 * 0.05);
  EXPECT_GT(fitness, 0.0);
  EXPECT_LT(fitness, 0.03 * 0.03);

}

TEST_F(StaticSceneRegistrationTest, CallsThroughThePclBaseAreCheckedToo)
{
  pcl::Registration<Point, Point, float>& base = registration_;
  base.align(aligned_);
  EXPECT_TRUE(base.hasConverged());
  registration_.setInputFlow(nullptr);
  ::testing::internal::CaptureStderr();
  base.align(aligned_);
  EXPECT_NE(::testing::internal::GetCapturedStderr().find(PREFIX), std::string::npos);
  EXPECT_FALSE(base.hasConverged());
  EXPECT_TRUE(aligned_.empty());
}

TEST(StaticSceneRegistrationParameters, DefaultsFollowTheAlgorithmAndBadValuesThrow)
{
  const dynvo::StaticSceneRegistrationParameters defaults;
  EXPECT_NO_THROW(defaults.validate());
  EXPECT_FLOAT_EQ(defaults.th_inlier, 3e-5f);
  EXPECT_FLOAT_EQ(defaults.trim_factor, 4.0f);
  EXPECT_EQ(defaults.trim_rounds, 2);
  EXPECT_EQ(defaults.min_correspondences, 6);

  dynvo::StaticSceneRegistration<Point> registration;
  EXPECT_THROW(registration.setInlierThreshold(0.0f), std::invalid_argument);
  EXPECT_THROW(registration.setInlierThreshold(std::numeric_limits<float>::quiet_NaN()),
               std::invalid_argument);
  EXPECT_THROW(registration.setTrimFactor(0.5f), std::invalid_argument);
  EXPECT_THROW(registration.setTrimRounds(-1), std::invalid_argument);
  EXPECT_THROW(registration.setMinCorrespondences(2), std::invalid_argument);
  // A rejected value leaves the previous one in place.
  EXPECT_FLOAT_EQ(registration.getInlierThreshold(), 3e-5f);
  registration.setTrimRounds(3);
  EXPECT_EQ(registration.getParameters().trim_rounds, 3);
  try {
    registration.setTrimFactor(0.5f);
  }
  catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("trim_factor"), std::string::npos) << e.what();
  }
}

TEST(StaticSceneRegistrationVga, VgaFramesWorkAndAMismatchedGridIsRejected)
{
  const BoxScene scene = BoxScene::make(640, 480);
  const FramePair<pcl::PointXYZRGBA> pair(scene);
  EXPECT_EQ(pair.flow->width, 40u);
  EXPECT_EQ(pair.flow->height, 30u);
  dynvo::StaticSceneRegistration<pcl::PointXYZRGBA> registration;
  pair.feed(registration);
  registration.setIndices(pair.staticPixels());
  pcl::PointCloud<pcl::PointXYZRGBA> aligned;
  registration.align(aligned);
  ASSERT_TRUE(registration.hasConverged());
  const Eigen::Matrix4d truth = scene.T_curr_prev.inverse().matrix();
  EXPECT_LT(rotationError(registration.getFinalTransformation(), truth), ROTATION_TOL);
  EXPECT_LT(translationError(registration.getFinalTransformation(), truth),
            TRANSLATION_TOL);
  EXPECT_EQ(registration.getNumberOfCorrespondences(), pair.staticCellCount());

  // 40x40 cells of 16 px would need 640 rows.
  registration.setInputFlow(
      pcl::make_shared<pcl::PointCloud<dynvo::PointFlow>>(40, 40));
  ::testing::internal::CaptureStderr();
  registration.align(aligned);
  EXPECT_NE(::testing::internal::GetCapturedStderr().find(PREFIX), std::string::npos);
  EXPECT_FALSE(registration.hasConverged());
}

} // namespace
