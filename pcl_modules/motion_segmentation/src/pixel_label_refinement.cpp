// SPDX-License-Identifier: BSD-3-Clause
// Cell labels to pixel labels (docs/algorithm.md §6.1).
#include <dynvo/motion_segmentation/pixel_label_refinement.h>
#include <dynvo/common/image.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace dynvo {

namespace {

/// True when a depth value is a measurement.
inline bool
hasDepth(float z)
{
  return std::isfinite(z) && z > 0.0f;
}

} // namespace

void
PixelLabelRefinement::Parameters::validate() const
{
  if (!(depth_tolerance > 0.0f && depth_tolerance <= 1.0f))
    throw std::invalid_argument("[dynvo::PixelLabelRefinement::Parameters::validate] "
                                "depth_tolerance must be in (0, 1], got " +
                                std::to_string(depth_tolerance));
  if (!(colour_weight >= 0.0f && colour_weight <= 100.0f))
    throw std::invalid_argument("[dynvo::PixelLabelRefinement::Parameters::validate] "
                                "colour_weight must be in [0, 100], got " +
                                std::to_string(colour_weight));
}

void
PixelLabelRefinement::setParameters(const Parameters& parameters)
{
  parameters.validate();
  params_ = parameters;
}

bool
PixelLabelRefinement::continuous(float z_a, float z_b) const
{
  return std::abs(z_a - z_b) <= params_.depth_tolerance * std::min(z_a, z_b);
}

void
PixelLabelRefinement::computeCellDepths(const FlowGrid& cells,
                                        const float* depth,
                                        std::size_t depth_stride,
                                        const std::uint32_t* rgba,
                                        std::size_t rgba_stride)
{
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const std::size_t width = cells.image_width;
  const std::size_t cell = cells.cell_size;
  cell_depth_.assign(cells.size(), nan);
  cell_grey_.assign(cells.size(), 0.0f);
  for (std::size_t i = 0; i < cells.size(); ++i) {
    const std::size_t centre = cells.centreIndex(i);
    if (rgba)
      cell_grey_[i] = lumaOfPacked(rgba[centre * rgba_stride]);
    const float z = depth[centre * depth_stride];
    if (hasDepth(z)) {
      cell_depth_[i] = z;
      continue;
    }
    // Central 5x5 first, then the whole cell: the nearer the centre, the likelier the
    // pixel lies on the surface the cell's track followed.
    const std::size_t left = i % cells.cols * cell, top = i / cells.cols * cell;
    const std::size_t half = std::min<std::size_t>(2, cell / 2);
    for (const std::size_t reach : {half, cell}) {
      const std::size_t u0 = reach == cell ? left : left + cell / 2 - half;
      const std::size_t v0 = reach == cell ? top : top + cell / 2 - half;
      const std::size_t n = reach == cell ? cell : 2 * half + 1;
      double sum = 0.0;
      std::size_t count = 0;
      for (std::size_t v = v0; v < v0 + n && v < top + cell; ++v)
        for (std::size_t u = u0; u < u0 + n && u < left + cell; ++u) {
          const float zp = depth[(v * width + u) * depth_stride];
          if (hasDepth(zp)) {
            sum += zp;
            ++count;
          }
        }
      if (count > 0) {
        cell_depth_[i] = static_cast<float>(sum / count);
        break;
      }
    }
  }
}

