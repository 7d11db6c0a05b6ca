// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/io/pcd_sequence_source.h>

#include <pcl/exceptions.h>
#include <pcl/io/pcd_io.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <limits>

namespace dynvo {

namespace fs = std::filesystem;

namespace {

/// The file name without extension as a number, or NaN when it is not one.
double
stampFromName(const std::string& file)
{
  const std::string stem = fs::path(file).stem().string();
  std::size_t used = 0;
  double stamp = std::numeric_limits<double>::quiet_NaN();
  try {
    stamp = std::stod(stem, &used);
  }
  catch (const std::exception&) {
    used = 0;
  }
  return used == stem.size() && std::isfinite(stamp)
             ? stamp
             : std::numeric_limits<double>::quiet_NaN();
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

PcdSequenceSource::PcdSequenceSource(const std::string& folder, double fps)
    : fps_(fps)
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
