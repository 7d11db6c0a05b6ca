// SPDX-License-Identifier: BSD-3-Clause
// Deterministic, band-limited procedural textures and counter-based random numbers
// (private to dynvo_synth; inline because they run once or more per pixel).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace dynvo::detail {

/// 32-bit integer finaliser (good avalanche, cheap).
inline std::uint32_t
mix32(std::uint32_t h)
{
  h ^= h >> 16;
  h *= 0x7feb352dU;
  h ^= h >> 15;
  h *= 0x846ca68bU;
  h ^= h >> 16;
  return h;
}

/// SplitMix64 step: a counter-based generator (the n-th value is splitMix64(key + n)).
inline std::uint64_t
splitMix64(std::uint64_t x)
{
  x += 0x9E3779B97F4A7C15ULL;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ULL;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBULL;
  return x ^ (x >> 31);
}

/// Hash of an integer lattice point for one texture layer.
inline std::uint32_t
latticeHash(std::int32_t x, std::int32_t y, std::uint32_t salt)
{
  return mix32(static_cast<std::uint32_t>(x) * 0x9E3779B1U +
               static_cast<std::uint32_t>(y) * 0x85EBCA77U + salt);
}

/// Quintic fade: zero first and second derivatives at the lattice points.
inline float
quinticFade(float t)
{
  return t * t * t * (t * (t * 6.0f - 15.0f) + 10.0f);
}

/// Lattice cell of (x, y) with the faded interpolation weights.
struct LatticeCell {
  std::int32_t ix, iy;
  float sx, sy;

  LatticeCell(float x, float y)
  {
    const float fx = std::floor(x), fy = std::floor(y);
    ix = static_cast<std::int32_t>(fx);
    iy = static_cast<std::int32_t>(fy);
    sx = quinticFade(x - fx);
    sy = quinticFade(y - fy);
  }

  float blend(float v00, float v10, float v01, float v11) const
  {
    const float bottom = v00 + sx * (v10 - v00);
    const float top = v01 + sx * (v11 - v01);
    return bottom + sy * (top - bottom);
  }
};

/// Scalar value noise in [0, 1], smooth (C2) in x and y (lattice units).
inline float
valueNoise(float x, float y, std::uint32_t salt)
{
  constexpr float TO_UNIT = 1.0f / 16777216.0f;
  const LatticeCell c(x, y);
  return c.blend(static_cast<float>(latticeHash(c.ix, c.iy, salt) >> 8) * TO_UNIT,
                 static_cast<float>(latticeHash(c.ix + 1, c.iy, salt) >> 8) * TO_UNIT,
                 static_cast<float>(latticeHash(c.ix, c.iy + 1, salt) >> 8) * TO_UNIT,
                 static_cast<float>(latticeHash(c.ix + 1, c.iy + 1, salt) >> 8) *
                     TO_UNIT);
}

/// Colour value noise: three independent channels in [0, 1] from one hash per corner.
inline void
colourNoise(float x, float y, std::uint32_t salt, float rgb[3])
{
  constexpr float TO_UNIT = 1.0f / 1023.0f;
  const LatticeCell c(x, y);
  const std::uint32_t h[4] = {
      latticeHash(c.ix, c.iy, salt), latticeHash(c.ix + 1, c.iy, salt),
      latticeHash(c.ix, c.iy + 1, salt), latticeHash(c.ix + 1, c.iy + 1, salt)};
  for (int channel = 0; channel < 3; ++channel) {
    const int shift = 10 * channel;
    rgb[channel] = c.blend(static_cast<float>((h[0] >> shift) & 1023U) * TO_UNIT,
                           static_cast<float>((h[1] >> shift) & 1023U) * TO_UNIT,
                           static_cast<float>((h[2] >> shift) & 1023U) * TO_UNIT,
                           static_cast<float>((h[3] >> shift) & 1023U) * TO_UNIT);
  }
}

/** \brief Level-of-detail weight of a layer: 1 when its lattice spans at least 3 px,
 * fading to 0 at 1.5 px, so no layer finer than the pixel grid can alias.
 * \param[in] lattice lattice spacing (metres)
 * \param[in] footprint pixel footprint on the surface (metres)
 */
inline float
detailWeight(float lattice, float footprint)
{
  return std::clamp((lattice / footprint - 1.5f) / 1.5f, 0.0f, 1.0f);
}

/// A textured face's albedo is its base colour times ALBEDO_FLOOR + ALBEDO_SPAN x (colour
/// patches in [0, 1], 0.5 on average) times a luminance gain (1 on average).
constexpr float ALBEDO_FLOOR = 0.35f;
constexpr float ALBEDO_SPAN = 0.65f;
/// The base colour's mean share over a textured face: a plain face's share.
constexpr float MEAN_ALBEDO = ALBEDO_FLOOR + 0.5f * ALBEDO_SPAN;

/** \brief Albedo of a textured surface at face coordinates (x, y) in metres.
 * \param[in] base the surface's base colour (linear, [0, 1])
 * \param[in] salt the surface's texture seed
 * \param[in] footprint pixel footprint (metres) for the level of detail
 * \param[out] rgb albedo in [0, 1]
 */
inline void
surfaceAlbedo(float x,
              float y,
              const float base[3],
              std::uint32_t salt,
              float footprint,
              float rgb[3])
{
  constexpr float COARSE = 0.35f, MID = 0.09f;
  constexpr int OCTAVES = 4;
  constexpr float LATTICE[OCTAVES] = {0.048f, 0.024f, 0.012f, 0.006f};
  constexpr float AMPLITUDE[OCTAVES] = {0.5f, 0.35f, 0.25f, 0.18f};

  float coarse[3], mid[3];
  colourNoise(x * (1.0f / COARSE), y * (1.0f / COARSE), salt, coarse);
  colourNoise(x * (1.0f / MID), y * (1.0f / MID), salt ^ 0x5bd1e995U, mid);
  const float w_coarse = detailWeight(COARSE, footprint);
  const float w_mid = detailWeight(MID, footprint);

  float luminance = 0.0f;
  for (int octave = 0; octave < OCTAVES; ++octave) {
    const float weight = detailWeight(LATTICE[octave], footprint);
    if (weight == 0.0f)
      break; // every finer octave has faded out as well
    const float inv = 1.0f / LATTICE[octave];
    luminance +=
        AMPLITUDE[octave] * weight *
        (valueNoise(x * inv, y * inv, salt + 0x632be5abU * (octave + 1)) - 0.5f);
  }
  const float gain = 1.0f + 1.6f * luminance;
  for (int channel = 0; channel < 3; ++channel) {
    const float patches = 0.6f * (0.5f + w_coarse * (coarse[channel] - 0.5f)) +
                          0.4f * (0.5f + w_mid * (mid[channel] - 0.5f));
    rgb[channel] = std::clamp(
        base[channel] * (ALBEDO_FLOOR + ALBEDO_SPAN * patches) * gain, 0.0f, 1.0f);
  }
}

} // namespace dynvo::detail
