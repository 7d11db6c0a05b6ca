// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/scene_flow/depth_preprocessing.h>

#include <dynvo/common/parallel.h>
#include <dynvo/common/vectorize.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace dynvo {

namespace {

constexpr float NaN = std::numeric_limits<float>::quiet_NaN();
/// docs/algorithm.md §1.1: the 3x3 median is trusted only with at least 5 valid neighbours.
constexpr int MIN_FLYING_NEIGHBOURS = 5;

/// Fills the gap between valid samples l and r (exclusive) of a line with stride `step`.
void
fillGap(float* line, std::size_t l, std::size_t r, std::size_t step)
{
  const float zl = line[l * step];
  const float zr = line[r * step];
  const float span = static_cast<float>(r - l);
  for (std::size_t k = l + 1; k < r; ++k)
    line[k * step] = zl + (zr - zl) * static_cast<float>(k - l) / span;
}

/// Throws std::invalid_argument unless map holds width * height values.
void
requireSize(const std::vector<float>& map,
            std::uint32_t width,
            std::uint32_t height,
            const char* where)
{
  if (map.size() != static_cast<std::size_t>(width) * height)
    throw std::invalid_argument(std::string("[dynvo::DepthPreprocessing::") + where +
                                "] the map holds " + std::to_string(map.size()) +
                                " values, expected " + std::to_string(width) + "x" +
                                std::to_string(height));
}

bool
similar(float zl, float zr, float tolerance)
{
  return std::abs(zl - zr) <= tolerance * std::min(zl, zr);
}

/// The depth kept at a pixel of in-range depth z (NaN: none) given its in-range neighbours
/// n[0..count): NaN when it flies off their median m, i.e. when m < z lo_factor or
/// m > z hi_factor (see apply()). Branch-free, so that rows vectorise.
inline float
keepPixel(float z, const float* n, int count, float lo_factor, float hi_factor)
{
  const float lo = z * lo_factor;
  const float hi = z * hi_factor;
  int valid = 0, below = 0, above = 0;
  for (int j = 0; j < count; ++j) {
    valid += n[j] == n[j];
    below += n[j] < lo;
    above += n[j] > hi;
  }
  const int k = valid / 2; // index of the median in the sorted valid neighbours
  const bool flying =
      (valid >= MIN_FLYING_NEIGHBOURS) & ((below >= k + 1) | (above >= valid - k));
  return flying ? NaN : z; // NaN stays NaN
}

/** For the pixels of row y of a column stripe: where a valid pixel closes a gap of 1 to
 * max_gap rows below its column's last valid row, gap_from = that row (else -1); then
 * last = y where the pixel is valid. Returns how many close a gap (branch-free).
 */
DYNVO_VECTORIZE_FOR_AVX2 int
markClosingGaps(
    const float* row, std::size_t cols, int y, int max_gap, int* last, int* gap_from)
{
  int closing = 0;
  for (std::size_t x = 0; x < cols; ++x) {
    const bool valid = row[x] == row[x];
    const int l = last[x];
    const int gap = y - l - 1;
    const bool closes = valid & (gap >= 1) & (gap <= max_gap);
    gap_from[x] = closes ? l : -1;
    closing += closes;
    last[x] = valid ? y : l;
  }
  return closing;
}

/// keepPixel() on the pixels 1..w-2 of a row, from the in-range rows above, at and below it.
DYNVO_VECTORIZE_FOR_AVX2 void
keepInteriorRow(const float* up,
                const float* mid,
                const float* down,
                float* dst,
                std::size_t w,
                float lo_factor,
                float hi_factor)
{
  for (std::size_t x = 1; x + 1 < w; ++x) {
    const float n[8] = {up[x - 1],  up[x],       up[x + 1], mid[x - 1],
                        mid[x + 1], down[x - 1], down[x],   down[x + 1]};
    dst[x] = keepPixel(mid[x], n, 8, lo_factor, hi_factor);
  }
}

} // namespace

