// SPDX-License-Identifier: BSD-3-Clause
// The one cell geometry of a grid scene flow, with one label per cell
// (docs/algorithm.md §1.2).
#pragma once

#include <dynvo/common/conventions.h>
#include <dynvo/common/export.h>
#include <dynvo/common/point_types.h>

#include <pcl/point_cloud.h>

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace dynvo {

/** \brief The cell grid of a grid scene flow over an organized image, plus one label per
 * cell; the modules pass it between them instead of working the geometry out each.
 *
 * Cell i = row * cols + col covers the pixels [col * cell_size, (col + 1) * cell_size) x
 * [row * cell_size, (row + 1) * cell_size) of the current image and is centred on
 * c_i = (col, row) * cell_size + cell_size / 2 (integer division), where
 * GridSceneFlowEstimation tracks it. Pixels right of or below the last full cell belong to
 * no cell. The cell size is never configured twice: every module infers it from its input
 * (fromFlow()).
 *
 * Labels follow the label convention: LABEL_NONE (0) no measurement or not selected,
 * LABEL_STATIC (1) static, 2.. moving objects.
 * \code
 * dynvo::FlowGrid grid;
 * if (dynvo::FlowGrid::fromFlow(*flow, cloud->width, cloud->height, grid))
 *   grid.labels[i] = dynvo::LABEL_STATIC;  // e.g. select cell i
 * \endcode
 */
struct DYNVO_EXPORTS FlowGrid {
  std::uint32_t image_width = 0;    ///< columns of the image the grid covers (px)
  std::uint32_t image_height = 0;   ///< rows of the image the grid covers (px)
  std::uint32_t cell_size = 0;      ///< w_grid (px); 0 for an empty grid
  std::uint32_t cols = 0;           ///< Gx = image_width / cell_size
  std::uint32_t rows = 0;           ///< Gy = image_height / cell_size
  std::vector<std::uint8_t> labels; ///< one label per cell, cell i = row * cols + col

  FlowGrid() = default;

  /// The grid of cell_size px cells (> 0) over an image, every label LABEL_NONE.
  FlowGrid(std::uint32_t width, std::uint32_t height, std::uint32_t cell)
      : image_width(width)
      , image_height(height)
      , cell_size(cell)
      , cols(width / cell)
      , rows(height / cell)
      , labels(static_cast<std::size_t>(cols) * rows, LABEL_NONE)
  {
  }

  /** \brief True when the cell size can be recovered from the image width and the number
   * of columns, as fromFlow() does: width / (width / cell_size) == cell_size (every cell size
   * up to 25 px on a 640 px wide image), and the grid has at least one cell.
   */
  bool isInferable() const
  {
    return cols > 0 && rows > 0 && image_width / cols == cell_size;
  }

  /** \brief The grid of a flow computed on a width x height image: cell size
   * width / flow.width (integer division, see isInferable()), labels LABEL_NONE.
   * \return false (grid untouched) when the flow is not organized or is not the
   *         (width / cell) x (height / cell) grid of that cell size
   */
  static bool fromFlow(const pcl::PointCloud<PointFlow>& flow,
                       std::uint32_t width,
                       std::uint32_t height,
                       FlowGrid& grid)
  {
    if (!flow.isOrganized() || flow.width == 0 || width < flow.width)
      return false;
    const FlowGrid inferred(width, height, width / flow.width);
    if (inferred.cols != flow.width || inferred.rows != flow.height)
      return false;
    grid = inferred;
    return true;
  }

  /// Number of cells.
  std::size_t size() const { return static_cast<std::size_t>(cols) * rows; }

  /// True when the other grid has the same geometry (labels aside).
  bool sameGeometry(const FlowGrid& other) const
  {
    return image_width == other.image_width && image_height == other.image_height &&
           cell_size == other.cell_size;
  }

  /// Centre c_i of cell i (px, current image).
  Eigen::Vector2f centre(std::size_t i) const
  {
    return {static_cast<float>(i % cols * cell_size + cell_size / 2),
            static_cast<float>(i / cols * cell_size + cell_size / 2)};
  }

  /// Linear index (row * image_width + col) of the centre pixel of cell i.
  std::size_t centreIndex(std::size_t i) const
  {
    return (i / cols * cell_size + cell_size / 2) * image_width + i % cols * cell_size +
           cell_size / 2;
  }

  /// The cell holding a pixel (linear index), or size() for a pixel in no cell.
  std::size_t cellOfPixel(std::size_t index) const
  {
    const std::size_t col = index % image_width / cell_size;
    const std::size_t row = index / image_width / cell_size;
    return col < cols && row < rows ? row * cols + col : size();
  }

  /// Calls f(index) for every pixel of cell i, row by row (linear indices).
  template <typename F> void forEachPixel(std::size_t i, F&& f) const
  {
    const std::size_t left = i % cols * cell_size;
    const std::size_t top = i / cols * cell_size;
    for (std::size_t v = top; v < top + cell_size; ++v)
      for (std::size_t u = left; u < left + cell_size; ++u)
        f(v * image_width + u);
  }
};

} // namespace dynvo
