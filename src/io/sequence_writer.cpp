// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/io/image_io.h>
#include <dynvo/io/label_io.h>
#include <dynvo/io/sequence_writer.h>
#include <dynvo/io/trajectory_io.h>

#include <pcl/exceptions.h>

#include <filesystem>
#include <fstream>

namespace dynvo {

namespace fs = std::filesystem;

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

SequenceWriter::SequenceWriter(const std::string& folder, double depth_scale)
    : folder_(folder)
    , depth_scale_(depth_scale)
{
  const fs::path root(folder);
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

void
SequenceWriter::writeFrame(double rgb_stamp,
                           double depth_stamp,
                           const ColorImage& color,
                           const RawDepthImage& depth,
                           const LabelImage& labels) const
{
  const fs::path root(folder_);
  writeColorImage((root / "rgb" / stampedPngName(rgb_stamp)).string(), color);
  writeRawDepthImage((root / "depth" / stampedPngName(depth_stamp)).string(), depth);
  writeLabelImage((root / "labels" / stampedPngName(rgb_stamp)).string(), labels);
}

void
SequenceWriter::writeIndex(const std::string& origin,
                           const std::vector<SequenceIndexEntry>& entries,
                           const Trajectory& groundtruth) const
{
  const fs::path root(folder_);
  const fs::path rgb_path = root / "rgb.txt", depth_path = root / "depth.txt";
  const fs::path objects_path = root / "objects.txt";
  std::ofstream rgb = openText(rgb_path), depth = openText(depth_path);
  std::ofstream objects = openText(objects_path);
  rgb << "# color images\n" << origin << "# timestamp filename\n";
  depth << "# depth maps (16-bit PNG, " << depth_scale_ << " per metre, 0 = none)\n"
        << origin << "# timestamp filename\n";
  objects << "# object poses (object-to-world, metres); moving = pose changed since "
             "the previous frame\n"
          << origin << "# timestamp id tx ty tz qx qy qz qw moving\n";
  for (const SequenceIndexEntry& entry : entries) {
    const std::string colour = formatStamp(entry.rgb_stamp);
    const std::string depth_stamp = formatStamp(entry.depth_stamp);
    rgb << colour << " rgb/" << colour << ".png\n";
    depth << depth_stamp << " depth/" << depth_stamp << ".png\n";
    for (const ObjectPose& object : entry.objects) {
      std::string line = formatTumLine({entry.rgb_stamp, object.T_world_object});
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
