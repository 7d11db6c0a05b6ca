// SPDX-License-Identifier: BSD-3-Clause
// Grey patches of two consecutive frames compared in place (docs/algorithm.md §4.1).
#include <dynvo/motion_segmentation/patch_match.h>

#include <dynvo/common/image.h>

#include <array>
#include <cmath>
#include <limits>
#include <vector>

namespace dynvo {

namespace {

constexpr int HALF = 4;            ///< patch half side (px)
constexpr int SIDE = 2 * HALF + 1; ///< patch side (px)
constexpr int AREA = SIDE * SIDE;  ///< pixels of a patch

/// Grey levels of the side x side square of `rgba` centred on (x, y), row by row; false
/// when it leaves the image.
bool
readSquare(const FramePairColours& colours,
           const std::uint32_t* rgba,
           int x,
           int y,
           int side,
           float* out)
{
  const int x0 = x - side / 2, y0 = y - side / 2;
  if (x0 < 0 || y0 < 0 || x0 + side > colours.width || y0 + side > colours.height)
    return false;
  for (int row = 0; row < side; ++row) {
    const std::size_t first = static_cast<std::size_t>(y0 + row) * colours.width + x0;
    for (int col = 0; col < side; ++col)
      out[row * side + col] = lumaOfPacked(rgba[(first + col) * colours.stride]);
  }
  return true;
}

/// Smallest mean zero-mean squared difference between the zero-mean patch `a` and the
/// patches at every position of the side x side square `region`.
float
bestMatch(const std::array<float, AREA>& a, const std::vector<float>& region, int side)
{
  float best = std::numeric_limits<float>::infinity();
  for (int oy = 0; oy + SIDE <= side; ++oy)
    for (int ox = 0; ox + SIDE <= side; ++ox) {
      const float* b = &region[static_cast<std::size_t>(oy) * side + ox];
      float mean = 0.0f;
      for (int row = 0; row < SIDE; ++row)
        for (int col = 0; col < SIDE; ++col)
          mean += b[row * side + col];
      mean /= AREA;
      float sum = 0.0f;
      for (int row = 0; row < SIDE; ++row)
        for (int col = 0; col < SIDE; ++col) {
          const float d = a[row * SIDE + col] - (b[row * side + col] - mean);
          sum += d * d;
        }
      best = std::min(best, sum / AREA);
    }
  return best;
}

} // namespace

bool
trackIsAmbiguous(const FramePairColours& colours,
                 const Eigen::Vector2f& centre,
                 const Eigen::Vector2f& track,
                 const Eigen::Vector2f& other,
                 int radius)
{
  if (colours.empty() || radius < 0 || !centre.allFinite() || !track.allFinite() ||
      !other.allFinite())
    return false;
  const auto pixel = [](float v) {
    return static_cast<int>(std::lround(v));
  };
  std::array<float, AREA> a;
  if (!readSquare(colours, colours.current, pixel(centre.x()), pixel(centre.y()), SIDE,
                  a.data()))
    return false;
  float mean = 0.0f;
  for (const float v : a)
    mean += v;
  mean /= AREA;
  for (float& v : a)
    v -= mean;
  const int own_side = SIDE + 2, other_side = SIDE + 2 * radius;
  std::vector<float> own(static_cast<std::size_t>(own_side) * own_side),
      elsewhere(static_cast<std::size_t>(other_side) * other_side);
  if (!readSquare(colours, colours.previous, pixel(track.x()), pixel(track.y()),
                  own_side, own.data()) ||
      !readSquare(colours, colours.previous, pixel(other.x()), pixel(other.y()),
                  other_side, elsewhere.data()))
    return false;
  return bestMatch(a, elsewhere, other_side) <=
         AMBIGUITY_FACTOR * bestMatch(a, own, own_side);
}

} // namespace dynvo