void
PixelLabelRefinement::fillCells(const FlowGrid& cells,
                                const std::vector<std::uint8_t>& fallback_labels)
{
  const std::size_t cols = cells.cols, rows = cells.rows;
  filled_ = cells.labels;
  // Breadth-first spreading from the labelled cells: first through depth-continuous
  // 4-neighbours only; then the dual model's label for the cells still without one, and
  // the continuous spreading again from those; last to any neighbour (closest reference
  // depth among the labelled 4-neighbours).
  enum class Pass { continuous, model, any };
  for (const Pass pass : {Pass::continuous, Pass::model, Pass::continuous, Pass::any}) {
    if (pass == Pass::model) {
      if (!fallback_labels.empty())
        for (std::size_t i = 0; i < filled_.size(); ++i)
          if (filled_[i] == LABEL_NONE && std::isfinite(cell_depth_[i]))
            filled_[i] = fallback_labels[i];
      continue;
    }
    const bool need_continuity = pass == Pass::continuous;
    queue_.clear();
    for (std::size_t i = 0; i < filled_.size(); ++i)
      if (filled_[i] != LABEL_NONE && std::isfinite(cell_depth_[i]))
        queue_.push_back(i);
    for (std::size_t head = 0; head < queue_.size(); ++head) {
      const std::size_t n = queue_[head];
      const std::size_t col = n % cols, row = n / cols;
      const std::size_t neighbours[4] = {
          col > 0 ? n - 1 : n, col + 1 < cols ? n + 1 : n, row > 0 ? n - cols : n,
          row + 1 < rows ? n + cols : n};
      for (const std::size_t m : neighbours) {
        if (m == n || filled_[m] != LABEL_NONE || !std::isfinite(cell_depth_[m]))
          continue;
        if (need_continuity && !continuous(cell_depth_[n], cell_depth_[m]))
          continue;
        if (!need_continuity) {
          // The labelled 4-neighbour of closest depth, not simply the first reached.
          float best = std::abs(cell_depth_[n] - cell_depth_[m]);
          std::size_t source = n;
          const std::size_t mc = m % cols, mr = m / cols;
          const std::size_t around[4] = {mc > 0 ? m - 1 : m, mc + 1 < cols ? m + 1 : m,
                                         mr > 0 ? m - cols : m,
                                         mr + 1 < rows ? m + cols : m};
          for (const std::size_t k : around)
            if (k != m && filled_[k] != LABEL_NONE && std::isfinite(cell_depth_[k]) &&
                std::abs(cell_depth_[k] - cell_depth_[m]) < best) {
              best = std::abs(cell_depth_[k] - cell_depth_[m]);
              source = k;
            }
          filled_[m] = filled_[source];
        }
        else {
          filled_[m] = filled_[n];
        }
        queue_.push_back(m);
      }
    }
  }
}

void
PixelLabelRefinement::computeGradients(const FlowGrid& cells)
{
  const std::size_t cols = cells.cols, rows = cells.rows;
  const float cell = static_cast<float>(cells.cell_size);
  gradient_u_.assign(cells.size(), 0.0f);
  gradient_v_.assign(cells.size(), 0.0f);
  // Central difference over the continuous neighbours of the same label, else one-sided.
  const auto slope = [&](std::size_t i, bool has_lo, std::size_t lo, bool has_hi,
                         std::size_t hi) {
    const auto usable = [&](bool has, std::size_t k) {
      return has && filled_[k] == filled_[i] && std::isfinite(cell_depth_[k]) &&
             continuous(cell_depth_[k], cell_depth_[i]);
    };
    const bool l = usable(has_lo, lo), h = usable(has_hi, hi);
    if (l && h)
      return (cell_depth_[hi] - cell_depth_[lo]) / (2.0f * cell);
    if (l)
      return (cell_depth_[i] - cell_depth_[lo]) / cell;
    if (h)
      return (cell_depth_[hi] - cell_depth_[i]) / cell;
    return 0.0f;
  };
  for (std::size_t i = 0; i < cells.size(); ++i) {
    if (filled_[i] == LABEL_NONE || !std::isfinite(cell_depth_[i]))
      continue;
    const std::size_t col = i % cols, row = i / cols;
    gradient_u_[i] = slope(i, col > 0, i - 1, col + 1 < cols, i + 1);
    gradient_v_[i] = slope(i, row > 0, i - cols, row + 1 < rows, i + cols);
  }
}

