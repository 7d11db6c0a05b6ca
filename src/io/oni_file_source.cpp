// SPDX-License-Identifier: BSD-3-Clause
// OniFileSource: .oni playback through pcl::io::OpenNI2Grabber (stub without OpenNI2).
#include <dynvo/common/error_text.h>
#include <dynvo/io/oni_file_source.h>

#include <pcl/exceptions.h>

#include <string>

#ifdef DYNVO_HAVE_OPENNI2

#include <pcl/console/print.h>
#include <pcl/io/openni2_grabber.h>
#include <pcl/memory.h>

#include <OpenNI.h>

#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>
#include <vector>

namespace dynvo {

namespace {

/// How long next() waits for the grabber's callbacks after each playback step.
constexpr std::chrono::milliseconds STEP_WAIT{20};
/// Focal length (px at 640 columns) used when a recording carries no field of view.
constexpr double FALLBACK_FOCAL_VGA_PX = 525.0;
/// next() gives up when the player delivers nothing for this long.
constexpr std::chrono::seconds STALL_TIMEOUT{10};

/// The exceptions this file throws itself; they already name the file.
class SourceError : public pcl::IOException {
public:
  using pcl::IOException::IOException;
};

[[noreturn]] void
fail(const std::string& message)
{
  throw SourceError(message);
}

/// Rejects files that are missing or do not start with the ONI magic "NI10".
/// OpenNI2 is not robust against arbitrary bytes, so this runs before it sees the file.
void
checkOniHeader(const std::string& file)
{
  namespace fs = std::filesystem;
  std::error_code error;
  if (!fs::exists(file, error))
    fail(file + ": no such file");
  if (!fs::is_regular_file(file, error))
    fail(file + ": not a regular file");
  std::ifstream in(file, std::ios::binary);
  if (!in)
    fail(file + ": cannot open file");
  char magic[4] = {0, 0, 0, 0};
  in.read(magic, sizeof(magic));
  if (in.gcount() != 4 || magic[0] != 'N' || magic[1] != 'I' || magic[2] != '1' ||
      magic[3] != '0')
    fail(file + ": not an ONI recording (missing 'NI10' header)");
}

/** Reads the OpenNI2 device and streams that OpenNI2Device keeps protected (PCL
 * exposes neither stepping nor the repeat switch). Naming the members through a
 * derived class is ordinary C++ access; the class is never instantiated. */
struct DeviceStreams : pcl::io::openni2::OpenNI2Device {
  static std::shared_ptr<openni::VideoStream>
  depth(const pcl::io::openni2::OpenNI2Device& device)
  {
    return device.*(&DeviceStreams::depth_video_stream_);
  }
  static std::shared_ptr<openni::VideoStream>
  color(const pcl::io::openni2::OpenNI2Device& device)
  {
    return device.*(&DeviceStreams::color_video_stream_);
  }
  static std::shared_ptr<openni::Device>
  device(const pcl::io::openni2::OpenNI2Device& device)
  {
    return device.*(&DeviceStreams::openni_device_);
  }
};

/// A depth frame copied out of OpenNI's buffers (raw millimetres, 0 = no measurement).
struct RawDepth {
  std::uint64_t stamp_us = 0;    ///< device time (microseconds)
  unsigned width = 0;            ///< columns (px)
  unsigned height = 0;           ///< rows (px)
  std::vector<std::uint16_t> mm; ///< width * height raw depths (mm)
};

/// A colour frame copied out of OpenNI's buffers (RGB8).
struct RawColor {
  std::uint64_t stamp_us = 0;    ///< device time (microseconds)
  unsigned width = 0;            ///< columns (px)
  unsigned height = 0;           ///< rows (px)
  std::vector<std::uint8_t> rgb; ///< width * height * 3 bytes
};

} // namespace

struct OniFileSource::Impl {
  using ImagePtr = std::shared_ptr<const RawColor>;
  using DepthPtr = std::shared_ptr<const RawDepth>;

  std::string file;
  /// Made by pcl::make_shared (Eigen's aligned allocator, as PCL expects): created by
  /// `new` in this C++17 file it was freed by libpcl_io's aligned operator delete.
  std::shared_ptr<pcl::io::OpenNI2Grabber> grabber;
  CameraIntrinsics intrinsics;
  std::size_t depth_count = 0; ///< depth frames in the recording
  std::size_t color_count = 0; ///< colour frames in the recording

