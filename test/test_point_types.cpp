// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/common/point_types.h>

#include <pcl/io/pcd_io.h>

#include <gtest/gtest.h>

#include "support/temp_dir.h"

#include <cmath>
#include <limits>

namespace {

TEST(PointFlow, SavesAndLoadsAsBinaryPcdWithEveryField)
{
  pcl::PointCloud<dynvo::PointFlow> grid(4, 3);
  for (std::size_t i = 0; i < grid.size(); ++i) {
    auto& p = grid[i];
    p.x = 0.1f * i;
    p.y = -0.2f * i;
    p.z = 1.0f + i;
    p.prev_x = 0.3f * i;
    p.prev_y = 0.4f;
    p.prev_z = 2.0f;
    p.u = 8.0f + 16.0f * (i % 4);
    p.v = 8.0f + 16.0f * (i / 4);
    p.prev_u = p.u + 0.25f;
    p.prev_v = p.v - 0.5f;
    p.weight = 0.5f;
    p.valid_2d = 1;
    p.valid_3d = static_cast<std::uint8_t>(i % 2);
  }
  grid[5].x = grid[5].y = grid[5].z = std::numeric_limits<float>::quiet_NaN();
  grid[5].weight = 0.0f;

  dynvo::test::TempDir dir;
  ASSERT_EQ(pcl::io::savePCDFileBinary(dir.file("flow.pcd"), grid), 0);
  pcl::PointCloud<dynvo::PointFlow> loaded;
  ASSERT_EQ(pcl::io::loadPCDFile(dir.file("flow.pcd"), loaded), 0);
  ASSERT_EQ(loaded.width, 4u);
  ASSERT_EQ(loaded.height, 3u);
  for (std::size_t i = 0; i < grid.size(); ++i) {
    if (i == 5) {
      EXPECT_TRUE(std::isnan(loaded[i].z));
      continue;
    }
    // Binary PCD stores the floats bit for bit.
    EXPECT_EQ(loaded[i].x, grid[i].x);
    EXPECT_EQ(loaded[i].prev_x, grid[i].prev_x);
    EXPECT_EQ(loaded[i].prev_u, grid[i].prev_u);
    EXPECT_EQ(loaded[i].prev_v, grid[i].prev_v);
    EXPECT_EQ(loaded[i].weight, grid[i].weight);
    EXPECT_EQ(loaded[i].valid_2d, grid[i].valid_2d);
    EXPECT_EQ(loaded[i].valid_3d, grid[i].valid_3d);
  }
}

} // namespace
