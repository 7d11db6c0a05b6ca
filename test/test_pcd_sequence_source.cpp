// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/io/pcd_sequence_source.h>

#include <pcl/exceptions.h>
#include <pcl/io/pcd_io.h>

#include <gtest/gtest.h>

#include "support/temp_dir.h"

#include <cmath>
#include <filesystem>
#include <limits>

namespace {

namespace fs = std::filesystem;
using dynvo::test::TempDir;

pcl::PointCloud<pcl::PointXYZRGB>
organizedCloud(float z)
{
  pcl::PointCloud<pcl::PointXYZRGB> cloud(5, 4);
  for (auto& p : cloud) {
    p.x = 0.1f;
    p.y = 0.2f;
    p.z = z;
    p.r = 200;
    p.g = 100;
    p.b = 50;
  }
  cloud[3].x = cloud[3].y = cloud[3].z = std::numeric_limits<float>::quiet_NaN();
  cloud.is_dense = false;
  return cloud;
}

TEST(NaturalLess, DigitRunsCompareAsNumbers)
{
  EXPECT_TRUE(dynvo::naturalLess("f2.pcd", "f10.pcd"));
  EXPECT_FALSE(dynvo::naturalLess("f10.pcd", "f2.pcd"));
  EXPECT_TRUE(dynvo::naturalLess("a.pcd", "b.pcd"));
  EXPECT_TRUE(dynvo::naturalLess("frame_9", "frame_0010"));
  EXPECT_FALSE(dynvo::naturalLess("x", "x"));
}

TEST(PcdSequenceSource, NaturalOrderAndStampsFromNamesOrFps)
{
  TempDir dir;
  // Names that are not numbers: stamps are index / fps in natural order.
  for (int k : {10, 2, 1})
    ASSERT_EQ(pcl::io::savePCDFileBinary(dir.file("f" + std::to_string(k) + ".pcd"),
                                         organizedCloud(0.5f * k)),
              0);
  dynvo::test::writeText(dir.file("notes.txt"), "ignored");
  dynvo::PcdSequenceSource source(dir.path().string(), 10.0);
  ASSERT_EQ(source.size(), 3u);
  dynvo::Frame frame;
  const float expected_z[] = {0.5f, 1.0f, 5.0f};
  for (int k = 0; k < 3; ++k) {
    ASSERT_TRUE(source.next(frame));
    EXPECT_DOUBLE_EQ(frame.timestamp, k / 10.0);
    EXPECT_FLOAT_EQ((*frame.cloud)[0].z, expected_z[k]);
    EXPECT_EQ(frame.cloud->width, 5u);
    EXPECT_EQ(frame.cloud->height, 4u);
    // Images derived from the cloud: depth = z, NaN where the point is missing.
    EXPECT_FLOAT_EQ(frame.depth.data[0], expected_z[k]);
    EXPECT_TRUE(std::isnan(frame.depth.data[3]));
    EXPECT_EQ(frame.color.data[0], 200);
    EXPECT_EQ(frame.color.data[2], 50);
  }
  EXPECT_FALSE(source.next(frame));
}

TEST(PcdSequenceSource, NumericNamesAreTimestamps)
{
  TempDir dir;
  ASSERT_EQ(pcl::io::savePCDFileBinaryCompressed(dir.file("1305031102.5.pcd"),
                                                 organizedCloud(1.0f)),
            0);
  ASSERT_EQ(
      pcl::io::savePCDFileBinary(dir.file("1305031102.25.pcd"), organizedCloud(1.0f)),
      0);
  dynvo::PcdSequenceSource source(dir.path().string());
  dynvo::Frame frame;
  ASSERT_TRUE(source.next(frame));
  EXPECT_DOUBLE_EQ(frame.timestamp, 1305031102.25);
  ASSERT_TRUE(source.next(frame));
  EXPECT_DOUBLE_EQ(frame.timestamp, 1305031102.5);
}

TEST(PcdSequenceSource, BadInputNamesTheFile)
{
  EXPECT_THROW(dynvo::PcdSequenceSource("/nonexistent/folder"), pcl::IOException);
  TempDir dir;
  EXPECT_THROW(dynvo::PcdSequenceSource(dir.path().string()), pcl::IOException);
  EXPECT_THROW(dynvo::PcdSequenceSource(dir.path().string(), 0.0),
               std::invalid_argument);

  const auto expect_next_fails = [&](const std::string& name,
                                     const std::string& needle) {
    dynvo::PcdSequenceSource source(dir.path().string());
    dynvo::Frame frame;
    try {
      source.next(frame);
      FAIL() << "expected pcl::IOException for " << name;
    }
    catch (const pcl::IOException& e) {
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
    fs::remove(dir.file(name));
  };

  dynvo::test::writeText(dir.file("a.pcd"), "garbage, not a PCD header\n");
  expect_next_fails("a.pcd", "cannot read PCD file");

  ASSERT_EQ(pcl::io::savePCDFileBinary(dir.file("t.pcd"), organizedCloud(1.0f)), 0);
  fs::resize_file(dir.file("t.pcd"), fs::file_size(dir.file("t.pcd")) - 100);
  expect_next_fails("t.pcd", "cannot read PCD file");

  pcl::PointCloud<pcl::PointXYZRGB> flat = organizedCloud(1.0f);
  flat.width = static_cast<std::uint32_t>(flat.size());
  flat.height = 1;
  ASSERT_EQ(pcl::io::savePCDFileBinary(dir.file("b.pcd"), flat), 0);
  expect_next_fails("b.pcd", "not organized");

  pcl::PointCloud<pcl::PointXYZ> no_colour(5, 4, pcl::PointXYZ(0.f, 0.f, 1.f));
  ASSERT_EQ(pcl::io::savePCDFileBinary(dir.file("c.pcd"), no_colour), 0);
  expect_next_fails("c.pcd", "no rgb");

  // 1-byte y, z and rgb: PCL's conversion would copy 4 bytes each, past the data (the
  // first finding of fuzz_pcd_header, under ASan a heap-buffer-overflow).
  dynvo::test::writeText(dir.file("s.pcd"),
                         "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z rgb\nSIZE 4 1 1 1\n"
                         "WIDTH 2\nHEIGHT 2\nPOINTS 4\nDATA ascii\n0 0 1 2\n0 0 1 "
                         "2\n0 0 1 2\n0 0 1 2\n");
  expect_next_fails("s.pcd", "field 'y' must hold one 4-byte value");

  // A header claiming more data than the file holds is refused before PCL allocates it.
  dynvo::test::writeText(dir.file("h.pcd"),
                         "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z rgb\nSIZE 4 4 4 4\n"
                         "TYPE F F F U\nCOUNT 1 1 1 1\nWIDTH 640\nHEIGHT 480\n"
                         "POINTS 307200\nDATA binary\n0123456789");
  expect_next_fails("h.pcd", "need more than the 10 bytes of binary data");
  dynvo::test::writeText(dir.file("w.pcd"),
                         "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z rgb\nSIZE 4 4 4 4\n"
                         "WIDTH 5000\nHEIGHT 5000\nPOINTS 25000000\nDATA binary\n");
  expect_next_fails("w.pcd", "over the frame-size limit of 16777216 px");
  // PCL reads an unknown DATA kind as ASCII and allocates COUNT values per point first
  // (fuzz_pcd_header: out of memory).
  dynvo::test::writeText(dir.file("k.pcd"),
                         "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z rgb\nSIZE 4 4 4 4\n"
                         "TYPE F F F U\nCOUNT 777777771 1 1 1\nWIDTH 2\nHEIGHT 2\n"
                         "POINTS 4\nDATA icsai\n0 0 1 255\n");
  expect_next_fails("k.pcd", "cannot be in the 10 bytes of ASCII data");
}

} // namespace
