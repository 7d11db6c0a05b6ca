// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/io/tum_folder_source.h>

#include <pcl/exceptions.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <gtest/gtest.h>

#include "support/shared_data.h"
#include "support/temp_dir.h"

#include <cmath>
#include <filesystem>

namespace {

namespace fs = std::filesystem;
using dynvo::test::TempDir;
using dynvo::test::writeText;

/// A 4x3 TUM folder: colour pixel (u, v) = (10u, 20v, 7) in RGB; depth raw = 1000 * (u + 1)
/// except pixel (0, 0), which is 0 (missing).
class TumFolderTest : public ::testing::Test {
protected:
  void SetUp() override
  {
    fs::create_directories(dir_.path() / "rgb");
    fs::create_directories(dir_.path() / "depth");
  }

  void writeImages(const std::string& stamp)
  {
    cv::Mat bgr(3, 4, CV_8UC3), depth(3, 4, CV_16UC1);
    for (int v = 0; v < 3; ++v)
      for (int u = 0; u < 4; ++u) {
        bgr.at<cv::Vec3b>(v, u) = cv::Vec3b(7, 20 * v, 10 * u);
        depth.at<std::uint16_t>(v, u) = static_cast<std::uint16_t>(1000 * (u + 1));
      }
    depth.at<std::uint16_t>(0, 0) = 0;
    ASSERT_TRUE(cv::imwrite(dir_.file("rgb/" + stamp + ".png"), bgr));
    ASSERT_TRUE(cv::imwrite(dir_.file("depth/" + stamp + ".png"), depth));
  }

  dynvo::TumFolderSource::Options options() const
  {
    dynvo::TumFolderSource::Options o;
    o.intrinsics = dynvo::CameraIntrinsics::fromPreset("fr1");
    o.intrinsics.distortion = {}; // 4x3 images: no lens to undistort
    return o;
  }

