// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/common/timestamps.h>
#include <dynvo/io/pcd_sequence_source.h>

#include <pcl/exceptions.h>
#include <pcl/io/pcd_io.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>

namespace dynvo {

namespace fs = std::filesystem;

namespace {

/// The file name without extension as a number, or NaN when it is not one.
double
stampFromName(const std::string& file)
{
  const std::string stem = fs::path(file).stem().string();
  double stamp = std::numeric_limits<double>::quiet_NaN();
  parseDecimal(stem, stamp);
  return stamp;
}

/// The largest LZF expansion: a 3-byte back reference stands for at most 264 bytes.
constexpr std::uint64_t LZF_MAX_EXPANSION = 88;

/** Refuses a header that claims more data than the file can hold, or a frame over the
 * limit, before PCL allocates anything for it (PCL trusts the header: a 0.3 MB file could
 * make it allocate gigabytes). */
void
checkPcdHeader(const std::string& file,
               const pcl::PCLPointCloud2& blob,
               int data_type,
               unsigned int data_index,
               std::uint64_t max_pixels)
{
  checkFrameSize(file, blob.width, blob.height, max_pixels);
  std::uint64_t point_bytes = 0, values = 0;
  for (const pcl::PCLPointField& field : blob.fields) {
    point_bytes += std::uint64_t{field.count} * pcl::getFieldSize(field.datatype);
    values += field.count;
  }
  std::error_code error;
  const std::uint64_t size = fs::file_size(file, error);
  if (error || data_index > size)
    throw pcl::IOException(file + ": truncated PCD file (no data after the header)");
  const std::uint64_t points = std::uint64_t{blob.width} * blob.height;
  const std::uint64_t remaining = size - data_index;
  const auto too_large = [&](std::uint64_t per_point, std::uint64_t available) {
    return per_point == 0 || points > available / per_point;
  };
  const std::string claim = file + ": the header's " + std::to_string(points) +
                            " points of " + std::to_string(point_bytes) + " bytes ";
  if (data_type == 0 && too_large(values, remaining)) // at least a character per value
    throw pcl::IOException(claim + "cannot be in the " + std::to_string(remaining) +
                           " bytes of ASCII data (truncated or corrupt)");
  if (data_type == 1 && too_large(point_bytes, remaining))
    throw pcl::IOException(claim + "need more than the " + std::to_string(remaining) +
                           " bytes of binary data (truncated or corrupt)");
  if (data_type == 2) {
    std::uint32_t sizes[2] = {0, 0}; // compressed, uncompressed
    std::ifstream in(file, std::ios::binary);
    in.seekg(data_index);
    if (!in.read(reinterpret_cast<char*>(sizes), sizeof(sizes)) ||
        sizes[0] > remaining - sizeof(sizes))
      throw pcl::IOException(file + ": truncated compressed PCD data");
    if (too_large(point_bytes, sizes[1]) || points * point_bytes != sizes[1] ||
        sizes[1] > LZF_MAX_EXPANSION * std::uint64_t{sizes[0]})
      throw pcl::IOException(claim + "disagree with the compressed block (" +
                             std::to_string(sizes[0]) + " bytes for " +
                             std::to_string(sizes[1]) + "; corrupt)");
  }
}

} // namespace

bool
naturalLess(const std::string& a, const std::string& b)
{
  std::size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    const bool da = std::isdigit(static_cast<unsigned char>(a[i]));
    const bool db = std::isdigit(static_cast<unsigned char>(b[j]));
    if (da && db) {
      std::size_t ei = i, ej = j;
      while (ei < a.size() && std::isdigit(static_cast<unsigned char>(a[ei])))
        ++ei;
      while (ej < b.size() && std::isdigit(static_cast<unsigned char>(b[ej])))
        ++ej;
      // Compare digit runs as numbers: skip leading zeros, then length, then digits.
      std::size_t si = i, sj = j;
      while (si + 1 < ei && a[si] == '0')
        ++si;
      while (sj + 1 < ej && b[sj] == '0')
        ++sj;
      if (ei - si != ej - sj)
        return ei - si < ej - sj;
      const int order = a.compare(si, ei - si, b, sj, ej - sj);
      if (order != 0)
        return order < 0;
      i = ei;
      j = ej;
    }
    else {
      if (a[i] != b[j])
        return a[i] < b[j];
      ++i;
      ++j;
    }
  }
  if ((a.size() - i) != (b.size() - j))
    return a.size() - i < b.size() - j;
  return a < b;
}

