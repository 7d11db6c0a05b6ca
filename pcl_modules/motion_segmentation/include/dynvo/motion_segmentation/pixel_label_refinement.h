// SPDX-License-Identifier: BSD-3-Clause
// Cell labels to pixel labels: filling cells without a track, per-pixel boundaries (docs/algorithm.md §6.1).
#pragma once

#include <dynvo/common/export.h>
#include <dynvo/common/flow_grid.h>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace dynvo {

/** \brief Turns the per-cell labels of the segmentation into one label per pixel with depth
 * (docs/algorithm.md §6.1).
 *
 * 1. Cell fill. Cells with at least one pixel with depth but label 0 (no valid track, or no
 *    measurement this frame) are filled breadth-first from the labelled cells: first through
 *    4-neighbours whose reference depth is continuous (relative difference at most
 *    depth_tolerance of the nearer); then a cell still without a label takes its fallback
 *    label (the compensated dual model's read-out, §5-§6) when non-zero, and the continuous
 *    spreading runs again; last, the rest take the label of their labelled 4-neighbour of
 *    closest reference depth. A cell's reference depth is its centre pixel's, else the mean
 *    of its central 5x5 pixels with depth, else the mean of all its pixels with depth. Only a
 *    frame without any labelled cell leaves cells with depth at 0.
 * 2. Pixels. A cell whose 8 neighbours all carry its own label (or 0) gives that label to
 *    its pixels with depth. In a boundary cell (a neighbour with another label) each pixel
 *    with depth takes the label of the cell among its own and its 8 neighbours (labelled,
 *    with a reference depth) that minimises
 *    `((z - z_n(u, v)) / (depth_tolerance z))^2 + (distance to c_n / w_grid)^2 +
 *    colour_weight ((I - I_n) / 255)^2`, z_n(u, v) being cell n's reference depth
 *    extrapolated to the pixel with its depth gradient (from its continuous 4-neighbours of
 *    the same label), I the pixel's and I_n cell n's centre grey level (mean of r, g, b):
 *    a depth discontinuity separates an object from what lies behind it, proximity decides
 *    on one continuous surface.
 * 3. Pixels without depth get 0. Pixels right of or below the last full cell belong to the
 *    nearest cell.
 *
 * Plain buffers; one thread; not thread-safe.
 * \code
 * dynvo::PixelLabelRefinement refinement;
 * std::vector<std::uint8_t> pixel_labels;
 * const std::size_t stride = sizeof(PointT) / sizeof(float);
 * refinement.refine(cell_grid, model_labels, &(*cloud)[0].z, stride, &(*cloud)[0].rgba,
 *                   stride, pixel_labels);
 * \endcode
 */
class DYNVO_EXPORTS PixelLabelRefinement {
public:
  /// Knobs of the refinement.
  struct DYNVO_EXPORTS Parameters {
    /// Relative depth difference (of the nearer depth) above which two cells or a pixel and
    /// a cell are discontinuous; 0.05 = tau_edge of §1.2. In (0, 1].
    float depth_tolerance = 0.05f;
    /// Weight of the grey-level difference in a boundary pixel's cost; 0 = depth and
    /// distance only. In [0, 100].
    float colour_weight = 1.0f;

    /// \throws std::invalid_argument when a field is out of its range
    void validate() const;
  };

  /// Name used in error prefixes: "PixelLabelRefinement".
  static const char* getClassName() { return "PixelLabelRefinement"; }

  /// \throws std::invalid_argument when parameters.validate() fails
  void setParameters(const Parameters& parameters);

  const Parameters& getParameters() const { return params_; }

  /** \brief Labels every pixel with depth.
   * \param[in] cells grid geometry and the output label of each cell (0 none)
   * \param[in] fallback_labels per cell, the label a cell without one and without a
   *            depth-continuous labelled neighbour takes (the dual model's read-out); empty =
   *            none
   * \param[in] depth z of pixel 0 (metres; NaN or <= 0 = no depth); pixel i's z is
   *            depth[i * depth_stride]
   * \param[in] depth_stride floats from one pixel's z to the next (1 for a depth image,
   *            sizeof(PointT) / 4 for a cloud's points)
   * \param[in] rgba packed colour of pixel 0 (PCL's rgba: b, g, r, a bytes), pixel i's at
   *            rgba[i * rgba_stride]; null to ignore colour
   * \param[in] rgba_stride 4-byte words from one pixel's colour to the next
   * \param[out] pixel_labels one label per pixel (row * width + col), 0 without depth
   * \throws std::invalid_argument when fallback_labels is neither empty nor one per cell
   */
  void refine(const FlowGrid& cells,
              const std::vector<std::uint8_t>& fallback_labels,
              const float* depth,
              std::size_t depth_stride,
              const std::uint32_t* rgba,
              std::size_t rgba_stride,
              std::vector<std::uint8_t>& pixel_labels);

  /// The cell labels after step 1 of the last refine().
  const std::vector<std::uint8_t>& getFilledCellLabels() const { return filled_; }

private:
  /// Reference depth, grey level and depth gradient of every cell (step 1's inputs).
  void computeCellDepths(const FlowGrid& cells,
                         const float* depth,
                         std::size_t depth_stride,
                         const std::uint32_t* rgba,
                         std::size_t rgba_stride);

  /// Step 1 on filled_.
  void fillCells(const FlowGrid& cells,
                 const std::vector<std::uint8_t>& fallback_labels);

  /// Depth gradients of the filled cells (along u and v, metres per pixel).
  void computeGradients(const FlowGrid& cells);

  /// True when two depths (metres, finite) differ by at most depth_tolerance of the nearer.
  bool continuous(float z_a, float z_b) const;

  Parameters params_;             ///< validated knobs
  std::vector<float> cell_depth_; ///< reference depth per cell (m), NaN without depth
  std::vector<float> cell_grey_;  ///< grey level at the cell centre (0-255)
  std::vector<float> gradient_u_; ///< dz/du per cell (m/px)
  std::vector<float> gradient_v_; ///< dz/dv per cell (m/px)
  std::vector<std::uint8_t> filled_; ///< cell labels after step 1
  std::vector<std::size_t> queue_;   ///< breadth-first scratch
};

} // namespace dynvo