  TempDir dir_;
};

TEST_F(TumFolderTest, AssociatesAndBuildsMetricOrganizedClouds)
{
  for (const char* stamp : {"1.000000", "1.033000", "1.066000"})
    writeImages(stamp);
  // Depth 4 ms late; the third colour frame has no depth within 0.02 s (1.100 is 34 ms
  // away) and must be dropped, as associate.py drops it.
  writeText(dir_.file("rgb.txt"), "# color images\n# timestamp filename\n\n"
                                  "1.000000 rgb/1.000000.png\n"
                                  "1.033000 rgb/1.033000.png\n"
                                  "1.066000 rgb/1.066000.png\n");
  writeText(dir_.file("depth.txt"), "# depth\n1.004000 depth/1.000000.png\n"
                                    "1.037000 depth/1.033000.png\n"
                                    "1.100000 depth/1.066000.png\n");
  dynvo::TumFolderSource source(dir_.path().string(), options());
  ASSERT_EQ(source.size(), 2u);
  EXPECT_DOUBLE_EQ(source.depthScale(), 5000.0);
  EXPECT_DOUBLE_EQ(source.entries()[1].depth_stamp, 1.037);

  dynvo::Frame frame;
  ASSERT_TRUE(source.next(frame));
  EXPECT_DOUBLE_EQ(frame.timestamp, 1.0);
  ASSERT_TRUE(frame.cloud);
  EXPECT_FALSE(frame.undistortion); // the images are the recording's
  ASSERT_EQ(frame.cloud->width, 4u);
  ASSERT_EQ(frame.cloud->height, 3u);
  EXPECT_TRUE(frame.cloud->isOrganized());
  // Missing depth becomes a NaN point that keeps its colour.
  EXPECT_TRUE(std::isnan((*frame.cloud)(0, 0).z));
  EXPECT_TRUE(std::isnan(frame.depth.data[0]));
  // raw 3000 at scale 5000 is 0.6 m; back-projection uses the fr1 intrinsics.
  const auto& p = (*frame.cloud)(2, 1);
  EXPECT_FLOAT_EQ(p.z, 0.6f);
  EXPECT_NEAR(p.x, (2 - 318.6) * 0.6 / 517.3, 1e-6);
  EXPECT_NEAR(p.y, (1 - 255.3) * 0.6 / 516.5, 1e-6);
  EXPECT_EQ(p.r, 20);
  EXPECT_EQ(p.g, 20);
  EXPECT_EQ(p.b, 7);
  EXPECT_EQ(frame.color.data[3 * (1 * 4 + 2)], 20);

  ASSERT_TRUE(source.next(frame));
  EXPECT_DOUBLE_EQ(frame.timestamp, 1.033);
  EXPECT_FALSE(source.next(frame));
  EXPECT_DOUBLE_EQ(frame.timestamp, 1.033); // untouched at the end
}

TEST_F(TumFolderTest, AssociationsLayoutUsesDepthScale1000)
{
  writeImages("5.000000");
  writeText(dir_.file("associations.txt"),
            "5.000000 rgb/5.000000.png 5.001000 depth/5.000000.png\n");
  dynvo::TumFolderSource source(dir_.path().string(), options());
  EXPECT_DOUBLE_EQ(source.depthScale(), 1000.0);
  dynvo::Frame frame;
  ASSERT_TRUE(source.next(frame));
  EXPECT_FLOAT_EQ((*frame.cloud)(1, 0).z, 2.0f); // raw 2000 at 1000 per metre

  auto explicit_scale = options();
  explicit_scale.depth_scale = 2000.0;
  dynvo::TumFolderSource scaled(dir_.path().string(), explicit_scale);
  ASSERT_TRUE(scaled.next(frame));
  EXPECT_FLOAT_EQ((*frame.cloud)(1, 0).z, 1.0f);
}

/// Expects the constructor or the first next() to throw naming `needle`.
void
expectFailure(const std::string& folder,
              const dynvo::TumFolderSource::Options& options,
              const std::string& needle)
{
  try {
    dynvo::TumFolderSource source(folder, options);
    dynvo::Frame frame;
    source.next(frame);
    FAIL() << "expected pcl::IOException mentioning " << needle;
  }
  catch (const pcl::IOException& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

TEST_F(TumFolderTest, BadInputNamesTheFileAndProblem)
{
  expectFailure(dir_.file("nope"), options(), "not a directory");
  expectFailure(dir_.path().string(), options(), "rgb.txt: cannot open");

  writeText(dir_.file("rgb.txt"), "1.0 rgb/a.png\nabc rgb/b.png\n");
  writeText(dir_.file("depth.txt"), "1.0 depth/a.png\n");
  expectFailure(dir_.path().string(), options(), "rgb.txt:2: bad timestamp 'abc'");

  writeText(dir_.file("rgb.txt"), "1.0 rgb/a.png\n");
  expectFailure(dir_.path().string(), options(), "rgb/a.png: cannot read colour image");

  writeText(dir_.file("rgb/a.png"), "this is not a png");
  expectFailure(dir_.path().string(), options(), "rgb/a.png: cannot read colour image");

  // An 8-bit depth image is the wrong type.
  ASSERT_TRUE(
      cv::imwrite(dir_.file("rgb/a.png"), cv::Mat(3, 4, CV_8UC3, cv::Scalar(1, 2, 3))));
  ASSERT_TRUE(
      cv::imwrite(dir_.file("depth/a.png"), cv::Mat(3, 4, CV_8UC1, cv::Scalar(9))));
  expectFailure(dir_.path().string(), options(),
                "depth/a.png: depth image must be 16-bit");

  // Colour and depth of different sizes.
  ASSERT_TRUE(
      cv::imwrite(dir_.file("depth/a.png"), cv::Mat(2, 4, CV_16UC1, cv::Scalar(9))));
  expectFailure(dir_.path().string(), options(), "depth image size differs");

  writeText(dir_.file("depth.txt"), "3.0 depth/a.png\n");
  expectFailure(dir_.path().string(), options(), "no colour image has a depth image");
}

TEST(TumFolderRealData, Fr1XyzHas200AssociatedPairs)
{
  const fs::path folder = dynvo::test::sharedDataPath("tum_fr1_xyz_200");
  DYNVO_REQUIRE_SHARED_DATA((folder / "rgb.txt").string());
  dynvo::TumFolderSource::Options options;
  options.intrinsics = dynvo::CameraIntrinsics::fromPreset("fr1");
  dynvo::TumFolderSource source(folder.string(), options);
  // The clip was cut as the first 200 associated pairs of the benchmark sequence.
  EXPECT_EQ(source.size(), 200u);
  for (const auto& entry : source.entries())
    EXPECT_LT(std::abs(entry.rgb_stamp - entry.depth_stamp), 0.02);

  dynvo::Frame frame;
  ASSERT_TRUE(source.next(frame));
  EXPECT_DOUBLE_EQ(frame.timestamp, 1305031102.175304);
  ASSERT_EQ(frame.cloud->width, 640u);
  ASSERT_EQ(frame.cloud->height, 480u);
  // The fr1 lens is undistorted as the frame is read. It barrels the image out, so the
  // undistorted image's corners see past the recording's edge: black, with no depth.
  ASSERT_TRUE(frame.undistortion);
  EXPECT_TRUE(std::isnan((*frame.cloud)(0, 0).z));
  EXPECT_EQ(frame.color.data[0] + frame.color.data[1] + frame.color.data[2], 0);
  std::size_t valid = 0;
  double sum_z = 0.0;
  for (const auto& p : frame.cloud->points)
    if (std::isfinite(p.z)) {
      ++valid;
      sum_z += p.z;
    }
  // A Kinect view of a desk: most pixels have depth, at 0.5-3 m.
  EXPECT_GT(valid, frame.cloud->size() / 2);
  EXPECT_GT(sum_z / valid, 0.5);
  EXPECT_LT(sum_z / valid, 3.0);
}

} // namespace
