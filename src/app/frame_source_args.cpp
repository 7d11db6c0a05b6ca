// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/app/frame_source_args.h>
#include <dynvo/common/parallel.h>
#include <dynvo/io/oni_file_source.h>
#include <dynvo/io/pcd_sequence_source.h>
#include <dynvo/io/tum_folder_source.h>

#include <pcl/console/print.h>

#include <cstdint>
#include <algorithm>
#include <future>
#include <limits>
#include <memory>

namespace dynvo::app {

std::vector<Option>
frameSourceOptions()
{
  std::string presets;
  for (const auto& name : CameraIntrinsics::presetNames())
    presets += (presets.empty() ? "" : "|") + name;
  return {
      {"tum_dir", "DIR", "TUM RGB-D folder (rgb.txt + depth.txt, or associations.txt)"},
      {"pcd_dir", "DIR", "folder of organized .pcd files, natural name order"},
      {"oni", "FILE", "OpenNI .oni recording"},
      {"camera", presets, "intrinsics preset (default: default = 525 525 319.5 239.5)"},
      {"fx", "PX", "focal length x, overrides the preset"},
      {"fy", "PX", "focal length y, overrides the preset"},
      {"cx", "PX", "principal point x, overrides the preset"},
      {"cy", "PX", "principal point y, overrides the preset"},
      {"distortion", "K1,K2,P1,P2,K3",
       "lens distortion (OpenCV's order; 0,0,0,0,0 for none), overrides the preset; "
       "the "
       "images are undistorted as they are read"},
      {"depth_scale", "S",
       "raw depth units per metre (default: 5000 TUM, 1000 associations.txt)"},
      {"fps", "HZ",
       "frame rate for PCD files whose names are not timestamps (default 30)"},
      {"max_frame_pixels", "N",
       "refuse larger frames before reading them (default " +
           std::to_string(DEFAULT_MAX_FRAME_PIXELS) + " = 4096x4096)"},
  };
}

CameraIntrinsics
intrinsicsFromArguments(const Arguments& args)
{
  CameraIntrinsics intrinsics;
  try {
    intrinsics = CameraIntrinsics::fromPreset(args.string("camera", "default"));
  }
  catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  intrinsics.fx = args.number("fx", intrinsics.fx);
  intrinsics.fy = args.number("fy", intrinsics.fy);
  intrinsics.cx = args.number("cx", intrinsics.cx);
  intrinsics.cy = args.number("cy", intrinsics.cy);
  const auto& k = intrinsics.distortion;
  const std::vector<double> distortion =
      args.numbers("distortion", k.size(), std::vector<double>(k.begin(), k.end()));
  std::copy(distortion.begin(), distortion.end(), intrinsics.distortion.begin());
  try {
    intrinsics.validate();
  }
  catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  return intrinsics;
}

FrameSource::Ptr
openFrameSource(const Arguments& args)
{
  const int given = args.has("tum_dir") + args.has("pcd_dir") + args.has("oni");
  if (given != 1)
    throw UsageError("give exactly one of -tum_dir, -pcd_dir, -oni");
  const auto max_pixels = static_cast<std::uint64_t>(
      args.integer("max_frame_pixels", static_cast<long>(DEFAULT_MAX_FRAME_PIXELS), 1,
                   std::numeric_limits<long>::max()));
  if (args.has("pcd_dir")) {
    const double fps = args.number("fps", 30.0);
    if (!(fps > 0.0))
      throw UsageError("-fps must be positive");
    return std::make_unique<PcdSequenceSource>(args.string("pcd_dir"), fps, max_pixels);
  }
  if (args.has("oni"))
    return std::make_unique<OniFileSource>(args.string("oni"));
  TumFolderSource::Options options;
  options.intrinsics = intrinsicsFromArguments(args);
  options.depth_scale = args.number("depth_scale", 0.0);
  options.max_frame_pixels = max_pixels;
  if (args.has("depth_scale") && !(options.depth_scale > 0.0))
    throw UsageError("-depth_scale must be positive");
  return std::make_unique<TumFolderSource>(args.string("tum_dir"), options);
}

FrameLoopEnd
processFrames(FrameSource& source,
              std::size_t max_frames,
              const std::function<void(const Frame&)>& process,
              bool read_ahead)
{
  FrameLoopEnd end;
  std::string where; // the frame in hand, once it has been read
  const auto wanted = [max_frames](std::size_t k) {
    return max_frames == 0 || k < max_frames;
  };
  // The next frame, none at the end of the recording.
  const auto read = [&source] {
    auto frame = std::make_unique<Frame>();
    if (!source.next(*frame))
      frame.reset();
    return frame;
  };
  // Last, so that a read still running when the loop stops ends before anything it uses.
  std::unique_ptr<TaskThread> reader;
  if (read_ahead)
    reader = std::make_unique<TaskThread>();
  try {
    const auto readNext = [&] {
      return reader ? reader->run(read) : std::async(std::launch::deferred, read);
    };
    std::future<std::unique_ptr<Frame>> next;
    if (wanted(0))
      next = readNext();
    while (next.valid()) {
      const std::unique_ptr<Frame> frame = next.get();
      if (!frame)
        break;
      if (wanted(end.frames + 1))
        next = readNext();
      where = frame->name + ": ";
      process(*frame);
      where.clear();
      ++end.frames;
    }
  }
  catch (const std::exception& e) {
    // Reader errors name their file already; anything else is about the frame in hand.
    end.error = shortenLongWords(where + errorMessage(e));
    if (end.frames == 0)
      pcl::console::print_error("Error: %s (stopped at the first frame; no output "
                                "is written or replaced)\n",
                                end.error.c_str());
    else
      pcl::console::print_error("Error: %s (stopped after %zu frames; the outputs of "
                                "those are written)\n",
                                end.error.c_str(), end.frames);
  }
  return end;
}

} // namespace dynvo::app