PcdSequenceSource::PcdSequenceSource(const std::string& folder,
                                     double fps,
                                     std::uint64_t max_frame_pixels)
    : folder_(folder)
    , fps_(fps)
    , max_frame_pixels_(max_frame_pixels)
{
  if (!(fps > 0.0) || !std::isfinite(fps))
    throw std::invalid_argument(
        "[dynvo::PcdSequenceSource] fps must be positive, got " + std::to_string(fps));
  if (!fs::is_directory(folder))
    throw pcl::IOException(folder + ": not a directory");
  for (const auto& entry : fs::directory_iterator(folder))
    if (entry.is_regular_file() && entry.path().extension() == ".pcd")
      files_.push_back(entry.path().string());
  if (files_.empty())
    throw pcl::IOException(folder + ": no .pcd file");
  // Timestamp names sort by value ("1.25" before "1.5"), any other name naturally.
  std::sort(files_.begin(), files_.end(),
            [](const std::string& a, const std::string& b) {
              const double ta = stampFromName(a), tb = stampFromName(b);
              if (std::isfinite(ta) && std::isfinite(tb) && ta != tb)
                return ta < tb;
              return naturalLess(fs::path(a).filename().string(),
                                 fs::path(b).filename().string());
            });
}

bool
PcdSequenceSource::next(Frame& frame)
{
  if (cursor_ >= files_.size())
    return false;
  const std::string& file = files_[cursor_];

  // PCL 1.13 dereferences garbage when a header has no fields or points, so the header
  // is checked on its own first.
  pcl::PCDReader reader;
  pcl::PCLPointCloud2 blob;
  Eigen::Vector4f origin;
  Eigen::Quaternionf orientation;
  int version = 0, data_type = 0;
  unsigned int data_index = 0;
  if (reader.readHeader(file, blob, origin, orientation, version, data_type,
                        data_index) != 0 ||
      blob.fields.empty() || blob.width * blob.height == 0)
    throw pcl::IOException(file + ": cannot read PCD file (missing or corrupt header)");
  checkPcdHeader(file, blob, data_type, data_index, max_frame_pixels_);
  if (reader.read(file, blob) != 0)
    throw pcl::IOException(file + ": cannot read PCD file (corrupt or truncated data)");
  if (blob.height <= 1)
    throw pcl::IOException(file + ": cloud is not organized (height " +
                           std::to_string(blob.height) + ")");
  const auto has_field = [&](const std::string& name) {
    return std::any_of(blob.fields.begin(), blob.fields.end(),
                       [&](const pcl::PCLPointField& f) {
                         return f.name == name;
                       });
  };
  if (!has_field("x") || !has_field("y") || !has_field("z"))
    throw pcl::IOException(file + ": cloud has no x, y, z fields");
  if (!has_field("rgb") && !has_field("rgba"))
    throw pcl::IOException(file + ": cloud has no rgb or rgba field");

  Frame out;
  out.name = file;
  out.cloud = pcl::make_shared<pcl::PointCloud<pcl::PointXYZRGB>>();
  pcl::fromPCLPointCloud2(blob, *out.cloud);

  const double stamp = stampFromName(file);
  out.timestamp = std::isfinite(stamp) ? stamp : static_cast<double>(cursor_) / fps_;

  const auto& cloud = *out.cloud;
  out.color.width = out.depth.width = cloud.width;
  out.color.height = out.depth.height = cloud.height;
  out.color.data.resize(3 * cloud.size());
  out.depth.data.resize(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    out.color.data[3 * i] = cloud[i].r;
    out.color.data[3 * i + 1] = cloud[i].g;
    out.color.data[3 * i + 2] = cloud[i].b;
    out.depth.data[i] = std::isfinite(cloud[i].z) && cloud[i].z > 0.0f
                            ? cloud[i].z
                            : std::numeric_limits<float>::quiet_NaN();
  }
  frame = std::move(out);
  ++cursor_;
  return true;
}

} // namespace dynvo