  std::mutex mutex;
  std::condition_variable changed;
  std::deque<DepthPtr> depths; ///< received, not yet delivered (file order)
  std::deque<ImagePtr> images; ///< received; front may be reused by the next depth
  std::size_t depth_received = 0;
  std::size_t image_received = 0;
  std::size_t delivered = 0;
  std::uint64_t last_depth_stamp_us = 0; ///< stamp of the last accepted depth frame
  bool stopping = false;
  std::vector<openni::VideoStream*> streams; ///< depth and colour, for step()
  std::shared_ptr<openni::VideoStream> depth_stream, color_stream; ///< keep alive
  std::string error;         ///< first failure on an OpenNI thread, reported by next()
  unsigned depth_width = 0;  ///< depth stream columns (px); colour comes at this size
  unsigned depth_height = 0; ///< depth stream rows (px)

  /// OpenNI thread: remembers a failure for next(); exceptions must not reach OpenNI.
  void setError(const std::string& message)
  {
    {
      std::lock_guard<std::mutex> lock(mutex);
      if (error.empty())
        error = message;
    }
    changed.notify_all();
  }

  /// OpenNI thread: a depth frame arrived. Its pixels are copied at once, so no
  /// OpenNI frame buffer is held beyond the callback.
  void onDepth(const pcl::io::DepthImage::Ptr& image)
  {
    auto depth = std::make_shared<RawDepth>();
    try {
      depth->stamp_us = image->getTimestamp();
      depth->width = image->getWidth();
      depth->height = image->getHeight();
      depth->mm.resize(static_cast<std::size_t>(depth->width) * depth->height);
      image->fillDepthImageRaw(depth->width, depth->height, depth->mm.data());
    }
    catch (const std::exception& failure) {
      setError(file + ": cannot read a depth frame: " + errorText(failure));
      return;
    }
    const auto no_sample = image->getNoSampleValue();
    const auto shadow = image->getShadowValue();
    for (auto& value : depth->mm)
      if (value == no_sample || value == shadow)
        value = 0;

    std::unique_lock<std::mutex> lock(mutex);
    if (stopping)
      return;
    if (depth_received >= depth_count)
      return; // beyond the recorded count: playback wrapped around, not ours
    if (depth_received > 0 && depth->stamp_us <= last_depth_stamp_us) {
      // Time went backwards: the player restarted before the announced frame count.
      if (error.empty())
        error = file + ": recording ends after " + std::to_string(depth_received) +
                " of " + std::to_string(depth_count) + " depth frames (truncated?)";
      changed.notify_all();
      return;
    }
    last_depth_stamp_us = depth->stamp_us;
    depths.push_back(depth);
    ++depth_received;
    changed.notify_all();
  }

  /// OpenNI thread: a colour frame arrived (copied at once, see onDepth()).
  void onImage(const pcl::io::Image::Ptr& frame)
  {
    auto image = std::make_shared<RawColor>();
    try {
      // Delivered at the depth resolution (PCL subsamples by an integer factor).
      image->stamp_us = frame->getTimestamp();
      image->width = depth_width;
      image->height = depth_height;
      image->rgb.resize(3 * static_cast<std::size_t>(image->width) * image->height);
      frame->fillRGB(image->width, image->height, image->rgb.data());
    }
    catch (const std::exception& failure) {
      setError(file + ": cannot read a colour frame of " +
               std::to_string(frame->getWidth()) + "x" +
               std::to_string(frame->getHeight()) + " px: " + errorText(failure));
      return;
    }

    std::unique_lock<std::mutex> lock(mutex);
    if (stopping)
      return;
    if (image_received >= color_count)
      return;
    images.push_back(image);
    ++image_received;
    changed.notify_all();
  }

  /// Asks the player (in manual mode) for the next record. waitForAnyStream() pokes
  /// the device when no frame is pending; the grabber's listeners then read the frame
  /// and call onDepth()/onImage(). Timeout 0: one poke, no waiting here.
  void step()
  {
    int ready = -1;
    openni::OpenNI::waitForAnyStream(streams.data(), static_cast<int>(streams.size()),
                                     &ready, 0);
  }

