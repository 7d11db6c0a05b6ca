// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/common/timestamps.h>
#include <dynvo/io/image_io.h>
#include <dynvo/common/lens_undistortion.h>
#include <dynvo/io/tum_folder_source.h>

#include <pcl/console/print.h>
#include <pcl/exceptions.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

namespace dynvo {

namespace fs = std::filesystem;

namespace {

[[noreturn]] void
fail(const std::string& message)
{
  throw pcl::IOException(message);
}

/// Non-comment, non-blank lines of a text file with their 1-based line numbers.
std::vector<std::pair<int, std::string>>
readIndexLines(const fs::path& path)
{
  std::ifstream in(path);
  if (!in)
    fail(path.string() + ": cannot open file");
  std::vector<std::pair<int, std::string>> lines;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#')
      continue;
    lines.emplace_back(number, line);
  }
  return lines;
}

struct StampedFile {
  double stamp;
  std::string file;
};

double
parseStamp(const std::string& token, const fs::path& path, int line)
{
  double stamp = 0.0;
  if (!parseDecimal(token, stamp))
    fail(path.string() + ":" + std::to_string(line) + ": bad timestamp '" + token +
         "' (expected a finite decimal number of seconds)");
  return stamp;
}

std::vector<StampedFile>
readFileList(const fs::path& path)
{
  std::vector<StampedFile> list;
  for (const auto& [number, line] : readIndexLines(path)) {
    std::istringstream tokens(line);
    std::string stamp, file;
    if (!(tokens >> stamp >> file))
      fail(path.string() + ":" + std::to_string(number) +
           ": expected 'timestamp filename'");
    list.push_back({parseStamp(stamp, path, number), file});
  }
  if (list.empty())
    fail(path.string() + ": no entries");
  return list;
}

/// Metres from raw units: raw * (1 / scale) in single precision; raw 0 becomes NaN.
DepthImage
toMetres(const RawDepthImage& raw, double depth_scale)
{
  DepthImage depth;
  depth.width = raw.width;
  depth.height = raw.height;
  depth.data.resize(raw.data.size());
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inv_scale = static_cast<float>(1.0 / depth_scale);
  for (std::size_t i = 0; i < raw.data.size(); ++i)
    depth.data[i] =
        raw.data[i] == 0 ? nan : static_cast<float>(raw.data[i]) * inv_scale;
  return depth;
}

} // namespace

TumFolderSource::TumFolderSource(const std::string& folder, const Options& options)
    : folder_(folder)
    , options_(options)
{
  options_.intrinsics.validate();
  if (!(options_.depth_scale >= 0.0) || !std::isfinite(options_.depth_scale))
    throw std::invalid_argument(
        "[dynvo::TumFolderSource] depth scale must be positive");
  const fs::path dir(folder);
  if (!fs::is_directory(dir))
    fail(folder + ": not a directory");

  const fs::path associations = dir / "associations.txt";
  if (fs::exists(associations) && !fs::exists(dir / "rgb.txt")) {
    depth_scale_ = options_.depth_scale > 0.0 ? options_.depth_scale : 1000.0;
    for (const auto& [number, line] : readIndexLines(associations)) {
      std::istringstream tokens(line);
      std::string t_rgb, rgb, t_depth, depth;
      if (!(tokens >> t_rgb >> rgb >> t_depth >> depth))
        fail(associations.string() + ":" + std::to_string(number) +
             ": expected 't_rgb rgb_file t_depth depth_file'");
      entries_.push_back({parseStamp(t_rgb, associations, number), rgb,
                          parseStamp(t_depth, associations, number), depth});
    }
  }
  else {
    depth_scale_ = options_.depth_scale > 0.0 ? options_.depth_scale : 5000.0;
    const auto rgb = readFileList(dir / "rgb.txt");
    const auto depth = readFileList(dir / "depth.txt");
    std::vector<double> rgb_stamps, depth_stamps;
    for (const auto& entry : rgb)
      rgb_stamps.push_back(entry.stamp);
    for (const auto& entry : depth)
      depth_stamps.push_back(entry.stamp);
    for (const auto& [i, j] :
         associateTimestamps(rgb_stamps, depth_stamps, options_.max_difference))
      entries_.push_back({rgb[i].stamp, rgb[i].file, depth[j].stamp, depth[j].file});
    if (entries_.size() < rgb.size())
      PCL_WARN(
          "[dynvo::TumFolderSource] %s: %zu of %zu colour images have no depth "
          "image within %g s (duplicate, out-of-order or distant stamps in rgb.txt "
          "or depth.txt); those frames are skipped\n",
          folder.c_str(), rgb.size() - entries_.size(), rgb.size(),
          options_.max_difference);
  }
  if (entries_.empty())
    fail(folder + ": no colour image has a depth image within " +
         std::to_string(options_.max_difference) + " s");
  for (std::size_t i = 1; i < entries_.size(); ++i)
    if (!(entries_[i].rgb_stamp > entries_[i - 1].rgb_stamp))
      fail(folder + ": timestamps do not increase at entry " + std::to_string(i + 1) +
           " (" + entries_[i].rgb_file + ")");
}

std::vector<std::string>
TumFolderSource::inputPaths() const
{
  const fs::path dir(folder_);
  std::vector<std::string> paths;
  for (const char* index :
       {"rgb.txt", "depth.txt", "associations.txt", "groundtruth.txt"})
    if (fs::exists(dir / index))
      paths.push_back((dir / index).string());
  for (const Entry& entry : entries_)
    for (const std::string& file : {entry.rgb_file, entry.depth_file}) {
      const std::string folder = (dir / file).parent_path().string();
      if (std::find(paths.begin(), paths.end(), folder) == paths.end())
        paths.push_back(folder);
    }
  return paths;
}

Frame
TumFolderSource::read(std::size_t i) const
{
  const Entry& entry = entries_.at(i);
  const fs::path dir(folder_);
  Frame frame;
  frame.timestamp = entry.rgb_stamp;
  frame.depth_timestamp = entry.depth_stamp;
  frame.name = (dir / entry.rgb_file).string();
  frame.color =
      readColorImage((dir / entry.rgb_file).string(), options_.max_frame_pixels);
  frame.depth = toMetres(
      readRawDepthImage((dir / entry.depth_file).string(), options_.max_frame_pixels),
      depth_scale_);
  if (frame.color.width != frame.depth.width ||
      frame.color.height != frame.depth.height)
    fail((dir / entry.depth_file).string() + ": depth image size differs from " +
         entry.rgb_file);
  if (options_.intrinsics.distorted()) {
    if (!undistortion_ || undistortion_->width() != frame.color.width ||
        undistortion_->height() != frame.color.height)
      undistortion_ = std::make_shared<const LensUndistortion>(
          options_.intrinsics, frame.color.width, frame.color.height);
    undistortion_->undistort(frame.color, frame.depth);
    frame.undistortion = undistortion_;
  }
  frame.cloud = makeOrganizedCloud(frame.color, frame.depth, options_.intrinsics);
  return frame;
}

bool
TumFolderSource::next(Frame& frame)
{
  if (cursor_ >= entries_.size())
    return false;
  frame = read(cursor_);
  ++cursor_;
  return true;
}

} // namespace dynvo
