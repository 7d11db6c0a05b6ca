// SPDX-License-Identifier: BSD-3-Clause
// Writes a small synthetic .oni recording whose frames encode their own index.
//
// Usage: make_oni_fixture OUT.oni [FRAMES [PERIOD_US]]
//   FRAMES in 1..32 (default 30), PERIOD_US frame spacing in microseconds, 1..10^7
//   (default 33333, i.e. 30 Hz)
//
// OpenNI 2 can only record live streams, and OpenNI 1 mock nodes made with plain
// Create() cannot be added to a recording (docs/platform.md, "ONI recordings"). So:
//   1. a child process records a few frames of OpenNI 2's built-in "Dummy" device to a
//      scratch file (its driver crashes on teardown, so the child ends with _exit;
//      it sometimes deadlocks, so it runs under a watchdog and is retried);
//   2. OpenNI 1 opens that scratch recording, builds mock depth and image nodes with
//      CreateBasedOn(), switches them to 640x480 and records FRAMES synthetic frames.
// The pattern is fixtureDepthMm() / fixtureColor() below; test_oni_file_source.cpp
// carries its own copy of the same formulas (the test checks the file, not this tool).
//
// Frame k (0-based), pixel (u, v), 640x480, timestamp (k + 1) * PERIOD_US, field of
// view of a 525 px focal length (depth and image):
//   depth (mm) = 1000 + 20 k + 2 (u / 64), except the 16x16 block at columns
//                [16 k, 16 k + 16), rows [0, 16), which is 0 (no measurement);
//   colour     = (R, G, B) = (8 k, u / 3, v / 2).
// Exit codes: 0 success, 1 failure, 2 usage error.
#include <OpenNI.h>
#include <XnCppWrapper.h>
#include <XnPropNames.h>

#include <csignal>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