  /// True when the front depth frame can be paired: a colour frame at or after its
  /// time has arrived, or no further colour frame will come.
  bool pairReady() const
  {
    if (depths.empty() || images.empty())
      return false;
    if (image_received >= color_count)
      return true;
    return images.back()->stamp_us >= depths.front()->stamp_us;
  }

  /// Pops the front depth frame with the colour frame nearest in time (lock held).
  std::pair<DepthPtr, ImagePtr> takePair()
  {
    DepthPtr depth = depths.front();
    depths.pop_front();
    const auto t = static_cast<double>(depth->stamp_us);
    std::size_t best = 0;
    for (std::size_t i = 1; i < images.size(); ++i)
      if (std::abs(static_cast<double>(images[i]->stamp_us) - t) <
          std::abs(static_cast<double>(images[best]->stamp_us) - t))
        best = i;
    // Older colour frames can never be nearer for a later depth frame.
    images.erase(images.begin(), images.begin() + static_cast<std::ptrdiff_t>(best));
    return {depth, images.front()};
  }

  void stop() noexcept
  {
    {
      std::lock_guard<std::mutex> lock(mutex);
      stopping = true;
    }
    changed.notify_all();
    if (grabber) {
      try {
        grabber->stop();
      }
      catch (...) {
        // Destruction must not throw; the device is released below anyway.
      }
      grabber.reset();
    }
  }
};

OniFileSource::OniFileSource(const std::string& file)
    : file_(file)
    , impl_(std::make_unique<Impl>())
{
  impl_->file = file;
  checkOniHeader(file);

  Impl& impl = *impl_;
  try {
    impl.grabber = pcl::make_shared<pcl::io::OpenNI2Grabber>(file);
    auto device = impl.grabber->getDevice();
    if (!device || !device->isFile())
      fail(file + ": OpenNI2 did not open the file as a recording");
    if (!device->hasColorSensor())
      fail(file + ": the recording has no colour stream");
    const int depth_count = device->getDepthFrameCount();
    const int color_count = device->getColorFrameCount();
    if (depth_count <= 0 || color_count <= 0)
      fail(file + ": the recording holds " + std::to_string(depth_count) +
           " depth and " + std::to_string(color_count) + " colour frames");
    impl.depth_count = static_cast<std::size_t>(depth_count);
    impl.color_count = static_cast<std::size_t>(color_count);

    // The grabber's own projection model for its XYZRGBA clouds: fx = fy from the
    // depth stream's field of view, principal point at the image centre.
    const auto mode = device->getDepthVideoMode();
    impl.depth_width = mode.x_resolution_;
    impl.depth_height = mode.y_resolution_;
    double focal = device->getDepthFocalLength();
    if (!(focal > 0.0) || !std::isfinite(focal)) {
      // The grabber would produce infinite coordinates; use the usual VGA value.
      focal = FALLBACK_FOCAL_VGA_PX * mode.x_resolution_ / 640.0;
      PCL_WARN("[dynvo::OniFileSource] %s: the depth stream reports no field of view; "
               "assuming a focal length of %g px\n",
               file.c_str(), focal);
    }
    impl.intrinsics.fx = impl.intrinsics.fy = focal;
    impl.intrinsics.cx = (static_cast<double>(mode.x_resolution_) - 1.0) / 2.0;
    impl.intrinsics.cy = (static_cast<double>(mode.y_resolution_) - 1.0) / 2.0;

    // The device opens recordings at speed 1.0 (real time), where a slow reader loses
    // frames, and at 0 ("as fast as possible") the player laps the reader. Speed -1 is
    // OpenNI2's manual mode: the player emits the next record only when poked, which
    // next() does through step(), so frames come one at a time and none is dropped.
    if (!device->setPlaybackSpeed(-1.0))
      fail(file + ": OpenNI2 refuses manual (stepped) playback");
    // Play once; a truncated file then stalls (reported) instead of repeating.
    if (auto oni_device = DeviceStreams::device(*device))
      if (auto* playback = oni_device->getPlaybackControl())
        playback->setRepeatEnabled(false);

    // Separate image and depth signals, paired here: the grabber's own
    // image+depth synchronizer holds back the last pair of a recording.
    std::function<pcl::io::OpenNI2Grabber::sig_cb_openni_depth_image> on_depth =
        [&impl](const pcl::io::DepthImage::Ptr& depth) {
          impl.onDepth(depth);
        };
    std::function<pcl::io::OpenNI2Grabber::sig_cb_openni_image> on_image =
        [&impl](const pcl::io::Image::Ptr& image) {
          impl.onImage(image);
        };
    impl.grabber->registerCallback(on_depth);
    impl.grabber->registerCallback(on_image);
    impl.grabber->start();
    impl.depth_stream = DeviceStreams::depth(*device);
    impl.color_stream = DeviceStreams::color(*device);
    if (!impl.depth_stream || !impl.color_stream)
      fail(file + ": the grabber did not open the depth and colour streams");
    impl.streams = {impl.depth_stream.get(), impl.color_stream.get()};
  }
  catch (const SourceError&) {
    impl.stop();
    throw;
  }
  catch (const std::exception& error) {
    impl.stop();
    fail(file + ": cannot play the recording: " + errorText(error));
  }
  PCL_DEBUG("[dynvo::OniFileSource] %s: %zu depth and %zu colour frames\n",
            file.c_str(), impl.depth_count, impl.color_count);
}

OniFileSource::~OniFileSource()
{
  if (impl_)
    impl_->stop();
}

std::size_t
OniFileSource::size() const
{
  return impl_->depth_count;
}

bool
OniFileSource::next(Frame& frame)
{
  Impl& impl = *impl_;
  std::pair<Impl::DepthPtr, Impl::ImagePtr> pair;
  std::size_t index = 0;
  {
    std::unique_lock<std::mutex> lock(impl.mutex);
    if (impl.delivered >= impl.depth_count)
      return false;
    index = impl.delivered;
    // Step the player until the pair is complete; the stall clock restarts whenever
    // a frame arrives.
    std::size_t seen = impl.depth_received + impl.image_received;
    auto deadline = std::chrono::steady_clock::now() + STALL_TIMEOUT;
    while (!impl.pairReady()) {
      if (!impl.error.empty())
        fail(impl.error);
      if (std::chrono::steady_clock::now() > deadline)
        fail(impl.file + ": playback stalled after " + std::to_string(index) + " of " +
             std::to_string(impl.depth_count) + " frames");
      lock.unlock();
      impl.step();
      lock.lock();
      impl.changed.wait_for(lock, STEP_WAIT, [&impl, seen] {
        return impl.pairReady() || !impl.error.empty() ||
               impl.depth_received + impl.image_received != seen;
      });
      if (impl.depth_received + impl.image_received != seen) {
        seen = impl.depth_received + impl.image_received;
        deadline = std::chrono::steady_clock::now() + STALL_TIMEOUT;
      }
    }
    pair = impl.takePair();
    ++impl.delivered;
  }

  const auto& [depth, image] = pair;
  Frame out;
  out.timestamp = out.depth_timestamp = static_cast<double>(depth->stamp_us) * 1e-6;
  out.name = impl.file + "#" + std::to_string(index);
  if (image->width != depth->width || image->height != depth->height)
    fail(out.name + ": colour frame is " + std::to_string(image->width) + "x" +
         std::to_string(image->height) + " but depth frame is " +
         std::to_string(depth->width) + "x" + std::to_string(depth->height));
  out.depth.width = depth->width;
  out.depth.height = depth->height;
  out.depth.data.resize(depth->mm.size());
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (std::size_t i = 0; i < depth->mm.size(); ++i)
    out.depth.data[i] =
        depth->mm[i] == 0 ? nan : static_cast<float>(depth->mm[i]) * 0.001f; // mm -> m
  out.color.width = image->width;
  out.color.height = image->height;
  out.color.data = image->rgb;
  out.cloud = makeOrganizedCloud(out.color, out.depth, impl.intrinsics);
  out.cloud->header.stamp = depth->stamp_us;
  out.cloud->header.seq = static_cast<std::uint32_t>(index);
  frame = std::move(out);
  return true;
}

} // namespace dynvo

#else // DYNVO_HAVE_OPENNI2

namespace dynvo {

struct OniFileSource::Impl {};

OniFileSource::OniFileSource(const std::string& file)
{
  throw pcl::IOException(file + ": dynvo was built without OpenNI2");
}

OniFileSource::~OniFileSource() = default;

std::size_t
OniFileSource::size() const
{
  return 0;
}

bool
OniFileSource::next(Frame&)
{
  return false;
}

} // namespace dynvo

#endif // DYNVO_HAVE_OPENNI2
