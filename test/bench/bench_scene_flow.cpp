// SPDX-License-Identifier: BSD-3-Clause
// Per-frame cost of the grid scene flow stage at VGA on real TUM fr1/xyz frames.
#include "real_frames.h"

#include <dynvo/common/lens_undistortion.h>
#include <dynvo/scene_flow/depth_preprocessing.h>
#include <dynvo/scene_flow/grid_scene_flow_estimation.h>

#include <pcl/point_types.h>

#include <benchmark/benchmark.h>

#include <algorithm>
#include <memory>
#include <vector>

namespace {

using dynvo::bench::frames;
using dynvo::bench::pingPong;
using dynvo::bench::skipWithoutData;

/// The whole stage per frame as a sequence runs it: depth preprocessing, one grey pyramid,
/// forward LK, the forward-backward check and back-projection. Arg: thread count.
void
BM_GridSceneFlowPerFrame(benchmark::State& state)
{
  if (skipWithoutData(state))
    return;
  dynvo::GridSceneFlowEstimation<pcl::PointXYZRGB> estimation;
  estimation.setCameraIntrinsics(dynvo::CameraIntrinsics::fromPreset("fr1"));
  estimation.setNumberOfThreads(static_cast<unsigned>(state.range(0)));
  if (state.range(1) == 1)
    estimation.setForwardBackwardCheck(dynvo::ForwardBackwardCheck::full);
  pcl::PointCloud<dynvo::PointFlow> flow;
  const std::size_t n = frames().size();
  std::size_t step = 0;
  estimation.setInputCloud(frames()[0].cloud);
  for (auto _ : state) {
    estimation.shiftCurrentToPrevious();
    estimation.setInputCloud(frames()[pingPong(++step, n)].cloud);
    estimation.compute(flow);
    benchmark::DoNotOptimize(flow.points.data());
  }
  state.SetLabel(state.range(1) == 1 ? "fb=full" : "fb=local");
}
BENCHMARK(BM_GridSceneFlowPerFrame)
    ->ArgNames({"threads", "full_fb"})
    ->Args({1, 0})
    ->Args({2, 0})
    ->Args({1, 1})
    ->Args({2, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(2.0)
    // The 2 cores are shared: with --benchmark_repetitions the minimum is the figure least
    // disturbed by other processes, next to the median.
    ->ComputeStatistics("min", [](const std::vector<double>& v) {
      return *std::min_element(v.begin(), v.end());
    });

/// The flow to a keyframe (docs/algorithm.md §7.3) that the pipeline adds per frame: frame 0
/// is the keyframe, frames 1-5 are tracked into it on the finest level from their own
/// positions (the seed a static camera gives; fr1/xyz moves 1-4 px over these frames, within
/// the reach of a good prediction).
/// Frame preparation is not timed here (BM_GridSceneFlowPerFrame has it). Arg: thread count.
void
BM_KeyframeFlowPerFrame(benchmark::State& state)
{
  if (skipWithoutData(state))
    return;
  dynvo::GridSceneFlowEstimation<pcl::PointXYZRGB> estimation;
  estimation.setCameraIntrinsics(dynvo::CameraIntrinsics::fromPreset("fr1"));
  estimation.setNumberOfThreads(static_cast<unsigned>(state.range(0)));
  pcl::PointCloud<dynvo::PointFlow> flow;
  estimation.setPreviousCloud(frames()[1].cloud);
  estimation.setInputCloud(frames()[0].cloud);
  estimation.compute(flow);
  estimation.setCurrentAsKeyframe();
  const std::size_t n = std::min<std::size_t>(frames().size() - 1, 5);
  std::size_t step = 0;
  for (auto _ : state) {
    state.PauseTiming();
    estimation.shiftCurrentToPrevious();
    estimation.setInputCloud(frames()[1 + step++ % n].cloud);
    estimation.compute(flow);
    state.ResumeTiming();
    estimation.computeToKeyframe(Eigen::Matrix4f::Identity(), 0, dynvo::FlowGrid(),
                                 flow);
    benchmark::DoNotOptimize(flow.points.data());
  }
}
BENCHMARK(BM_KeyframeFlowPerFrame)
    ->ArgNames({"threads"})
    ->Args({1})
    ->Args({2})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(1.0);

/// Depth preprocessing alone (docs/algorithm.md §1.1) on one VGA depth map. Arg: thread count.
void
BM_DepthPreprocessing(benchmark::State& state)
{
  if (skipWithoutData(state))
    return;
  dynvo::DepthPreprocessing preprocessing;
  preprocessing.setNumberOfThreads(static_cast<unsigned>(state.range(0)));
  const dynvo::DepthImage& depth = frames()[1].depth;
  std::vector<float> out;
  for (auto _ : state) {
    preprocessing.apply(depth.data, depth.width, depth.height, out);
    benchmark::DoNotOptimize(out.data());
  }
}
BENCHMARK(BM_DepthPreprocessing)
    ->ArgName("threads")
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

/// Undistorting one VGA frame's colour and depth through the fr1 lens, as TumFolderSource does
/// before the pipeline (docs/algorithm.md §0); outside the pipeline's timers.
void
BM_LensUndistortion(benchmark::State& state)
{
  if (skipWithoutData(state))
    return;
  const dynvo::Frame& frame = frames()[1];
  const dynvo::LensUndistortion lens(dynvo::CameraIntrinsics::fromPreset("fr1"),
                                     frame.color.width, frame.color.height);
  for (auto _ : state) {
    state.PauseTiming();
    dynvo::ColorImage color = frame.color;
    dynvo::DepthImage depth = frame.depth;
    state.ResumeTiming();
    lens.undistort(color, depth);
    benchmark::DoNotOptimize(depth.data.data());
  }
}
BENCHMARK(BM_LensUndistortion)->Unit(benchmark::kMillisecond)->UseRealTime();

} // namespace