namespace {

constexpr int WIDTH = 640;
constexpr int HEIGHT = 480;
constexpr double FOCAL_PX = 525.0;

std::uint16_t
fixtureDepthMm(int k, int u, int v)
{
  if (v < 16 && u >= 16 * k && u < 16 * k + 16)
    return 0;
  return static_cast<std::uint16_t>(1000 + 20 * k + 2 * (u / 64));
}

void
fixtureColor(int k, int u, int v, std::uint8_t* rgb)
{
  rgb[0] = static_cast<std::uint8_t>(8 * k);
  rgb[1] = static_cast<std::uint8_t>(u / 3);
  rgb[2] = static_cast<std::uint8_t>(v / 2);
}

/// Child process: record a few frames of the OpenNI 2 Dummy device into `path`.
[[noreturn]] void
recordDummyDevice(const std::string& path)
{
  int code = 1;
  if (openni::OpenNI::initialize() != openni::STATUS_OK) {
    std::fprintf(stderr, "make_oni_fixture: OpenNI2 initialize failed: %s\n",
                 openni::OpenNI::getExtendedError());
    std::fflush(stderr);
    _exit(code);
  }
  // Allocated and never destroyed: the Dummy driver crashes when torn down.
  auto* device = new openni::Device;
  auto* depth = new openni::VideoStream;
  auto* color = new openni::VideoStream;
  auto* recorder = new openni::Recorder;
  if (device->open("Dummy") != openni::STATUS_OK ||
      depth->create(*device, openni::SENSOR_DEPTH) != openni::STATUS_OK ||
      color->create(*device, openni::SENSOR_COLOR) != openni::STATUS_OK ||
      recorder->create(path.c_str()) != openni::STATUS_OK ||
      recorder->attach(*depth) != openni::STATUS_OK ||
      recorder->attach(*color) != openni::STATUS_OK ||
      depth->start() != openni::STATUS_OK || color->start() != openni::STATUS_OK ||
      recorder->start() != openni::STATUS_OK) {
    std::fprintf(stderr,
                 "make_oni_fixture: recording the OpenNI2 Dummy device failed: %s\n",
                 openni::OpenNI::getExtendedError());
  }
  else {
    openni::VideoFrameRef frame;
    bool ok = true;
    for (int i = 0; i < 3 && ok; ++i)
      ok = depth->readFrame(&frame) == openni::STATUS_OK &&
           color->readFrame(&frame) == openni::STATUS_OK;
    recorder->stop();
    recorder->destroy();
    code = ok ? 0 : 1;
    if (!ok)
      std::fprintf(stderr, "make_oni_fixture: reading Dummy frames failed\n");
  }
  std::fflush(stderr);
  _exit(code);
}

/// Runs recordDummyDevice() in a child process with a watchdog. OpenNI2's recorder
/// occasionally deadlocks with the Dummy driver (seen about 1 run in 20), so a child
/// that does not finish in time is killed and the step retried.
bool
recordSeed(const std::string& seed)
{
  constexpr int ATTEMPTS = 5;
  constexpr int TIMEOUT_MS = 3000; // a normal run takes about 0.3 s
  for (int attempt = 1; attempt <= ATTEMPTS; ++attempt) {
    std::fflush(nullptr);
    const pid_t child = fork();
    if (child < 0) {
      std::perror("make_oni_fixture: fork");
      return false;
    }
    if (child == 0)
      recordDummyDevice(seed);
    int status = 0;
    pid_t done = 0;
    for (int waited_ms = 0; waited_ms < TIMEOUT_MS; waited_ms += 10) {
      done = waitpid(child, &status, WNOHANG);
      if (done != 0)
        break;
      usleep(10000);
    }
    if (done == child && WIFEXITED(status) && WEXITSTATUS(status) == 0)
      return true;
    if (done == 0) {
      kill(child, SIGKILL);
      waitpid(child, &status, 0);
      std::fprintf(
          stderr, "make_oni_fixture: OpenNI2 Dummy recording hung (attempt %d of %d)\n",
          attempt, ATTEMPTS);
    }
    else {
      std::fprintf(
          stderr,
          "make_oni_fixture: OpenNI2 Dummy recording failed (attempt %d of %d)\n",
          attempt, ATTEMPTS);
    }
    std::remove(seed.c_str());
  }
  return false;
}

bool
check(XnStatus status, const char* what)
{
  if (status == XN_STATUS_OK)
    return true;
  std::fprintf(stderr, "make_oni_fixture: %s failed: %s\n", what,
               xnGetStatusString(status));
  return false;
}

/// Parent process: write `frames` synthetic frames to `out` with OpenNI 1 mock nodes.
bool
writeFixture(const std::string& seed,
             const std::string& out,
             int frames,
             std::uint64_t period_us)
{
  xn::Context context;
  if (!check(context.Init(), "OpenNI context init"))
    return false;
  xn::Player player;
  xn::DepthGenerator seed_depth;
  xn::ImageGenerator seed_image;
  if (!check(context.OpenFileRecording(seed.c_str(), player),
             "opening the seed recording") ||
      !check(context.FindExistingNode(XN_NODE_TYPE_DEPTH, seed_depth),
             "finding seed depth") ||
      !check(context.FindExistingNode(XN_NODE_TYPE_IMAGE, seed_image),
             "finding seed image"))
    return false;

  xn::MockDepthGenerator depth;
  xn::MockImageGenerator image;
  XnMapOutputMode mode{};
  mode.nXRes = WIDTH;
  mode.nYRes = HEIGHT;
  mode.nFPS = 30;
  if (!check(depth.CreateBasedOn(seed_depth, "FixtureDepth"), "creating mock depth") ||
      !check(image.CreateBasedOn(seed_image, "FixtureImage"), "creating mock image") ||
      !check(depth.SetMapOutputMode(mode), "setting depth mode") ||
      !check(image.SetMapOutputMode(mode), "setting image mode") ||
      !check(image.SetPixelFormat(XN_PIXEL_FORMAT_RGB24), "setting image format"))
    return false;
  // A pinhole with f = FOCAL_PX at 640x480; the Dummy seed carries no field of view.
  XnFieldOfView fov{};
  fov.fHFOV = 2.0 * std::atan(0.5 * WIDTH / FOCAL_PX);
  fov.fVFOV = 2.0 * std::atan(0.5 * HEIGHT / FOCAL_PX);
  if (!check(depth.SetGeneralProperty(XN_PROP_FIELD_OF_VIEW, sizeof(fov), &fov),
             "setting depth field of view") ||
      !check(image.SetGeneralProperty(XN_PROP_FIELD_OF_VIEW, sizeof(fov), &fov),
             "setting image field of view"))
    return false;

  xn::Recorder recorder;
  if (!check(recorder.Create(context), "creating recorder") ||
      !check(recorder.SetDestination(XN_RECORD_MEDIUM_FILE, out.c_str()),
             "opening output") ||
      // Both codecs are lossless, so the test can compare exact values.
      !check(recorder.AddNodeToRecording(depth, XN_CODEC_16Z_EMB_TABLES),
             "adding depth") ||
      !check(recorder.AddNodeToRecording(image, XN_CODEC_UNCOMPRESSED), "adding image"))
    return false;

  std::vector<XnDepthPixel> depth_map(WIDTH * HEIGHT);
  std::vector<XnUInt8> rgb(3 * WIDTH * HEIGHT);
  for (int k = 0; k < frames; ++k) {
    for (int v = 0; v < HEIGHT; ++v)
      for (int u = 0; u < WIDTH; ++u) {
        const int i = v * WIDTH + u;
        depth_map[i] = fixtureDepthMm(k, u, v);
        fixtureColor(k, u, v, &rgb[3 * i]);
      }
    const XnUInt64 stamp = static_cast<XnUInt64>(k + 1) * period_us;
    const XnUInt32 id = static_cast<XnUInt32>(k + 1);
    if (!check(depth.SetData(id, stamp, depth_map.size() * sizeof(XnDepthPixel),
                             depth_map.data()),
               "setting depth data") ||
        !check(image.SetData(id, stamp, rgb.size(), rgb.data()),
               "setting image data") ||
        !check(recorder.Record(), "recording a frame"))
      return false;
  }
  recorder.Release();
  depth.Release();
  image.Release();
  seed_depth.Release();
  seed_image.Release();
  player.Release();
  context.Release();
  return true;
}

} // namespace

