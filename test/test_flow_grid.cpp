// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/common/flow_grid.h>

#include <gtest/gtest.h>

#include <vector>

namespace {

TEST(FlowGrid, GeometryOfAVgaGrid)
{
  const dynvo::FlowGrid grid(640, 480, 16);
  EXPECT_EQ(grid.cols, 40u);
  EXPECT_EQ(grid.rows, 30u);
  EXPECT_EQ(grid.size(), 1200u);
  EXPECT_TRUE(grid.isInferable());
  // Cell 41 = (col 1, row 1): pixels [16, 32) x [16, 32), centre (24, 24).
  EXPECT_EQ(grid.centre(41), Eigen::Vector2f(24.0f, 24.0f));
  EXPECT_EQ(grid.centreIndex(41), 24u * 640u + 24u);
  EXPECT_EQ(grid.cellOfPixel(16 * 640 + 31), 41u);
  EXPECT_EQ(grid.cellOfPixel(15 * 640 + 31), 1u);
  std::vector<std::size_t> pixels;
  grid.forEachPixel(41, [&](std::size_t index) {
    pixels.push_back(index);
  });
  ASSERT_EQ(pixels.size(), 256u);
  EXPECT_EQ(pixels.front(), 16u * 640u + 16u);
  EXPECT_EQ(pixels.back(), 31u * 640u + 31u);
  for (const std::size_t index : pixels)
    EXPECT_EQ(grid.cellOfPixel(index), 41u);
}

TEST(FlowGrid, PixelsBeyondTheLastFullCellBelongToNone)
{
  const dynvo::FlowGrid grid(100, 70,
                             16); // 6 x 4 cells, 4 columns and 6 rows left over
  EXPECT_EQ(grid.cellOfPixel(99), grid.size());
  EXPECT_EQ(grid.cellOfPixel(69 * 100), grid.size());
  EXPECT_EQ(grid.cellOfPixel(95), 5u);
}

TEST(FlowGrid, TheCellSizeIsInferredFromTheFlow)
{
  const pcl::PointCloud<dynvo::PointFlow> flow(40, 30);
  dynvo::FlowGrid grid;
  ASSERT_TRUE(dynvo::FlowGrid::fromFlow(flow, 640, 480, grid));
  EXPECT_EQ(grid.cell_size, 16u);
  EXPECT_EQ(grid.labels, std::vector<std::uint8_t>(1200, dynvo::LABEL_NONE));
  // 40 x 40 cells of 16 px would need 640 rows; a grid wider than the image has no cell size.
  EXPECT_FALSE(dynvo::FlowGrid::fromFlow(pcl::PointCloud<dynvo::PointFlow>(40, 40), 640,
                                         480, grid));
  EXPECT_FALSE(dynvo::FlowGrid::fromFlow(pcl::PointCloud<dynvo::PointFlow>(700, 30),
                                         640, 480, grid));
  EXPECT_EQ(grid.cell_size, 16u); // untouched by the failures
  // 50 px cells on 640 px leave 40 columns over, more than the 12 cells: 640 / 12 = 53.
  EXPECT_FALSE(dynvo::FlowGrid(640, 480, 50).isInferable());
}

} // namespace