const ParameterTable<DepthPreprocessing::Parameters>&
DepthPreprocessing::Parameters::table()
{
  using P = Parameters;
  static_assert(AGGREGATE_FIELD_COUNT<P> == 5, "every field of P needs a row below");
  static const ParameterTable<P> table(std::vector<ParameterTable<P>::Field>{
      makeField("min_depth", &P::min_depth, FieldRange::above(0), "z_min, metres"),
      makeField("max_depth", &P::max_depth, FieldRange::above(0),
                "z_max, metres, > min_depth"),
      makeField("flying_pixel_tolerance", &P::flying_pixel_tolerance,
                FieldRange{0, 1, true, true}, "tau_fly, relative"),
      makeField("max_hole_width", &P::max_hole_width, FieldRange::atLeast(0),
                "w_hole, px, 0 = no filling"),
      makeField("hole_fill_tolerance", &P::hole_fill_tolerance, FieldRange::atLeast(0),
                "tau_fill, relative"),
  });
  return table;
}

void
DepthPreprocessing::Parameters::validate() const
{
  const std::string prefix = "[dynvo::DepthPreprocessing::Parameters::validate]";
  table().checkAll(*this, prefix);
  if (!(max_depth > min_depth))
    throw std::invalid_argument(prefix +
                                " max_depth must be > min_depth, got min_depth " +
                                formatFieldValue(min_depth, true) + ", max_depth " +
                                formatFieldValue(max_depth, true));
}

DepthPreprocessing::DepthPreprocessing(const Parameters& parameters)
{
  setParameters(parameters);
}

void
DepthPreprocessing::setParameters(const Parameters& parameters)
{
  parameters.validate();
  params_ = parameters;
}

void
DepthPreprocessing::setNumberOfThreads(unsigned threads)
{
  if (threads == 0)
    throw std::invalid_argument("[dynvo::DepthPreprocessing::setNumberOfThreads] need "
                                "at least 1 thread, got 0");
  threads_ = threads;
}

void
DepthPreprocessing::apply(const std::vector<float>& depth,
                          std::uint32_t width,
                          std::uint32_t height,
                          std::vector<float>& out) const
{
  applyRows(depth, width, height, out);
  applyColumns(width, height, out);
}