void
PixelLabelRefinement::refine(const FlowGrid& cells,
                             const std::vector<std::uint8_t>& fallback_labels,
                             const float* depth,
                             std::size_t depth_stride,
                             const std::uint32_t* rgba,
                             std::size_t rgba_stride,
                             std::vector<std::uint8_t>& pixel_labels)
{
  if (!fallback_labels.empty() && fallback_labels.size() != cells.size())
    throw std::invalid_argument("[dynvo::PixelLabelRefinement::refine] fallback_labels "
                                "must be empty or hold one "
                                "label per cell, got " +
                                std::to_string(fallback_labels.size()) + " for " +
                                std::to_string(cells.size()));
  const std::size_t width = cells.image_width, height = cells.image_height;
  pixel_labels.assign(width * height, LABEL_NONE);
  if (cells.size() == 0 || !depth)
    return;
  computeCellDepths(cells, depth, depth_stride, rgba, rgba_stride);
  fillCells(cells, fallback_labels);
  computeGradients(cells);

  const int cols = static_cast<int>(cells.cols), rows = static_cast<int>(cells.rows);
  const int cell = static_cast<int>(cells.cell_size);
  const float inv_cell2 = 1.0f / static_cast<float>(cell * cell);
  const float colour_weight = rgba ? params_.colour_weight / (255.0f * 255.0f) : 0.0f;
  const float inv_tol2 = 1.0f / (params_.depth_tolerance * params_.depth_tolerance);
  for (int row = 0; row < rows; ++row)
    for (int col = 0; col < cols; ++col) {
      const std::size_t i = static_cast<std::size_t>(row) * cols + col;
      // Pixel range of the cell; the last column and row of cells take the margins.
      const int u0 = col * cell, v0 = row * cell;
      const int u1 = col + 1 == cols ? static_cast<int>(width) : u0 + cell;
      const int v1 = row + 1 == rows ? static_cast<int>(height) : v0 + cell;
      // Candidate cells: the labelled ones of the 3x3 window with a reference depth, with
      // everything the per-pixel cost needs from them.
      struct Candidate {
        float u, v, z, gradient_u, gradient_v, grey;
        std::uint8_t label;
      } candidates[9];
      int count = 0;
      bool boundary = false;
      // The cell's own centre first: it is nearest to most of its pixels, so the distance
      // bound below skips most of the others.
      static constexpr int ORDER[9][2] = {{0, 0},   {-1, 0}, {1, 0},  {0, -1}, {0, 1},
                                          {-1, -1}, {1, -1}, {-1, 1}, {1, 1}};
      for (const auto& [dc, dr] : ORDER) {
        const int r = row + dr, c = col + dc;
        if (r < 0 || r >= rows || c < 0 || c >= cols)
          continue;
        const std::size_t k = static_cast<std::size_t>(r) * cols + c;
        if (filled_[k] == LABEL_NONE || !std::isfinite(cell_depth_[k]))
          continue;
        candidates[count++] = {static_cast<float>(c * cell + cell / 2),
                               static_cast<float>(r * cell + cell / 2),
                               cell_depth_[k],
                               gradient_u_[k],
                               gradient_v_[k],
                               cell_grey_[k],
                               filled_[k]};
        boundary = boundary || filled_[k] != filled_[i];
      }
      if (!boundary || count == 0) {
        const std::uint8_t label = filled_[i];
        if (label == LABEL_NONE)
          continue;
        for (int v = v0; v < v1; ++v) {
          const std::size_t first = static_cast<std::size_t>(v) * width;
          for (int u = u0; u < u1; ++u)
            if (hasDepth(depth[(first + u) * depth_stride]))
              pixel_labels[first + u] = label;
        }
        continue;
      }
      for (int v = v0; v < v1; ++v)
        for (int u = u0; u < u1; ++u) {
          const std::size_t p = static_cast<std::size_t>(v) * width + u;
          const float z = depth[p * depth_stride];
          if (!hasDepth(z))
            continue;
          const float grey = rgba ? lumaOfPacked(rgba[p * rgba_stride]) : 0.0f;
          const float inv_z2 = inv_tol2 / (z * z);
          const float fu = static_cast<float>(u), fv = static_cast<float>(v);
          float best = std::numeric_limits<float>::infinity();
          std::uint8_t label = LABEL_NONE;
          for (int n = 0; n < count; ++n) {
            const Candidate& k = candidates[n];
            const float du = fu - k.u, dv = fv - k.v;
            const float distance = (du * du + dv * dv) * inv_cell2;
            if (distance >= best) // the other terms only add to it
              continue;
            const float dz = z - (k.z + k.gradient_u * du + k.gradient_v * dv);
            const float dg = grey - k.grey;
            const float cost = distance + dz * dz * inv_z2 + colour_weight * dg * dg;
            if (cost < best) {
              best = cost;
              label = k.label;
            }
          }
          pixel_labels[p] = label;
        }
    }
}

} // namespace dynvo