int
main(int argc, char** argv)
{
  if (argc < 2 || argc > 4) {
    std::fprintf(
        stderr,
        "usage: %s OUT.oni [FRAMES (1..32, default 30) [PERIOD_US (1..10000000, "
        "default 33333)]]\n",
        argv[0]);
    return 2;
  }
  const std::string out = argv[1];
  int frames = 30;
  std::uint64_t period_us = 33333;
  if (argc >= 3) {
    char* end = nullptr;
    const long value = std::strtol(argv[2], &end, 10);
    if (end == argv[2] || *end != '\0' || value < 1 || value > 32) {
      std::fprintf(stderr, "make_oni_fixture: FRAMES must be 1..32, got '%s'\n",
                   argv[2]);
      return 2;
    }
    frames = static_cast<int>(value);
  }
  if (argc == 4) {
    char* end = nullptr;
    const long long value = std::strtoll(argv[3], &end, 10);
    if (end == argv[3] || *end != '\0' || value < 1 || value > 10000000) {
      std::fprintf(stderr,
                   "make_oni_fixture: PERIOD_US must be 1..10000000, got '%s'\n",
                   argv[3]);
      return 2;
    }
    period_us = static_cast<std::uint64_t>(value);
  }
  const std::string seed = out + ".seed.oni";

  if (!recordSeed(seed)) {
    std::remove(seed.c_str());
    return 1;
  }
  const bool ok = writeFixture(seed, out, frames, period_us);
  std::remove(seed.c_str());
  if (!ok) {
    std::remove(out.c_str());
    return 1;
  }
  return 0;
}