void
DepthPreprocessing::applyRows(const std::vector<float>& depth,
                              std::uint32_t width,
                              std::uint32_t height,
                              std::vector<float>& out) const
{
  const std::size_t w = width;
  const std::size_t h = height;
  requireSize(depth, width, height, "applyRows");
  if (&depth == &out)
    throw std::invalid_argument("[dynvo::DepthPreprocessing::applyRows] out aliases depth");
  out.resize(w * h);

  // Steps 1 and 2 read only the input, so rows are independent. A depth outside [z_min, z_max]
  // is read as NaN (no depth), so that every comparison below is false on it. A neighbour q
  // counts when it is a number; "median < lo" and "median > hi" are decided by counting,
  // which avoids sorting (see the class doc for the median definition):
  //   |z - m| > tau m  <=>  m < z / (1 + tau)  or  m > z / (1 - tau)   (m > 0, tau < 1).
  const float z_min = params_.min_depth;
  const float z_max = params_.max_depth;
  const auto in_range = [z_min, z_max](float q) {
    return q >= z_min && q <= z_max ? q : NaN;
  };
  const float lo_factor = 1.0f / (1.0f + params_.flying_pixel_tolerance);
  const float hi_factor = 1.0f / (1.0f - params_.flying_pixel_tolerance);
  // Border pixels: gather the neighbours that exist.
  const auto border_pixel = [&](std::size_t x, std::size_t y) {
    float n[8];
    int count = 0;
    for (std::size_t yy = y > 0 ? y - 1 : y; yy <= std::min(y + 1, h - 1); ++yy)
      for (std::size_t xx = x > 0 ? x - 1 : x; xx <= std::min(x + 1, w - 1); ++xx)
        if (yy != y || xx != x)
          n[count++] = in_range(depth[yy * w + xx]);
    out[y * w + x] =
        keepPixel(in_range(depth[y * w + x]), n, count, lo_factor, hi_factor);
  };
  // Step 3's row pass on row y reads and writes row y only: it follows the row's step 2.
  const std::size_t max_gap = static_cast<std::size_t>(params_.max_hole_width);
  const float tau_fill = params_.hole_fill_tolerance;
  const auto fill_row = [&](std::size_t y) {
    float* line = out.data() + y * w;
    std::size_t last = w; // no valid pixel seen yet
    for (std::size_t x = 0; x < w; ++x) {
      if (std::isnan(line[x]))
        continue;
      if (last != w && x - last - 1 >= 1 && x - last - 1 <= max_gap &&
          similar(line[last], line[x], tau_fill))
        fillGap(line, last, x, 1);
      last = x;
    }
  };
  forEachStripe(h, threads_, [&](std::size_t row_begin, std::size_t row_end) {
    // The in-range depths of rows y - 1, y and y + 1, in a ring of three rows.
    std::vector<float> ring(3 * w);
    const auto row_in_range = [&](std::size_t y) {
      float* row = ring.data() + (y % 3) * w;
      const float* src = depth.data() + y * w;
      for (std::size_t x = 0; x < w; ++x)
        row[x] = in_range(src[x]);
    };
    for (std::size_t y = row_begin; y < row_end; ++y) {
      if (y == 0 || y + 1 == h || w < 3) {
        for (std::size_t x = 0; x < w; ++x)
          border_pixel(x, y);
        fill_row(y);
        continue;
      }
      if (y == row_begin || y - 1 == 0) {
        row_in_range(y - 1);
        row_in_range(y);
      }
      row_in_range(y + 1);
      border_pixel(0, y);
      const float* up = ring.data() + ((y - 1) % 3) * w;
      const float* mid = ring.data() + (y % 3) * w;
      const float* down = ring.data() + ((y + 1) % 3) * w;
      keepInteriorRow(up, mid, down, out.data() + y * w, w, lo_factor, hi_factor);
      border_pixel(w - 1, y);
      fill_row(y);
    }
  });
}

void
DepthPreprocessing::applyColumns(std::uint32_t width,
                                 std::uint32_t height,
                                 std::vector<float>& out) const
{
  const std::size_t w = width;
  const std::size_t h = height;
  requireSize(out, width, height, "applyColumns");
  const std::size_t max_gap = static_cast<std::size_t>(params_.max_hole_width);
  if (max_gap == 0)
    return;
  const float tau_fill = params_.hole_fill_tolerance;
  // Column pass on the row-filled map: stripes own column ranges and walk the rows in order,
  // remembering the last valid row of every column, which keeps memory access row-major. Each
  // row first marks the columns that close a gap (branch-free, vectorised), then fills those.
  // (A gap is shorter than h.)
  const int max_gap_rows = static_cast<int>(std::min(max_gap, h));
  forEachStripe(w, threads_, [&](std::size_t col_begin, std::size_t col_end) {
    const std::size_t cols = col_end - col_begin;
    // The last valid row of each column; before the first, one that makes any gap too wide.
    std::vector<int> last(cols, -max_gap_rows - 2);
    std::vector<int> gap_from(cols);
    for (std::size_t y = 0; y < h; ++y) {
      const float* row = out.data() + y * w + col_begin;
      const int yi = static_cast<int>(y);
      int closing =
          markClosingGaps(row, cols, yi, max_gap_rows, last.data(), gap_from.data());
      for (std::size_t x = 0; closing > 0 && x < cols; ++x) {
        const int l = gap_from[x];
        if (l < 0)
          continue;
        --closing;
        const std::size_t column = col_begin + x;
        if (similar(out[static_cast<std::size_t>(l) * w + column], row[x], tau_fill))
          fillGap(out.data() + column, static_cast<std::size_t>(l), y, w);
      }
    }
  });
}

} // namespace dynvo
