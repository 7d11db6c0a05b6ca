// SPDX-License-Identifier: BSD-3-Clause
// Two-frame rigid motion segmentation (docs/algorithm.md §3) on synthetic flow grids.
#include <dynvo/motion_segmentation/spatial_segmentation.h>

#include "support/pose_compare.h"
#include "support/synthetic_flow.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <numeric>
#include <random>
#include <vector>

namespace {

using dynvo::test::FlowRegion;
using dynvo::test::makeMotion;

constexpr int COLS = 40; // 1200 cells, as VGA with 16 px cells
constexpr int ROWS = 30;
constexpr int CELL = 4; // 160 x 120 image

dynvo::CameraIntrinsics
smallIntrinsics()
{
  dynvo::CameraIntrinsics K; // the "default" preset scaled to 160 x 120
  K.fx = K.fy = 525.0 / 4.0;
  K.cx = 79.5;
  K.cy = 59.5;
  return K;
}

/// The paper's metric model. These flows are noise-free 160 x 120 grids whose motions
/// differ by 3-5 cm; the sensor model's 0.6 px tracking error at f = 131 px is 4.6 mm per
/// metre of depth, a 4-sigma radius of 3 cm at 1.2 m, which is meant for real tracking.
dynvo::RigidMotionSegmentationParameters
paperModel()
{
  dynvo::RigidMotionSegmentationParameters params;
  params.residual_model = dynvo::ResidualModel::paper;
  return params;
}

dynvo::SpatialSegmentationResult
segmentFlow(const dynvo::test::SyntheticFlow& synthetic,
            const dynvo::RigidMotionSegmentationParameters& params = paperModel())
{
  dynvo::GridFlowData grid;
  const auto& flow = *synthetic.flow;
  grid.assign(flow, dynvo::FlowGrid(flow.width * CELL, flow.height * CELL, CELL));
  if (params.residual_model == dynvo::ResidualModel::sensor)
    grid.setSensorNoise(params.noise, static_cast<float>(smallIntrinsics().fx), 1.0f,
                        1.0f);
  dynvo::SpatialSegmenter segmenter;
  dynvo::SpatialSegmentationResult result;
  segmenter.segment(grid, params, result);
  return result;
}

/// Segment (1..g) with the largest cell IoU against region `id`, and that IoU.
std::pair<int, double>
bestSegment(const dynvo::SpatialSegmentationResult& result,
            const std::vector<int>& truth,
            int id)
{
  std::pair<int, double> best{0, 0.0};
  for (int c = 1; c <= result.segmentCount(); ++c) {
    const double iou =
        dynvo::test::cellIoU(result.labels, static_cast<std::uint8_t>(c), truth, id);
    if (iou > best.second)
      best = {c, iou};
  }
  return best;
}

/// Camera moving forward and panning, plus two boxes with their own motions.
struct TwoObjects {
  Eigen::Matrix4d T_background = makeMotion({0, 1, 0}, 0.01, {0.01, 0.0, -0.02});
  std::vector<FlowRegion> regions;
  TwoObjects()
  {
    FlowRegion box1{4, 6, 14, 16, 1.2, makeMotion({0, 0, 1}, 0.05, {0.04, 0.01, 0.0}),
                    2};
    FlowRegion box2{
        24, 12, 34, 24, 1.6, makeMotion({1, 1, 0}, 0.03, {-0.03, 0.0, 0.02}), 3};
    regions = {box1, box2};
  }
};

TEST(SpatialSegmentation, TwoRigidMotionsAndBackgroundAreRecovered)
{
  const TwoObjects scene;
  const auto synthetic = dynvo::test::makeSyntheticFlow(
      COLS, ROWS, CELL, smallIntrinsics(), scene.T_background, scene.regions);
  const dynvo::SpatialSegmentationResult result = segmentFlow(synthetic);
  ASSERT_EQ(result.segmentCount(), 3);
  const std::vector<Eigen::Matrix4d> truth_motions = {
      scene.T_background, scene.regions[0].T_curr_prev, scene.regions[1].T_curr_prev};
  for (int id = 1; id <= 3; ++id) {
    const auto [segment, iou] = bestSegment(result, synthetic.truth, id);
    SCOPED_TRACE("region " + std::to_string(id));
    EXPECT_GE(iou, 0.9);
    ASSERT_GT(segment, 0);
    // Noise-free input: the fit is exact up to float rounding of the points (~1e-7 m at 3 m).
    const Eigen::Matrix4d& H = result.motions[segment - 1];
    EXPECT_LT(dynvo::test::translationError(H, truth_motions[id - 1]), 1e-3);
    EXPECT_LT(dynvo::test::rotationError(H, truth_motions[id - 1]),
              dynvo::test::radians(0.1));
  }
  // The background is the largest segment.
  EXPECT_EQ(bestSegment(result, synthetic.truth, 1).first, 1);
}

TEST(SpatialSegmentation, OneObjectSeenInTwoRegionsIsOneSegment)
{
  const Eigen::Matrix4d T_object = makeMotion({0, 0, 1}, 0.04, {0.03, -0.02, 0.01});
  // Two disjoint patches of the same rigid object (e.g. split by an occluder).
  const std::vector<FlowRegion> regions = {{3, 4, 11, 12, 1.3, T_object, 2},
                                           {28, 16, 37, 26, 1.3, T_object, 2}};
  const auto synthetic = dynvo::test::makeSyntheticFlow(
      COLS, ROWS, CELL, smallIntrinsics(), Eigen::Matrix4d::Identity(), regions);
  const dynvo::SpatialSegmentationResult result = segmentFlow(synthetic);
  ASSERT_EQ(result.segmentCount(), 2);
  EXPECT_GE(bestSegment(result, synthetic.truth, 2).second, 0.9);
}

TEST(SpatialSegmentation, PureNoiseFlowGivesNoLargeSegment)
{
  // Every cell gets its own random 3 cm displacement: no 7 neighbours share a rigid motion
  // within the 5.5 mm inlier radius.
  const auto synthetic = dynvo::test::makeSyntheticFlow(
      COLS, ROWS, CELL, smallIntrinsics(), Eigen::Matrix4d::Identity(), {}, 0.03, 7);
  const dynvo::RigidMotionSegmentationParameters params = paperModel();
  const dynvo::SpatialSegmentationResult result = segmentFlow(synthetic, params);
  for (const int size : result.sizes)
    EXPECT_LE(size, params.min_segment_size);
}

TEST(SpatialSegmentation, StaticFlowGivesOneSegment)
{
  const Eigen::Matrix4d T_camera = makeMotion({1, 0, 0}, 0.02, {0.0, 0.01, 0.03});
  for (const double sigma : {0.0, 0.001}) {
    SCOPED_TRACE("noise sigma " + std::to_string(sigma));
    const auto synthetic = dynvo::test::makeSyntheticFlow(
        COLS, ROWS, CELL, smallIntrinsics(), T_camera, {}, sigma, 3);
    const dynvo::SpatialSegmentationResult result = segmentFlow(synthetic);
    ASSERT_EQ(result.segmentCount(), 1);
    // 1 mm noise per axis: |noise|^2 ~ 3e-6 m^2, 10 sigma under th_inlier = 3e-5, so every
    // cell is an inlier.
    EXPECT_EQ(result.sizes[0], COLS * ROWS);
    EXPECT_LT(dynvo::test::translationError(result.motions[0], T_camera), 1e-3);
  }
}

TEST(SpatialSegmentation, TooFewValidCellsGiveNoSegment)
{
  auto synthetic = dynvo::test::makeSyntheticFlow(COLS, ROWS, CELL, smallIntrinsics(),
                                                  Eigen::Matrix4d::Identity(), {});
  const dynvo::RigidMotionSegmentationParameters params;
  // Keep 2 m - 1 valid cells: below the 2 m of docs/algorithm.md §3.
  for (std::size_t i = 2 * params.sample_size - 1; i < synthetic.flow->size(); ++i)
    (*synthetic.flow)[i].valid_3d = 0;
  const dynvo::SpatialSegmentationResult result = segmentFlow(synthetic, params);
  EXPECT_EQ(result.segmentCount(), 0);
  EXPECT_EQ(std::count(result.labels.begin(), result.labels.end(), 0),
            static_cast<long>(COLS * ROWS));
}

TEST(SpatialSegmentation, SameSeedSameResult)
{
  const TwoObjects scene;
  const auto synthetic = dynvo::test::makeSyntheticFlow(
      COLS, ROWS, CELL, smallIntrinsics(), scene.T_background, scene.regions, 0.002, 5);
  dynvo::RigidMotionSegmentationParameters params;
  params.seed = 42;
  const auto one = segmentFlow(synthetic, params);
  const auto again = segmentFlow(synthetic, params);
  EXPECT_EQ(one.labels, again.labels);
  EXPECT_EQ(one.trials, again.trials);
  ASSERT_EQ(one.motions.size(), again.motions.size());
  for (std::size_t c = 0; c < one.motions.size(); ++c)
    EXPECT_TRUE(one.motions[c] == again.motions[c]); // bit-identical
}

TEST(SpatialSegmentation, MotionFieldDistanceOfTwoTranslations)
{
  // Two pure translations 4 mm apart move every point 4 mm apart.
  const std::vector<Eigen::Vector3d> a = {{0, 0, 1}, {1, 0, 2}, {0, 1, 3}};
  dynvo::MotionHypothesis x, y;
  x.T_curr_prev = makeMotion({0, 0, 1}, 0.0, {0.01, 0.0, 0.0});
  y.T_curr_prev = makeMotion({0, 0, 1}, 0.0, {0.01, 0.004, 0.0});
  x.inliers = {0, 1};
  y.inliers = {1, 2};
  EXPECT_NEAR(dynvo::motionFieldDistance(x, y, a, {}), 0.004, 1e-12);
  // A rotation by 0.01 rad about the optical axis moves the points of the union {0, 2}
  // by 0.01 * |(x, y)|, i.e. by 0 and 0.01 m: RMS = sqrt((0 + 1e-4) / 2).
  y.T_curr_prev = makeMotion({0, 0, 1}, 0.01, {0.01, 0.0, 0.0});
  x.inliers = {0};
  y.inliers = {2};
  EXPECT_NEAR(dynvo::motionFieldDistance(x, y, a, {}), std::sqrt(1e-4 / 2.0), 1e-6);
}

/// The neighbour test of items on a line at the given positions (|x_i - x_j| <= epsilon),
/// counting its calls.
struct LineNeighbours {
  std::vector<double> positions;
  double epsilon;
  int calls = 0;
  std::function<bool(int, int)> test()
  {
    return [this](int i, int j) {
      ++calls;
      return std::abs(positions[i] - positions[j]) <= epsilon;
    };
  }
};

TEST(Dbscan, MinPointsOneGivesConnectedComponents)
{
  // Chain 0-1-2 (steps of 4 <= eps 5), isolated 3, pair 4-5; 0 and 2 are 8 apart but linked.
  LineNeighbours line{{0, 4, 8, 30, 60, 63}, 5.0};
  const std::vector<int> clusters = dynvo::dbscan(6, 1, line.test());
  EXPECT_EQ(clusters, (std::vector<int>{0, 0, 0, 1, 2, 2}));
}

TEST(Dbscan, MinPointsOneAsksNoPairAlreadyJoined)
{
  // Five items within eps of each other: 0-1, 0-2, 0-3, 0-4 join all of them, and none of
  // the six pairs among 1-4 is asked.
  LineNeighbours line{{0, 1, 2, 3, 4}, 5.0};
  EXPECT_EQ(dynvo::dbscan(5, 1, line.test()), (std::vector<int>(5, 0)));
  EXPECT_EQ(line.calls, 4);
}

TEST(Dbscan, MinPointsOneFindsTheComponentsOfRandomGraphs)
{
  // The union-find's components against label propagation (each item takes the smallest
  // label among its neighbours' until nothing changes) on random graphs of 2-21 items.
  std::mt19937 rng(7);
  for (int round = 0; round < 50; ++round) {
    const int n = 2 + static_cast<int>(rng() % 20);
    std::vector<char> edge(static_cast<std::size_t>(n) * n, 0);
    for (int i = 0; i < n; ++i)
      for (int j = i + 1; j < n; ++j)
        edge[i * n + j] = edge[j * n + i] = rng() % 7 == 0;
    std::vector<int> label(n);
    std::iota(label.begin(), label.end(), 0);
    for (bool changed = true; changed;) {
      changed = false;
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j)
          if (edge[i * n + j] && label[j] < label[i]) {
            label[i] = label[j];
            changed = true;
          }
    }
    std::vector<int> expected(n), id(n, -1);
    int next = 0;
    for (int i = 0; i < n; ++i)
      expected[i] = id[label[i]] < 0 ? (id[label[i]] = next++) : id[label[i]];
    EXPECT_EQ(dynvo::dbscan(n, 1,
                            [&](int i, int j) {
                              return edge[i * n + j] != 0;
                            }),
              expected);
  }
}

TEST(Dbscan, MinPointsMarksNoiseAndBorderPoints)
{
  // With min_points 3, only item 1 (neighbours 0, 1, 2) is core; 0 and 2 are border points
  // of its cluster; 3, 4 and 5 are noise. Each of the 15 pairs is tested once.
  LineNeighbours line{{0, 4, 8, 30, 60, 63}, 5.0};
  const std::vector<int> clusters = dynvo::dbscan(6, 3, line.test());
  EXPECT_EQ(clusters, (std::vector<int>{0, 0, 0, -1, -1, -1}));
  EXPECT_EQ(line.calls, 15);
  EXPECT_TRUE(dynvo::dbscan(0, 1, line.test()).empty());
}

} // namespace
