// SPDX-License-Identifier: BSD-3-Clause
// The grid's Lucas-Kanade on real TUM fr1/xyz frame pairs: OpenCV's cv::calcOpticalFlowPyrLK
// against dynvo's trackLucasKanade, which returns the same tracks bit for bit.
#include "../../pcl_modules/scene_flow/src/lucas_kanade.h"
#include "real_frames.h"

#include <opencv2/core/utility.hpp>
#include <opencv2/video/tracking.hpp>

#include <benchmark/benchmark.h>

#include <vector>

namespace {

using dynvo::bench::frames;
using dynvo::bench::pingPong;
using dynvo::bench::skipWithoutData;

/// The LK pyramids (window 16, levels 0-2, with derivatives) of the benchmark's frames.
const std::vector<std::vector<cv::Mat>>&
pyramids()
{
  static const std::vector<std::vector<cv::Mat>> built = [] {
    std::vector<std::vector<cv::Mat>> result;
    for (const dynvo::Frame& frame : frames()) {
      std::vector<std::uint8_t> grey = dynvo::bench::greyOf(frame);
      const cv::Mat image(static_cast<int>(frame.cloud->height),
                          static_cast<int>(frame.cloud->width), CV_8UC1, grey.data());
      result.emplace_back();
      cv::buildOpticalFlowPyramid(image, result.back(), cv::Size(16, 16), 2, true);
    }
    return result;
  }();
  return built;
}

/// One frame pair as the grid tracks it: the 1200 cell centres forward through 3 levels,
/// then the local backward check (the finest level, from the centres). Arg: 0 OpenCV, 1 ours
/// with 128-bit kernels, 2 ours with the widest kernels the CPU has.
void
BM_LucasKanadeFramePair(benchmark::State& state)
{
  if (skipWithoutData(state))
    return;
  std::vector<cv::Point2f> centres;
  for (int row = 0; row < 30; ++row)
    for (int col = 0; col < 40; ++col)
      centres.emplace_back(col * 16 + 8.0f, row * 16 + 8.0f);
  dynvo::detail::LucasKanadeSettings forward;
  forward.wide = state.range(0) == 2;
  dynvo::detail::LucasKanadeSettings backward = forward;
  backward.max_level = 0;
  const cv::TermCriteria criteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS,
                                  forward.max_iterations, forward.epsilon);
  const std::size_t n = pyramids().size();
  // One thread, as the grid runs each of its stripes (OpenCV would share one call out).
  const int threads = cv::getNumThreads();
  cv::setNumThreads(1);
  std::vector<std::uint8_t> status;
  // The implementation the argument names, from the guesses in `out`.
  const auto track = [&](const std::vector<cv::Mat>& from_pyramid,
                         const std::vector<cv::Mat>& to_pyramid,
                         const std::vector<cv::Point2f>& points,
                         const dynvo::detail::LucasKanadeSettings& s,
                         std::vector<cv::Point2f>& out) {
    if (state.range(0) == 0)
      cv::calcOpticalFlowPyrLK(from_pyramid, to_pyramid, points, out, status,
                               cv::noArray(), cv::Size(s.window, s.window), s.max_level,
                               criteria, cv::OPTFLOW_USE_INITIAL_FLOW,
                               s.min_eigen_threshold);
    else
      dynvo::detail::trackLucasKanade(from_pyramid, to_pyramid, points, s, out, status);
  };
  std::vector<cv::Point2f> tracked, back;
  std::size_t step = 0;
  for (auto _ : state) {
    const auto& from = pyramids()[pingPong(step + 1, n)];
    const auto& to = pyramids()[pingPong(step, n)];
    ++step;
    tracked = centres;
    track(from, to, centres, forward, tracked);
    back = centres;
    track(to, from, tracked, backward, back);
    benchmark::DoNotOptimize(back.data());
  }
  cv::setNumThreads(threads);
  state.SetLabel(state.range(0) == 0   ? "opencv"
                 : state.range(0) == 1 ? "ours 128-bit"
                                       : "ours widest");
}
BENCHMARK(BM_LucasKanadeFramePair)
    ->ArgNames({"impl"})
    ->Arg(0)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

} // namespace
