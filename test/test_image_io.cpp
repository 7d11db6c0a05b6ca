// SPDX-License-Identifier: BSD-3-Clause
// Colour and raw-depth PNGs, depth quantisation, and the sequence writer's folder rules.
#include <dynvo/io/image_io.h>
#include <dynvo/io/sequence_writer.h>

#include <pcl/exceptions.h>

#include <gtest/gtest.h>

#include "support/temp_dir.h"

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <filesystem>
#include <limits>
#include <string>

namespace {

using dynvo::test::TempDir;

TEST(ImageIo, ColourRoundTripsInRgbOrderAndIsStoredAsBgr)
{
  const TempDir dir;
  dynvo::ColorImage color{3, 2, {}};
  for (int i = 0; i < 18; ++i)
    color.data.push_back(static_cast<std::uint8_t>(10 * i + 1));
  dynvo::writeColorImage(dir.file("c.png"), color);
  const dynvo::ColorImage back = dynvo::readColorImage(dir.file("c.png"));
  EXPECT_EQ(back.width, 3u);
  EXPECT_EQ(back.height, 2u);
  EXPECT_EQ(back.data, color.data);
  // Other tools read the file as OpenCV does: B, G, R.
  const cv::Mat bgr = cv::imread(dir.file("c.png"), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(bgr.type(), CV_8UC3);
  EXPECT_EQ(bgr.at<cv::Vec3b>(0, 0), cv::Vec3b(21, 11, 1));
}

TEST(ImageIo, RawDepthRoundTripsAndWrongTypesAreRefusedNamingTheFile)
{
  const TempDir dir;
  const dynvo::RawDepthImage depth{2, 2, {0, 1, 5000, 65535}};
  dynvo::writeRawDepthImage(dir.file("d.png"), depth);
  EXPECT_EQ(dynvo::readRawDepthImage(dir.file("d.png")).data, depth.data);
  dynvo::writeColorImage(dir.file("c.png"), {1, 1, {1, 2, 3}});
  try {
    dynvo::readRawDepthImage(dir.file("c.png"));
    FAIL() << "expected pcl::IOException";
  }
  catch (const pcl::IOException& e) {
    EXPECT_NE(std::string(e.what()).find(dir.file("c.png")), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("16-bit single channel"), std::string::npos);
  }
  EXPECT_THROW(dynvo::readColorImage(dir.file("d.png")), pcl::IOException);
  EXPECT_THROW(dynvo::readColorImage(dir.file("missing.png")), pcl::IOException);
  EXPECT_THROW(dynvo::writeRawDepthImage(dir.file("bad.png"), {2, 2, {1, 2, 3}}),
               pcl::IOException);
}

TEST(ImageIo, QuantizeDepthRoundsSaturatesAndMapsNanToZero)
{
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const dynvo::DepthImage depth{5, 1, {nan, 1.0f, 0.00011f, 0.00009f, 20.0f}};
  const dynvo::RawDepthImage raw = dynvo::quantizeDepth(depth, 5000.0);
  EXPECT_EQ(raw.width, 5u);
  // 0.55 and 0.45 raw units round to 1 and 0; 20 m is beyond 16 bits at 5000 per metre.
  EXPECT_EQ(raw.data, (std::vector<std::uint16_t>{0, 5000, 1, 0, 65535}));
}

TEST(SequenceWriter, RefusesANonEmptyFolderAndWritesTheIndexFiles)
{
  const TempDir dir;
  std::filesystem::create_directories(dir.path() / "full");
  dynvo::test::writeText(dir.file("full/keep.txt"), "x\n");
  EXPECT_THROW(dynvo::SequenceWriter(dir.file("full"), 5000.0), pcl::IOException);

  const dynvo::SequenceWriter writer(dir.file("seq"), 5000.0);
  writer.writeFrame(1.0, 1.005, {1, 1, {1, 2, 3}}, {1, 1, {5000}}, {1, 1, {2}});
  dynvo::SequenceIndexEntry entry{1.0, 1.005, {}};
  entry.objects.push_back(
      {2, Eigen::Isometry3d(Eigen::Translation3d(0.5, 0, 1)), true});
  writer.writeIndex("# test\n", {entry}, {{1.0, Eigen::Isometry3d::Identity()}});
  for (const char* file :
       {"rgb/1.000000.png", "depth/1.005000.png", "labels/1.000000.png", "rgb.txt",
        "depth.txt", "objects.txt", "groundtruth.txt"})
    EXPECT_TRUE(std::filesystem::exists(dir.path() / "seq" / file)) << file;
  EXPECT_NE(dynvo::test::readText(dir.file("seq/objects.txt"))
                .find("1.000000 2 0.500000000 0.000000000 1.000000000 0.000000000 "
                      "0.000000000 0.000000000 1.000000000 1\n"),
            std::string::npos);
  EXPECT_NE(dynvo::test::readText(dir.file("seq/depth.txt")).find("5000 per metre"),
            std::string::npos);
}

} // namespace
