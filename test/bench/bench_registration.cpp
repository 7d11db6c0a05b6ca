// SPDX-License-Identifier: BSD-3-Clause
// Per-frame cost of the registration's direct step at VGA on real TUM fr1/xyz frames.
#include "real_frames.h"

#include <dynvo/common/image.h>
#include <dynvo/registration/direct_odometry.h>

#include <benchmark/benchmark.h>

#include <cstdint>
#include <utility>
#include <vector>

namespace {

using dynvo::bench::frames;
using dynvo::bench::pingPong;
using dynvo::bench::skipWithoutData;

/// A frame's grey levels and depths as the scene flow hands them to the registration.
struct GreyDepth {
  std::vector<std::uint8_t> grey;
  std::vector<float> depth;
};

const std::vector<GreyDepth>&
greyDepths()
{
  static const std::vector<GreyDepth> made = [] {
    std::vector<GreyDepth> result;
    for (const dynvo::Frame& frame : frames()) {
      GreyDepth& out = result.emplace_back();
      out.grey = dynvo::bench::greyOf(frame);
      for (const pcl::PointXYZRGB& p : *frame.cloud)
        out.depth.push_back(p.z);
    }
    return result;
  }();
  return made;
}

/// The direct step (docs/algorithm.md §7.7) per frame as the pipeline runs it: the frame's
/// pyramids, the previous frame's samples, then two alignments to it (the step and its refit
/// on the keyframe fit's cells), every cell static. The guess is the identity (fr1/xyz moves
/// 1-4 px per frame here), where the pipeline starts from the flow's estimate. Arg: threads
/// of the alignments' residuals.
void
BM_DirectOdometryPerFrame(benchmark::State& state)
{
  if (skipWithoutData(state))
    return;
  const dynvo::CameraIntrinsics intrinsics = dynvo::CameraIntrinsics::fromPreset("fr1");
  const dynvo::StaticMaskRegistrationParameters parameters;
  const auto threads = static_cast<unsigned>(state.range(0));
  const auto width = frames()[0].cloud->width, height = frames()[0].cloud->height;
  dynvo::FlowGrid cells(width, height, 16);
  cells.labels.assign(cells.size(), dynvo::LABEL_STATIC);
  dynvo::detail::DirectFrame frame_a, frame_b;
  dynvo::detail::DirectFrame* previous = &frame_a;
  dynvo::detail::DirectFrame* current = &frame_b;
  const auto fill = [&](dynvo::detail::DirectFrame& frame, std::size_t k) {
    frame.resize(static_cast<int>(width), static_cast<int>(height));
    frame.assign(greyDepths()[k].grey.data(), greyDepths()[k].depth.data());
    frame.buildPyramid();
  };
  fill(*previous, 0);
  const std::size_t n = frames().size();
  std::size_t step = 0;
  std::size_t failed = 0;
  for (auto _ : state) {
    fill(*current, pingPong(++step, n));
    Eigen::Matrix4f guess = Eigen::Matrix4f::Identity(), T;
    for (int fit = 0; fit < 2; ++fit) {
      if (dynvo::detail::estimateDirectOdometry(*current, cells, *previous, cells,
                                                intrinsics, parameters, guess, threads,
                                                T))
        guess = T;
      else
        ++failed;
    }
    benchmark::DoNotOptimize(guess.data());
    std::swap(previous, current);
  }
  if (failed > 0)
    state.SkipWithError("an alignment failed");
}
BENCHMARK(BM_DirectOdometryPerFrame)
    ->ArgName("threads")
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

} // namespace
