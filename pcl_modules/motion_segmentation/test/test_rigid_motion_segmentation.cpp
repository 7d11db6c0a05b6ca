// SPDX-License-Identifier: BSD-3-Clause
// RigidMotionSegmentation<PointT>: contract, identity, known motion, typed tests.
#include <dynvo/motion_segmentation/rigid_motion_segmentation.h>

#include "support/pose_compare.h"
#include "support/synthetic_flow.h"

#include <pcl/point_types.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

namespace {

using dynvo::test::FlowRegion;
using dynvo::test::makeMotion;

constexpr int CELL = 4;

template <typename PointT> class RigidMotionSegmentationTyped : public ::testing::Test {
};
using PointTypes = ::testing::Types<pcl::PointXYZRGB, pcl::PointXYZRGBA>;
TYPED_TEST_SUITE(RigidMotionSegmentationTyped, PointTypes);

TYPED_TEST(RigidMotionSegmentationTyped, KnownMotionsGivePixelSegments)
{
  const Eigen::Matrix4d T_camera = makeMotion({0, 1, 0}, 0.01, {0.01, 0.0, -0.02});
  const Eigen::Matrix4d T_object = makeMotion({0, 0, 1}, 0.05, {0.04, 0.01, 0.0});
  const auto synthetic =
      dynvo::test::makeSyntheticFlow(40, 30, CELL, dynvo::test::intrinsicsFor(160),
                                     T_camera, {{4, 6, 14, 16, 1.2, T_object, 2}});
  const auto cloud = dynvo::test::cloudFromFlow<TypeParam>(*synthetic.flow, CELL);

  dynvo::RigidMotionSegmentation<TypeParam> segmentation;
  // Noise-free 160 x 120 flow, 4 cm between the motions: the paper's metric test (the
  // sensor model's 0.6 px at f = 131 px allows 3 cm at 1.2 m).
  segmentation.setResidualModel(dynvo::ResidualModel::paper);
  segmentation.setTracking(false);
  segmentation.setInputCloud(cloud);
  segmentation.setInputFlow(synthetic.flow);
  std::vector<pcl::PointIndices> segments;
  segmentation.segment(segments);
  ASSERT_EQ(segments.size(), 2u);
  ASSERT_EQ(segmentation.getMotions().size(), 2u);
  EXPECT_EQ(segmentation.getSegmentLabels(), (std::vector<std::uint8_t>{1, 2}));
  // The 4 px cell size comes from the flow grid: 160 px / 40 columns.
  EXPECT_EQ(segmentation.getCellGrid().cell_size, static_cast<std::uint32_t>(CELL));
  EXPECT_EQ(segmentation.getCellGrid().labels, segmentation.getCellLabels());
  // Pixel indices: every finite pixel of the segment's cells, ascending, nothing else.
  const std::vector<std::uint8_t>& cells = segmentation.getCellLabels();
  for (std::size_t s = 0; s < segments.size(); ++s) {
    std::size_t expected = 0;
    for (std::size_t i = 0; i < cloud->size(); ++i) {
      const std::size_t cell =
          (i / cloud->width / CELL) * 40 + (i % cloud->width) / CELL;
      expected += cells[cell] == s + 1 && std::isfinite((*cloud)[i].z);
    }
    EXPECT_EQ(segments[s].indices.size(), expected);
    EXPECT_TRUE(std::is_sorted(segments[s].indices.begin(), segments[s].indices.end()));
    for (const int index : segments[s].indices)
      EXPECT_TRUE(std::isfinite((*cloud)[index].z));
  }
  // The object's box: 10 x 10 cells of 16 px, one in seven pixels without depth.
  EXPECT_NEAR(static_cast<double>(segments[1].indices.size()), 1600.0 * 6.0 / 7.0, 2.0);
  const Eigen::Matrix4d motion = segmentation.getMotions()[1].template cast<double>();
  // Float storage of the motion: 1e-6 relative, far below the 1 mm / 0.1 deg tolerances.
  EXPECT_LT(dynvo::test::translationError(motion, T_object), 1e-3);
  EXPECT_LT(dynvo::test::rotationError(motion, T_object), dynvo::test::radians(0.1));
}

TYPED_TEST(RigidMotionSegmentationTyped, SameFrameTwiceGivesOneStaticSegment)
{
  const auto synthetic = dynvo::test::makeSyntheticFlow(
      40, 30, CELL, dynvo::test::intrinsicsFor(160), Eigen::Matrix4d::Identity(), {});
  dynvo::RigidMotionSegmentation<TypeParam> segmentation;
  segmentation.setTracking(false);
  segmentation.setInputCloud(
      dynvo::test::cloudFromFlow<TypeParam>(*synthetic.flow, CELL));
  segmentation.setInputFlow(synthetic.flow);
  std::vector<pcl::PointIndices> segments;
  segmentation.segment(segments);
  ASSERT_EQ(segments.size(), 1u);
  EXPECT_EQ(segments[0].indices.size(), 160u * 120u - (160u * 120u + 6u) / 7u);
  // Zero flow: the fit returns identity up to float rounding of the points.
  EXPECT_TRUE(segmentation.getMotions()[0].isIdentity(1e-5f));
}

/// A static camera and one object turning 0.04 rad and moving (2, 0, 3) cm (cells 20-32 x 5-15
/// at 1.1 m), 2 mm of noise per axis.
const Eigen::Matrix4d T_OBJECT = makeMotion({0, 1, 1}, 0.04, {0.02, 0.0, 0.03});

dynvo::test::SyntheticFlow
objectFlow()
{
  return dynvo::test::makeSyntheticFlow(40, 30, CELL, dynvo::test::intrinsicsFor(160),
                                        Eigen::Matrix4d::Identity(),
                                        {{20, 5, 32, 15, 1.1, T_OBJECT, 2}}, 0.002, 9);
}

TEST(RigidMotionSegmentationDeterminism, SameSeedSameOutputForOneAndTwoThreads)
{
  const auto synthetic = objectFlow();
  const auto cloud =
      dynvo::test::cloudFromFlow<pcl::PointXYZRGB>(*synthetic.flow, CELL);
  const auto run = [&](unsigned threads) {
    dynvo::RigidMotionSegmentation<pcl::PointXYZRGB> segmentation;
    segmentation.setSeed(7);
    segmentation.setNumberOfThreads(threads);
    segmentation.setInputCloud(cloud);
    segmentation.setInputFlow(synthetic.flow);
    std::vector<pcl::PointIndices> segments;
    segmentation.segment(segments);
    return std::make_pair(segments, segmentation.getMotions());
  };
  const auto one = run(1);
  const auto two = run(2);
  // Not vacuous: the background and the object were both found, with pixels and one
  // motion each (two empty results would compare equal too).
  ASSERT_GE(one.first.size(), 2u);
  ASSERT_EQ(one.second.size(), one.first.size());
  for (const pcl::PointIndices& segment : one.first)
    EXPECT_FALSE(segment.indices.empty());
  EXPECT_TRUE(std::any_of(one.second.begin() + 1, one.second.end(), [&](const auto& H) {
    return dynvo::test::translationError(H, T_OBJECT) < 0.01; // 2 mm noise per axis
  }));
  ASSERT_EQ(one.first.size(), two.first.size());
  ASSERT_EQ(one.second.size(), two.second.size());
  for (std::size_t s = 0; s < one.first.size(); ++s)
    EXPECT_EQ(one.first[s].indices, two.first[s].indices);
  for (std::size_t s = 0; s < one.second.size(); ++s)
    EXPECT_TRUE(one.second[s] == two.second[s]); // bit-identical
}

TEST(RigidMotionSegmentationContract, DepthImageGivesTheLabelsOfTheCloud)
{
  const auto synthetic = objectFlow();
  const auto cloud =
      dynvo::test::cloudFromFlow<pcl::PointXYZRGB>(*synthetic.flow, CELL);
  using Image = std::shared_ptr<const std::vector<float>>;
  std::vector<float> z;
  for (const auto& point : *cloud)
    z.push_back(std::isfinite(point.z) ? point.z : std::numeric_limits<float>::quiet_NaN());
  const Image depth = std::make_shared<const std::vector<float>>(z);
  // Each run on a new object: same seed, same cell stage, only the pixels' source differs.
  const auto run = [&](const Image& image, bool before_cloud = false) {
    dynvo::RigidMotionSegmentation<pcl::PointXYZRGB> segmentation;
    segmentation.setSeed(7);
    if (image && before_cloud)
      segmentation.setInputDepth(image);
    segmentation.setInputCloud(cloud);
    if (image && !before_cloud)
      segmentation.setInputDepth(image);
    segmentation.setInputFlow(synthetic.flow);
    std::vector<pcl::PointIndices> segments;
    segmentation.segment(segments);
    return std::make_pair(segmentation.getPixelLabels(), segments.size());
  };
  const auto from_cloud = run(nullptr);
  // Not vacuous: background and object, so boundary cells compare per-pixel depths.
  ASSERT_GE(from_cloud.second, 2u);
  EXPECT_EQ(run(depth), from_cloud);
  // The image is what is read: without depth no pixel gets a label.
  const Image none = std::make_shared<const std::vector<float>>(
      z.size(), std::numeric_limits<float>::quiet_NaN());
  const auto from_none = run(none);
  EXPECT_EQ(std::count(from_none.first.begin(), from_none.first.end(), 0),
            static_cast<long>(none->size()));
  // An image of another size is ignored, and setInputCloud() drops the image set before it.
  EXPECT_EQ(run(std::make_shared<const std::vector<float>>(z.begin(), z.end() - 1)),
            from_cloud);
  EXPECT_EQ(run(none, true), from_cloud);
}

TEST(RigidMotionSegmentationContract, BadInputsClearOutputs)
{
  using Segmentation = dynvo::RigidMotionSegmentation<pcl::PointXYZRGB>;
  const auto synthetic = dynvo::test::makeSyntheticFlow(
      40, 30, CELL, dynvo::test::intrinsicsFor(160), Eigen::Matrix4d::Identity(), {});
  const auto cloud =
      dynvo::test::cloudFromFlow<pcl::PointXYZRGB>(*synthetic.flow, CELL);
  std::vector<pcl::PointIndices> segments(3);

  Segmentation no_inputs;
  no_inputs.segment(segments);
  EXPECT_TRUE(segments.empty());

  Segmentation no_flow;
  no_flow.setInputCloud(cloud);
  segments.resize(2);
  no_flow.segment(segments);
  EXPECT_TRUE(segments.empty());

  // A 10x10 flow grid does not tile this 160x120 cloud (16 px cells would give 7 rows).
  Segmentation mismatched;
  mismatched.setInputCloud(cloud);
  mismatched.setInputFlow(pcl::make_shared<pcl::PointCloud<dynvo::PointFlow>>(10, 10));
  segments.resize(2);
  mismatched.segment(segments);
  EXPECT_TRUE(segments.empty());
  EXPECT_TRUE(mismatched.getCellLabels().empty());
  EXPECT_EQ(mismatched.getCellGrid().size(), 0u);
  EXPECT_TRUE(mismatched.getMotions().empty());

  Segmentation unorganized;
  pcl::PointCloud<pcl::PointXYZRGB>::Ptr flat(
      new pcl::PointCloud<pcl::PointXYZRGB>(*cloud));
  flat->width = static_cast<std::uint32_t>(flat->size());
  flat->height = 1;
  unorganized.setInputCloud(flat);
  unorganized.setInputFlow(synthetic.flow);
  segments.resize(2);
  unorganized.segment(segments);
  EXPECT_TRUE(segments.empty());
}

TEST(RigidMotionSegmentationContract, VgaFrameWithDefaultCells)
{
  // 640 x 480 with the default 16 px cells: 40 x 30 grid.
  const Eigen::Matrix4d T_object = makeMotion({1, 0, 0}, 0.03, {0.0, 0.03, 0.02});
  const auto synthetic = dynvo::test::makeSyntheticFlow(
      40, 30, 16, dynvo::test::intrinsicsFor(640), Eigen::Matrix4d::Identity(),
      {{20, 10, 30, 20, 1.4, T_object, 2}});
  dynvo::RigidMotionSegmentation<pcl::PointXYZRGBA> segmentation;
  segmentation.setInputCloud(
      dynvo::test::cloudFromFlow<pcl::PointXYZRGBA>(*synthetic.flow, 16));
  segmentation.setInputFlow(synthetic.flow);
  std::vector<pcl::PointIndices> segments;
  segmentation.segment(segments);
  ASSERT_EQ(segments.size(), 2u);
  EXPECT_EQ(dynvo::test::cellIoU(segmentation.getCellLabels(), std::uint8_t{2},
                                 synthetic.truth, 2),
            1.0);
}

TEST(RigidMotionSegmentationContract, BadParametersThrow)
{
  dynvo::RigidMotionSegmentation<pcl::PointXYZRGB> segmentation;
  EXPECT_THROW(segmentation.setInlierThreshold(0.0f), std::invalid_argument);
  EXPECT_THROW(segmentation.setSampleSize(2), std::invalid_argument);
  EXPECT_THROW(segmentation.setMaxHypotheses(0), std::invalid_argument);
  EXPECT_THROW(segmentation.setMaxTrials(0), std::invalid_argument);
  EXPECT_THROW(segmentation.setDbscanEpsilon(-1.0f), std::invalid_argument);
  EXPECT_THROW(segmentation.setMaxLabels(255), std::invalid_argument);
  EXPECT_THROW(segmentation.setMinCorrelation(0.0f), std::invalid_argument);
  EXPECT_THROW(segmentation.setObjectSeparationRatio(-1.0f), std::invalid_argument);
  EXPECT_THROW(segmentation.setObjectSeparationHold(0.5f), std::invalid_argument);
  EXPECT_THROW(segmentation.setNumberOfThreads(0), std::invalid_argument);
  dynvo::CameraIntrinsics bad;
  bad.fx = 0.0;
  EXPECT_THROW(segmentation.setCameraIntrinsics(bad), std::invalid_argument);
  Eigen::Matrix4f nan_motion = Eigen::Matrix4f::Identity();
  nan_motion(0, 3) = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(segmentation.setPredictedMotion(nan_motion), std::invalid_argument);
  // A failed setter keeps the previous value.
  EXPECT_EQ(segmentation.getSampleSize(),
            dynvo::RigidMotionSegmentationParameters{}.sample_size);
  EXPECT_FLOAT_EQ(segmentation.getInlierThreshold(),
                  dynvo::RigidMotionSegmentationParameters{}.inlier_threshold);
}

TEST(RigidMotionSegmentationContract, CrossFieldRulesAreCheckedBySegmentNotBySetters)
{
  // 250 hypotheses need max_trials >= 250; with max_trials still at its default 200, the
  // setter must accept the value, so that the two setters work in either order.
  dynvo::RigidMotionSegmentation<pcl::PointXYZRGB> segmentation;
  EXPECT_NO_THROW(segmentation.setMaxHypotheses(250));
  std::vector<pcl::PointIndices> segments(2);
  try {
    segmentation.segment(segments);
    ADD_FAILURE() << "segment() accepted max_trials < max_hypotheses";
  }
  catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("max_trials"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(segments.empty());
  EXPECT_NO_THROW(segmentation.setMaxTrials(300));
  EXPECT_NO_THROW(segmentation.getParameters().validate());
  // Likewise object_separation_hold <= object_separation_ratio (3 by default).
  EXPECT_NO_THROW(segmentation.setObjectSeparationHold(4.0f));
  EXPECT_THROW(segmentation.segment(segments), std::invalid_argument);
  EXPECT_NO_THROW(segmentation.setObjectSeparationRatio(5.0f));
  EXPECT_NO_THROW(segmentation.getParameters().validate());
}

} // namespace
