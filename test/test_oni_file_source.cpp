// SPDX-License-Identifier: BSD-3-Clause
// OniFileSource: playback of a synthetic .oni recording written at test time by
// make_oni_fixture (test/tools), plus the error paths.
#include "support/temp_dir.h"

#include <dynvo/common/error_text.h>
#include <dynvo/io/oni_file_source.h>

#include <pcl/exceptions.h>

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <random>
#include <string>
#include <vector>

namespace {

using dynvo::Frame;
using dynvo::OniFileSource;

// The fixture's pattern, restated from test/tools/make_oni_fixture.cpp (frame k,
// pixel (u, v), 640x480, device time (k + 1) * 33333 us).
constexpr int WIDTH = 640;
constexpr int HEIGHT = 480;

std::uint16_t
expectedDepthMm(int k, int u, int v)
{
  if (v < 16 && u >= 16 * k && u < 16 * k + 16)
    return 0;
  return static_cast<std::uint16_t>(1000 + 20 * k + 2 * (u / 64));
}

void
expectedColor(int k, int u, int v, std::uint8_t* rgb)
{
  rgb[0] = static_cast<std::uint8_t>(8 * k);
  rgb[1] = static_cast<std::uint8_t>(u / 3);
  rgb[2] = static_cast<std::uint8_t>(v / 2);
}

/// Expects `call` to throw pcl::IOException whose message, as apps print it, names `file`
/// and carries no PCL function signature or source location.
template <typename Call>
void
expectIOExceptionNaming(const std::string& file, Call call)
{
  try {
    call();
    ADD_FAILURE() << "no exception for " << file;
  }
  catch (const pcl::IOException& error) {
    const std::string shown = dynvo::errorText(error);
    EXPECT_NE(shown.find(file), std::string::npos)
        << "message does not name the file: " << shown;
    EXPECT_EQ(shown.find(" @ "), std::string::npos) << shown;
    EXPECT_EQ(shown.find("pcl::"), std::string::npos) << shown;
    EXPECT_EQ(shown.find('\n'), std::string::npos) << shown;
  }
  catch (const std::exception& error) {
    ADD_FAILURE() << "wrong exception type for " << file << ": " << error.what();
  }
}

#if defined(DYNVO_HAVE_OPENNI2) && defined(DYNVO_ONI_FIXTURE_TOOL)

class OniFileSourceTest : public ::testing::Test {
protected:
  /// Writes a fixture of `frames` frames spaced `period_us` apart into the temp dir
  /// and returns its path.
  std::string makeFixture(int frames, long period_us = 33333)
  {
    const std::string file = dir_.file("fixture_" + std::to_string(frames) + "_" +
                                       std::to_string(period_us) + ".oni");
    const std::string command = std::string("\"") + DYNVO_ONI_FIXTURE_TOOL + "\" \"" +
                                file + "\" " + std::to_string(frames) + " " +
                                std::to_string(period_us);
    const int status = std::system(command.c_str());
    EXPECT_EQ(status, 0) << command;
    return file;
  }

