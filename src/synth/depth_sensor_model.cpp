// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/synth/depth_sensor_model.h>

#include "procedural_texture.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace dynvo {

namespace {

constexpr double TWO_PI = 6.28318530717958647692;
/// A point is shadowed when a point to its right lands this many projector columns
/// further left: keeps rounding on slanted planes from shadowing them.
constexpr float SHADOW_MARGIN_PX = 0.25f;

/// Uniform in [0, 1) from the top 24 bits.
double
uniform(std::uint64_t bits)
{
  return static_cast<double>(bits >> 40) / 16777216.0;
}

/// Projector shadows of one row (see DepthSensorModel step 1).
void
markShadowedRow(const SurfaceSample* row, int width, double fx, std::uint8_t* shadowed)
{
  const float disparity_scale = static_cast<float>(fx * DepthSensorModel::BASELINE);
  float smallest_right = std::numeric_limits<float>::infinity();
  for (int u = width - 1; u >= 0; --u) {
    const float z = row[u].z;
    if (!std::isfinite(z))
      continue;
    const float projector_column = static_cast<float>(u) - disparity_scale / z;
    shadowed[u] = projector_column > smallest_right + SHADOW_MARGIN_PX;
    smallest_right = std::min(smallest_right, projector_column);
  }
}

} // namespace

double
DepthSensorModel::axialSigma(double z)
{
  return SIGMA_CONSTANT + SIGMA_QUADRATIC * (z - SIGMA_OFFSET) * (z - SIGMA_OFFSET);
}

void
DepthSensorModel::measure(const std::vector<SurfaceSample>& samples,
                          int width,
                          int height,
                          double fx,
                          std::uint32_t seed,
                          int frame,
                          const std::vector<std::uint8_t>& mask,
                          std::vector<float>& depth)
{
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const std::size_t pixels = static_cast<std::size_t>(width) * height;
  if (mask.empty())
    depth.assign(pixels, nan);
  std::vector<std::uint8_t> shadowed(pixels, 0);
  for (int v = 0; v < height; ++v)
    markShadowedRow(&samples[static_cast<std::size_t>(v) * width], width, fx,
                    &shadowed[static_cast<std::size_t>(v) * width]);

  const std::uint64_t frame_key = detail::splitMix64(
      (static_cast<std::uint64_t>(seed) << 32) | static_cast<std::uint32_t>(frame));
  const float jump = static_cast<float>(EDGE_JUMP_RATIO);
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * width + u;
      if (!mask.empty() && mask[i] == 0)
        continue;
      depth[i] = nan;
      const SurfaceSample& s = samples[i];
      const float z = s.z;
      if (!(z >= MIN_DEPTH && z <= MAX_DEPTH) || shadowed[i])
        continue;
      const auto nearer = [&](std::size_t n) {
        return z - samples[n].z > jump * z;
      };
      if ((u > 0 && nearer(i - 1)) || (u + 1 < width && nearer(i + 1)) ||
          (v > 0 && nearer(i - width)) || (v + 1 < height && nearer(i + width)))
        continue;
      const std::uint64_t r1 = detail::splitMix64(frame_key + i);
      const std::uint64_t r2 = detail::splitMix64(r1);
      const std::uint64_t r3 = detail::splitMix64(r2);
      const double grazing = (s.cosine - GRAZING_COSINE_NONE) /
                             (GRAZING_COSINE_FULL - GRAZING_COSINE_NONE);
      const double returned = (s.dark ? DARK_RETURN_RATE : 1.0) *
                              std::clamp(grazing, 0.0, 1.0) * (1.0 - DROPOUT_RATE);
      if (uniform(r1) >= returned)
        continue;
      double noisy = z;
      if (uniform(r3) < SPECKLE_RATE) {
        noisy *= 1.0 + SPECKLE_ERROR * (2.0 * uniform(detail::splitMix64(r3)) - 1.0);
      }
      else {
        // Box-Muller from two 24-bit uniforms (u1 in (0, 1], so the log is finite).
        const double u1 = (static_cast<double>(r2 >> 40) + 1.0) / 16777216.0;
        const double u2 = static_cast<double>(r2 & 0xFFFFFFU) / 16777216.0;
        const double gauss = std::sqrt(-2.0 * std::log(u1)) * std::cos(TWO_PI * u2);
        const double sigma = axialSigma(z);
        const double step = INVERSE_DEPTH_STEP * z * z; // depth step at z (m)
        const double added =
            std::sqrt(std::max(sigma * sigma - step * step / 12.0, 0.0));
        noisy += added * gauss;
      }
      const double measured =
          1.0 / (std::round(1.0 / noisy / INVERSE_DEPTH_STEP) * INVERSE_DEPTH_STEP);
      if (measured >= MIN_DEPTH && measured <= MAX_DEPTH)
        depth[i] = static_cast<float>(measured);
    }
  }
}

} // namespace dynvo
