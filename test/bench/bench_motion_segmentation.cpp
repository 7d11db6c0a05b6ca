// SPDX-License-Identifier: BSD-3-Clause
// Per-frame cost of the rigid motion segmentation stages at VGA (1200 cells, h_max 20).
#include <dynvo/io/frame.h>
#include <dynvo/motion_segmentation/patch_match.h>
#include <dynvo/motion_segmentation/pixel_label_refinement.h>
#include <dynvo/motion_segmentation/rigid_motion_segmentation.h>
#include <dynvo/scene_flow/grid_scene_flow_estimation.h>
#include <dynvo/synth/scene_synthesizer.h>

#include <pcl/point_types.h>

#include <benchmark/benchmark.h>

#include <vector>

namespace {

using Point = pcl::PointXYZRGB;

/// One VGA frame of static_two (static camera, two moving boxes) with its flow from k-1.
struct FlowFrame {
  pcl::PointCloud<Point>::Ptr cloud;
  pcl::PointCloud<dynvo::PointFlow>::Ptr flow;
};

/// Frames 1..FRAMES of static_two with and without the Kinect depth model, made once
/// (rendering and scene flow are not timed).
constexpr int FRAMES = 12;

const std::vector<FlowFrame>&
sequence(bool noise)
{
  static const auto make = [](bool with_noise) {
    dynvo::SynthOptions options;
    options.scenario = "static_two";
    options.frames = FRAMES + 1;
    options.noise = with_noise;
    const dynvo::SceneSynthesizer synth(options);
    dynvo::GridSceneFlowEstimation<Point> estimation;
    estimation.setCameraIntrinsics(synth.intrinsics());
    std::vector<FlowFrame> frames;
    for (int k = 0; k <= FRAMES; ++k) {
      const dynvo::SynthFrame frame = synth.render(k);
      FlowFrame f;
      f.cloud = dynvo::makeOrganizedCloud(frame.color, frame.depth, synth.intrinsics());
      f.flow.reset(new pcl::PointCloud<dynvo::PointFlow>);
      estimation.shiftCurrentToPrevious();
      estimation.setInputCloud(f.cloud);
      if (k > 0) {
        estimation.compute(*f.flow);
        frames.push_back(f);
      }
    }
    return frames;
  };
  static const std::vector<FlowFrame> clean = make(false);
  static const std::vector<FlowFrame> noisy = make(true);
  return noise ? noisy : clean;
}

/// The cell geometry of a frame's flow.
dynvo::FlowGrid
gridOf(const FlowFrame& frame)
{
  dynvo::FlowGrid grid;
  dynvo::FlowGrid::fromFlow(*frame.flow, frame.cloud->width, frame.cloud->height, grid);
  return grid;
}

/// §3 alone (hypotheses, refinement, DBSCAN, labelling) on plain buffers. Arg: noise.
void
BM_SpatialSegmentation(benchmark::State& state)
{
  const std::vector<FlowFrame>& frames = sequence(state.range(0) == 1);
  const dynvo::RigidMotionSegmentationParameters params;
  std::vector<dynvo::GridFlowData> grids(frames.size());
  for (std::size_t k = 0; k < frames.size(); ++k) {
    grids[k].assign(*frames[k].flow, gridOf(frames[k]));
    grids[k].setSensorNoise(params.noise, 525.0f, 1.0f, 1.0f);
  }
  dynvo::SpatialSegmenter segmenter;
  dynvo::SpatialSegmentationResult result;
  std::size_t k = 0;
  for (auto _ : state) {
    segmenter.segment(grids[k++ % grids.size()], params, result);
    benchmark::DoNotOptimize(result.labels.data());
  }
}
BENCHMARK(BM_SpatialSegmentation)
    ->ArgName("noise")
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

/// RigidMotionSegmentation::segment() per frame, including the pixel indices.
/// Args: noise, tracking, threads.
void
BM_RigidMotionSegmentation(benchmark::State& state)
{
  const std::vector<FlowFrame>& frames = sequence(state.range(0) == 1);
  dynvo::RigidMotionSegmentation<Point> segmentation;
  segmentation.setTracking(state.range(1) == 1);
  segmentation.setNumberOfThreads(static_cast<unsigned>(state.range(2)));
  std::vector<pcl::PointIndices> segments;
  std::size_t k = 0;
  for (auto _ : state) {
    const FlowFrame& frame = frames[k++ % frames.size()];
    segmentation.setInputCloud(frame.cloud);
    segmentation.setInputFlow(frame.flow);
    segmentation.segment(segments);
    benchmark::DoNotOptimize(segments.data());
  }
}
BENCHMARK(BM_RigidMotionSegmentation)
    ->ArgNames({"noise", "tracking", "threads"})
    ->Args({0, 0, 1})
    ->Args({1, 0, 1})
    ->Args({0, 1, 1})
    ->Args({1, 1, 1})
    ->Args({0, 0, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

/// §4-§6 alone: matching, guard, compensation, model update and read-out (the two-frame
/// segmentations are computed beforehand). Arg: noise.
void
BM_SegmentTracking(benchmark::State& state)
{
  const std::vector<FlowFrame>& frames = sequence(state.range(0) == 1);
  const dynvo::RigidMotionSegmentationParameters params;
  const dynvo::CameraIntrinsics intrinsics;
  std::vector<dynvo::GridFlowData> grids(frames.size());
  std::vector<dynvo::SpatialSegmentationResult> spatial(frames.size());
  dynvo::SpatialSegmenter segmenter;
  for (std::size_t k = 0; k < frames.size(); ++k) {
    grids[k].assign(*frames[k].flow, gridOf(frames[k]));
    grids[k].setSensorNoise(params.noise, 525.0f, 1.0f, 1.0f);
    segmenter.segment(grids[k], params, spatial[k]);
  }
  dynvo::SegmentTracker tracker;
  std::size_t k = 0;
  for (auto _ : state) {
    const std::size_t f = k++ % frames.size();
    tracker.update(grids[f], spatial[f], Eigen::Matrix4d::Identity(), intrinsics,
                   params);
    benchmark::DoNotOptimize(tracker.labels().data());
  }
}
BENCHMARK(BM_SegmentTracking)
    ->ArgName("noise")
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

/// §6.1 alone: cell labels to pixel labels (fill and per-pixel boundaries) on the tracked
/// output of segment() for each frame (computed beforehand). Arg: noise.
void
BM_PixelLabelRefinement(benchmark::State& state)
{
  const std::vector<FlowFrame>& frames = sequence(state.range(0) == 1);
  dynvo::RigidMotionSegmentation<Point> segmentation;
  std::vector<dynvo::FlowGrid> cells(frames.size());
  std::vector<std::vector<std::uint8_t>> model(frames.size());
  std::vector<pcl::PointIndices> segments;
  for (std::size_t k = 0; k < frames.size(); ++k) {
    segmentation.setInputCloud(frames[k].cloud);
    segmentation.setInputFlow(frames[k].flow);
    segmentation.segment(segments);
    cells[k] = segmentation.getCellGrid();
    model[k] = segmentation.getTracker().modelLabels();
  }
  const std::size_t stride = sizeof(Point) / sizeof(float);
  dynvo::PixelLabelRefinement refinement;
  std::vector<std::uint8_t> pixels;
  std::size_t k = 0;
  for (auto _ : state) {
    const std::size_t f = k++ % frames.size();
    const pcl::PointCloud<Point>& cloud = *frames[f].cloud;
    refinement.refine(cells[f], model[f], &cloud[0].z, stride, &cloud[0].rgba, stride,
                      pixels);
    benchmark::DoNotOptimize(pixels.data());
  }
}
BENCHMARK(BM_PixelLabelRefinement)
    ->ArgName("noise")
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

/// §4.1 alone: the ambiguity test of one far cell (r_amb 3 px: 49 positions around the
/// background's, 9 around the track) between consecutive noisy frames, over every cell of a
/// frame in turn. Its cost per frame is this times the far cells of the object segments.
void
BM_TrackIsAmbiguous(benchmark::State& state)
{
  const std::vector<FlowFrame>& frames = sequence(true);
  const pcl::PointCloud<Point>& previous = *frames[0].cloud;
  const pcl::PointCloud<Point>& current = *frames[1].cloud;
  const dynvo::FramePairColours colours{&previous[0].rgba, &current[0].rgba,
                                        sizeof(Point) / sizeof(float),
                                        static_cast<int>(current.width),
                                        static_cast<int>(current.height)};
  const pcl::PointCloud<dynvo::PointFlow>& flow = *frames[1].flow;
  std::size_t k = 0;
  for (auto _ : state) {
    const dynvo::PointFlow& cell = flow[k++ % flow.size()];
    const Eigen::Vector2f centre(cell.u, cell.v);
    benchmark::DoNotOptimize(dynvo::trackIsAmbiguous(
        colours, centre, centre, centre + Eigen::Vector2f(12.0f, 0.0f), 3));
  }
}
BENCHMARK(BM_TrackIsAmbiguous)->Unit(benchmark::kMicrosecond);

} // namespace
