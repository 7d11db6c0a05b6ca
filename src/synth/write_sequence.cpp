// SPDX-License-Identifier: BSD-3-Clause
// SceneSynthesizer::writeSequence: the TUM folder layout, frames written in parallel.
#include <dynvo/io/label_io.h>
#include <dynvo/io/trajectory_io.h>
#include <dynvo/synth/scene_synthesizer.h>

#include "synthesizer_impl.h"

#include <pcl/exceptions.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <atomic>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <stdexcept>
#include <thread>

namespace dynvo {

namespace fs = std::filesystem;

namespace {

/// zlib level 1: the textures are incompressible noise, so higher levels buy little.
constexpr int PNG_COMPRESSION = 1;

} // namespace

void
detail::writePng(const fs::path& path, const cv::Mat& image)
{
  bool written = false;
  try {
    written = cv::imwrite(path.string(), image,
                          {cv::IMWRITE_PNG_COMPRESSION, PNG_COMPRESSION});
  }
  catch (const cv::Exception& e) {
    throw pcl::IOException(path.string() + ": cannot write PNG (" + e.what() + ")");
  }
  if (!written)
    throw pcl::IOException(path.string() + ": cannot write PNG");
}

namespace {

void
writeFrame(const fs::path& root, const SynthFrame& frame)
{
  const int width = static_cast<int>(frame.color.width);
  const int height = static_cast<int>(frame.color.height);
  cv::Mat bgr(height, width, CV_8UC3);
  cv::Mat depth(height, width, CV_16UC1);
  for (int v = 0; v < height; ++v) {
    std::uint8_t* out = bgr.ptr<std::uint8_t>(v);
    std::uint16_t* raw = depth.ptr<std::uint16_t>(v);
    for (int u = 0; u < width; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * width + u;
      for (int channel = 0; channel < 3; ++channel) // OpenCV stores BGR
        out[3 * u + channel] = frame.color.data[3 * i + 2 - channel];
      const float z = frame.depth.data[i];
      raw[u] = std::isnan(z) ? 0
                             : cv::saturate_cast<std::uint16_t>(
                                   std::round(z * SceneSynthesizer::DEPTH_PNG_SCALE));
    }
  }
  detail::writeFrameFiles(root, frame.timestamp, frame.depth_timestamp, bgr, depth,
                          frame.labels);
}

} // namespace

void
detail::writeFrameFiles(const fs::path& root,
                        double rgb_stamp,
                        double depth_stamp,
                        const cv::Mat& bgr,
                        const cv::Mat& depth,
                        const std::vector<std::uint8_t>& labels)
{
  writePng(root / "rgb" / stampedPngName(rgb_stamp), bgr);
  writePng(root / "depth" / stampedPngName(depth_stamp), depth);
  writeLabelImage((root / "labels" / stampedPngName(rgb_stamp)).string(),
                  {static_cast<std::uint32_t>(bgr.cols),
                   static_cast<std::uint32_t>(bgr.rows), labels});
}

void
detail::prepareFolder(const fs::path& root)
{
  std::error_code error;
  if (fs::exists(root, error)) {
    if (!fs::is_directory(root, error))
      throw pcl::IOException(root.string() + ": exists and is not a folder");
    if (!fs::is_empty(root, error) || error)
      throw pcl::IOException(root.string() +
                             ": folder is not empty; refusing to write into it");
  }
  for (const char* sub : {"rgb", "depth", "labels"}) {
    fs::create_directories(root / sub, error);
    if (error)
      throw pcl::IOException((root / sub).string() + ": cannot create folder (" +
                             error.message() + ")");
  }
}

namespace {

/// Opens a text file for writing. \throws pcl::IOException
std::ofstream
openText(const fs::path& path)
{
  std::ofstream out(path, std::ios::trunc);
  if (!out)
    throw pcl::IOException(path.string() + ": cannot write file");
  return out;
}

void
closeText(std::ofstream& out, const fs::path& path)
{
  out.close();
  if (!out)
    throw pcl::IOException(path.string() + ": write failed");
}

} // namespace

void
SceneSynthesizer::writeSequence(const std::string& folder, int threads) const
{
  if (threads < 1)
    throw std::invalid_argument("[dynvo::SceneSynthesizer::writeSequence] threads must "
                                "be >= 1, got " +
                                std::to_string(threads));
  const fs::path root(folder);
  detail::prepareFolder(root);
  const int frames = impl_->options.frames;

  std::atomic<int> next_frame{0};
  std::atomic<bool> failed{false};
  std::exception_ptr first_error;
  std::mutex error_mutex;
  const auto worker = [&]() {
    try {
      for (int k = next_frame++; k < frames && !failed; k = next_frame++)
        writeFrame(root, render(k));
    }
    catch (...) {
      const std::lock_guard<std::mutex> lock(error_mutex);
      if (!first_error)
        first_error = std::current_exception();
      failed = true;
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < std::min(threads, frames); ++t)
    pool.emplace_back(worker);
  worker();
  for (std::thread& thread : pool)
    thread.join();
  if (first_error)
    std::rethrow_exception(first_error);

  std::vector<FrameScript> scripts;
  Trajectory trajectory;
  for (int k = 0; k < frames; ++k) {
    scripts.push_back(impl_->script(k));
    trajectory.push_back({scripts.back().timestamp, scripts.back().T_world_camera});
  }
  detail::writeIndexFiles(root,
                          "# dynvo synthetic scenario '" + impl_->options.scenario +
                              "', seed " + std::to_string(impl_->options.seed) + "\n",
                          scripts, trajectory);
}

void
detail::writeIndexFiles(const fs::path& root,
                        const std::string& origin,
                        const std::vector<FrameScript>& scripts,
                        const Trajectory& groundtruth)
{
  const fs::path rgb_path = root / "rgb.txt", depth_path = root / "depth.txt";
  const fs::path objects_path = root / "objects.txt";
  std::ofstream rgb = openText(rgb_path), depth = openText(depth_path);
  std::ofstream objects = openText(objects_path);
  rgb << "# color images\n" << origin << "# timestamp filename\n";
  depth << "# depth maps (16-bit PNG, " << SceneSynthesizer::DEPTH_PNG_SCALE
        << " per metre, 0 = none)\n"
        << origin << "# timestamp filename\n";
  objects << "# object poses (object-to-world, metres); moving = pose changed since "
             "the previous frame\n"
          << origin << "# timestamp id tx ty tz qx qy qz qw moving\n";
  for (const FrameScript& script : scripts) {
    const std::string colour = formatStamp(script.timestamp);
    const std::string depth_stamp = formatStamp(script.depth_timestamp);
    rgb << colour << " rgb/" << colour << ".png\n";
    depth << depth_stamp << " depth/" << depth_stamp << ".png\n";
    for (const ObjectState& object : script.objects) {
      std::string line = formatTumLine({script.timestamp, object.T_world_object});
      line.insert(line.find(' '), " " + std::to_string(object.id));
      objects << line << ' ' << (object.moving ? 1 : 0) << '\n';
    }
  }
  closeText(rgb, rgb_path);
  closeText(depth, depth_path);
  closeText(objects, objects_path);
  writeTrajectory((root / "groundtruth.txt").string(), groundtruth);
}

} // namespace dynvo
