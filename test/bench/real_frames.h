// SPDX-License-Identifier: BSD-3-Clause
// The real frames the benchmarks run on: the first frames of the shared tum_fr1_xyz_200 clip.
#pragma once

#include <dynvo/common/image.h>
#include <dynvo/io/tum_folder_source.h>

#include <benchmark/benchmark.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace dynvo::bench {

/// Frames 0..FRAMES-1 of the shared fr1/xyz clip, loaded once (PNG decoding is not timed).
constexpr std::size_t FRAMES = 30;

inline const std::vector<Frame>&
frames()
{
  static const std::vector<Frame> loaded = [] {
    std::vector<Frame> result;
    const std::string folder = std::string(DYNVO_SHARED_DATA_DIR) + "/tum_fr1_xyz_200";
    if (!std::filesystem::exists(folder + "/rgb.txt"))
      return result;
    TumFolderSource::Options options;
    options.intrinsics = CameraIntrinsics::fromPreset("fr1");
    const TumFolderSource source(folder, options);
    for (std::size_t k = 0; k < FRAMES && k < source.size(); ++k)
      result.push_back(source.read(k));
    return result;
  }();
  return loaded;
}

/// A frame's grey levels (luma of its cloud's colours), row-major, as the pipeline reads them.
inline std::vector<std::uint8_t>
greyOf(const Frame& frame)
{
  std::vector<std::uint8_t> grey;
  grey.reserve(frame.cloud->size());
  for (const auto& p : *frame.cloud)
    grey.push_back(luma(p.r, p.g, p.b));
  return grey;
}

/// Frame order 0, 1, ..., N-1, N-2, ..., 1, 0, 1, ...: every step is a real consecutive pair.
inline std::size_t
pingPong(std::size_t step, std::size_t n)
{
  const std::size_t period = 2 * (n - 1);
  const std::size_t phase = step % period;
  return phase < n ? phase : period - phase;
}

/// Marks the benchmark skipped when the clip is not there.
inline bool
skipWithoutData(benchmark::State& state)
{
  if (frames().size() >= 2)
    return false;
  state.SkipWithError("tum_fr1_xyz_200 not found under DYNVO_SHARED_DATA_DIR");
  return true;
}

} // namespace dynvo::bench