  dynvo::test::TempDir dir_;
};

// Every frame arrives once, in recording order, with metric depth and exact colour.
TEST_F(OniFileSourceTest, DeliversEveryFrameInOrderWithMetricDepth)
{
  constexpr int FRAMES = 30;
  const std::string file = makeFixture(FRAMES);
  ASSERT_FALSE(HasFailure());

  const auto start = std::chrono::steady_clock::now();
  OniFileSource source(file);
  EXPECT_EQ(source.size(), static_cast<std::size_t>(FRAMES));

  Frame frame;
  int k = 0;
  double first_stamp = 0.0;
  std::uint8_t rgb[3];
  while (source.next(frame)) {
    ASSERT_LT(k, FRAMES) << "more frames than recorded (duplicates or looping)";
    SCOPED_TRACE("frame " + std::to_string(k));
    // Device time in integer microseconds; playback starts the clock at the first
    // frame, so stamps are checked relative to it: 33.333 ms per frame to 1 us.
    if (k == 0)
      first_stamp = frame.timestamp;
    EXPECT_NEAR(frame.timestamp - first_stamp, k * 33333e-6, 1e-6);
    EXPECT_NE(frame.name.find(file), std::string::npos);
    ASSERT_EQ(frame.depth.width, static_cast<std::uint32_t>(WIDTH));
    ASSERT_EQ(frame.depth.height, static_cast<std::uint32_t>(HEIGHT));
    ASSERT_EQ(frame.color.width, static_cast<std::uint32_t>(WIDTH));
    ASSERT_EQ(frame.color.height, static_cast<std::uint32_t>(HEIGHT));
    ASSERT_TRUE(frame.cloud);
    ASSERT_EQ(frame.cloud->width, static_cast<std::uint32_t>(WIDTH));
    ASSERT_EQ(frame.cloud->height, static_cast<std::uint32_t>(HEIGHT));

    // Depth: OpenNI millimetres -> metres. The float product raw * 0.001 is within
    // 1e-6 m of the exact value; neighbouring frames differ by 20 mm and the column
    // steps by 2 mm, so any swapped, repeated or resampled frame fails.
    int depth_errors = 0, color_errors = 0, cloud_errors = 0;
    for (int v = 0; v < HEIGHT; ++v) {
      for (int u = 0; u < WIDTH; ++u) {
        const std::size_t i = static_cast<std::size_t>(v) * WIDTH + u;
        const std::uint16_t mm = expectedDepthMm(k, u, v);
        const float z = frame.depth.data[i];
        if (mm == 0 ? !std::isnan(z) : !(std::abs(z - mm * 1e-3) <= 1e-6))
          ++depth_errors;
        // Colour is recorded uncompressed, so it must come back bit-exact.
        expectedColor(k, u, v, rgb);
        if (frame.color.data[3 * i] != rgb[0] ||
            frame.color.data[3 * i + 1] != rgb[1] ||
            frame.color.data[3 * i + 2] != rgb[2])
          ++color_errors;
        const pcl::PointXYZRGB& p = (*frame.cloud)[i];
        const bool z_ok = mm == 0 ? std::isnan(p.z) : p.z == z;
        if (!z_ok || p.r != rgb[0] || p.g != rgb[1] || p.b != rgb[2])
          ++cloud_errors;
      }
    }
    EXPECT_EQ(depth_errors, 0);
    EXPECT_EQ(color_errors, 0);
    EXPECT_EQ(cloud_errors, 0);

    // Pinhole geometry: a point right of the image centre has x > 0, and the left and
    // right edges of a constant-depth row are symmetric about the centre to 1e-5 m.
    const pcl::PointXYZRGB& left = (*frame.cloud)[240 * WIDTH + 0];
    const pcl::PointXYZRGB& right = (*frame.cloud)[240 * WIDTH + WIDTH - 1];
    EXPECT_LT(left.x, 0.0f);
    EXPECT_GT(right.x, 0.0f);
    EXPECT_NEAR(left.x / left.z, -right.x / right.z, 1e-5);
    ++k;
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(k, FRAMES);
  // At the end the frame is left untouched and further calls keep returning false.
  const double last_stamp = frame.timestamp;
  EXPECT_FALSE(source.next(frame));
  EXPECT_EQ(frame.timestamp, last_stamp);
  // Real-time playback would take 30 x 33.3 ms = 1.0 s; stepping is unpaced.
  RecordProperty("seconds_for_30_frames", std::to_string(seconds));
  std::printf("[          ] opening + reading %d frames took %.3f s\n", FRAMES,
              seconds);
}

// A one-frame recording: the last (only) pair must not be held back waiting for a
// successor, which is what the grabber's own image+depth synchronizer does.
TEST_F(OniFileSourceTest, DeliversSingleFrameRecording)
{
  const std::string file = makeFixture(1);
  ASSERT_FALSE(HasFailure());
  OniFileSource source(file);
  EXPECT_EQ(source.size(), 1u);
  Frame frame;
  ASSERT_TRUE(source.next(frame));
  EXPECT_NEAR(frame.depth.data[100 * WIDTH + 100], 1.0 + 2 * 0.001, 1e-6);
  EXPECT_FALSE(source.next(frame));
}

// Playback is stepped, not paced by the recorded clock: 8 frames recorded 1 s apart
// (7 s of recording time) must read in well under that, even on a loaded machine
// (unloaded, one frame takes about 10 ms).
TEST_F(OniFileSourceTest, PlaybackIsNotRealTimePaced)
{
  const std::string file = makeFixture(8, 1000000);
  ASSERT_FALSE(HasFailure());
  OniFileSource source(file);
  const auto start = std::chrono::steady_clock::now();
  Frame frame;
  int frames = 0;
  double first_stamp = 0.0;
  while (source.next(frame)) {
    if (frames == 0)
      first_stamp = frame.timestamp;
    ++frames;
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(frames, 8);
  EXPECT_NEAR(frame.timestamp - first_stamp, 7.0, 1e-6);
  EXPECT_LT(seconds, 3.5) << "playback appears to be paced at recording speed";
}

// Destroying a source mid-stream (player thread parked in a callback) returns promptly.
TEST_F(OniFileSourceTest, DestroyMidStreamDoesNotHang)
{
  const std::string file = makeFixture(30);
  ASSERT_FALSE(HasFailure());
  const auto start = std::chrono::steady_clock::now();
  {
    OniFileSource unread(file);
  }
  {
    OniFileSource source(file);
    Frame frame;
    for (int k = 0; k < 3; ++k)
      ASSERT_TRUE(source.next(frame));
    EXPECT_NEAR(frame.depth.data[100 * WIDTH + 100], 1.0 + 2 * 20e-3 + 2e-3, 1e-6);
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_LT(seconds, 5.0);
}

// A truncated recording (valid header, data cut off) is an I/O error, not a crash.
TEST_F(OniFileSourceTest, TruncatedRecordingThrows)
{
  const std::string full = makeFixture(3);
  ASSERT_FALSE(HasFailure());
  const std::string file = dir_.file("truncated.oni");
  {
    std::ifstream in(full, std::ios::binary);
    std::vector<char> head(512);
    in.read(head.data(), static_cast<std::streamsize>(head.size()));
    std::ofstream out(file, std::ios::binary);
    out.write(head.data(), in.gcount());
  }
  expectIOExceptionNaming(file, [&] {
    OniFileSource source(file);
    Frame frame;
    while (source.next(frame)) {
    }
  });
}

#endif // DYNVO_HAVE_OPENNI2 && DYNVO_ONI_FIXTURE_TOOL

TEST(OniFileSource, MissingFileThrowsNamingIt)
{
  dynvo::test::TempDir dir;
  const std::string file = dir.file("does_not_exist.oni");
  expectIOExceptionNaming(file, [&] {
    OniFileSource source(file);
  });
}

TEST(OniFileSource, RandomBytesThrowNamingFile)
{
  dynvo::test::TempDir dir;
  const std::string file = dir.file("x.oni");
  std::mt19937 random(42);
  std::vector<char> bytes(64 * 1024);
  for (char& b : bytes)
    b = static_cast<char>(random() & 0xff);
  std::ofstream(file, std::ios::binary)
      .write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  expectIOExceptionNaming(file, [&] {
    OniFileSource source(file);
  });
}

// Passes the header check, so OpenNI2 itself must reject the rest without crashing.
TEST(OniFileSource, OniMagicFollowedByRandomBytesThrowsNamingFile)
{
  dynvo::test::TempDir dir;
  const std::string file = dir.file("garbage.oni");
  std::mt19937 random(7);
  std::vector<char> bytes(64 * 1024);
  for (char& b : bytes)
    b = static_cast<char>(random() & 0xff);
  bytes[0] = 'N';
  bytes[1] = 'I';
  bytes[2] = '1';
  bytes[3] = '0';
  std::ofstream(file, std::ios::binary)
      .write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  expectIOExceptionNaming(file, [&] {
    OniFileSource source(file);
  });
}

TEST(OniFileSource, EmptyFileThrowsNamingIt)
{
  dynvo::test::TempDir dir;
  const std::string file = dir.file("empty.oni");
  std::ofstream(file, std::ios::binary).close();
  expectIOExceptionNaming(file, [&] {
    OniFileSource source(file);
  });
}

TEST(OniFileSource, DirectoryThrowsNamingIt)
{
  dynvo::test::TempDir dir;
  expectIOExceptionNaming(dir.path().string(), [&] {
    OniFileSource source(dir.path().string());
  });
}

} // namespace
