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
#include <sstream>
#include <vector>
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

/// Longest PCD header read when looking for its DATA line (real headers are ~200 bytes).
constexpr std::streamsize MAX_PCD_HEADER_BYTES = 64 * 1024;

/** Refuses a header that claims more data than the file can hold, or a frame over the
 * limit, before PCL reads it: PCL's readHeader() already allocates what the header claims
 * (a 0.3 MB file could make it allocate gigabytes). */
void
checkPcdHeader(const std::string& file, std::uint64_t max_pixels)
{
  std::ifstream in(file, std::ios::binary);
  if (!in)
    throw pcl::IOException(file + ": cannot open PCD file");
  const auto corrupt = [&file](const std::string& why) {
    return pcl::IOException(file + ": cannot read PCD file (corrupt header: " + why +
                            ")");
  };
  const auto number = [&](const std::string& token) {
    if (token.empty() || token.find_first_not_of("0123456789") != std::string::npos ||
        token.size() > 19)
      throw corrupt("'" + token + "' is not a count");
    return std::stoull(token);
  };
  std::vector<std::uint64_t> sizes, counts;
  std::uint64_t width = 0, height = 0, points = 0;
  std::string line, data;
  while (data.empty() && std::getline(in, line)) {
    if (in.tellg() > MAX_PCD_HEADER_BYTES)
      throw corrupt("no DATA line in its first 64 KB");
    std::istringstream tokens(line);
    std::string key, token;
    tokens >> key;
    // PCL matches a key by its first letters ("SIZEs" is SIZE), so this does too.
    const auto is = [&key](const char* name) {
      return key.rfind(name, 0) == 0;
    };
    const bool counted = is("WIDTH") || is("HEIGHT") || is("POINTS");
    std::vector<std::uint64_t> values;
    if (is("SIZE") || is("COUNT") || counted)
      while (tokens >> token)
        values.push_back(number(token));
    if (is("SIZE"))
      sizes = values;
    else if (is("COUNT"))
      counts = values;
    else if (counted)
      (is("WIDTH")    ? width
       : is("HEIGHT") ? height
                      : points) = values.size() == 1 ? values[0] : 0;
    else if (is("DATA") && !(tokens >> data))
      throw corrupt("DATA without a kind");
  }
  if (data.empty())
    throw corrupt("no DATA line");
  if (width == 0 || height == 0 || width > UINT32_MAX || height > UINT32_MAX ||
      points != width * height)
    throw corrupt("WIDTH " + std::to_string(width) + " x HEIGHT " +
                  std::to_string(height) + " must be POINTS " + std::to_string(points));
  checkFrameSize(file, static_cast<std::uint32_t>(width),
                 static_cast<std::uint32_t>(height), max_pixels);
  if (!counts.empty() && counts.size() != sizes.size())
    throw corrupt("SIZE and COUNT differ in length");
  std::uint64_t point_bytes = 0, values = 0;
  for (std::size_t f = 0; f < sizes.size(); ++f) {
    const std::uint64_t count = counts.empty() ? 1 : counts[f];
    if (sizes[f] > 8 || count > UINT32_MAX)
      throw corrupt("field " + std::to_string(f) + " has SIZE " +
                    std::to_string(sizes[f]) + " and COUNT " + std::to_string(count));
    point_bytes += sizes[f] * count;
    values += count;
  }
  const auto data_index = static_cast<std::uint64_t>(in.tellg());
  std::error_code error;
  const std::uint64_t size = fs::file_size(file, error);
  if (error || data_index > size)
    throw pcl::IOException(file +
                           ": cannot read PCD file (truncated: no data after the "
                           "header)");
  const std::uint64_t remaining = size - data_index;
  // PCL's classification: any other DATA kind is read as ASCII.
  const bool compressed = data.rfind("binary_compressed", 0) == 0;
  const bool binary = !compressed && data.rfind("binary", 0) == 0;
  const auto too_large = [points](std::uint64_t per_point, std::uint64_t available) {
    return per_point == 0 || points > available / per_point;
  };
  const std::string claim = file + ": cannot read PCD file: the header's " +
                            std::to_string(points) + " points of " +
                            std::to_string(point_bytes) + " bytes ";
  if (!binary && !compressed &&
      too_large(values, remaining)) // a character per value at least
    throw pcl::IOException(claim + "cannot be in the " + std::to_string(remaining) +
                           " bytes of ASCII data (truncated or corrupt)");
  if (binary && too_large(point_bytes, remaining))
    throw pcl::IOException(claim + "need more than the " + std::to_string(remaining) +
                           " bytes of binary data (truncated or corrupt)");
  if (compressed) {
    std::uint32_t block[2] = {0, 0}; // compressed, uncompressed size
    if (!in.read(reinterpret_cast<char*>(block), sizeof(block)) ||
        block[0] > remaining - sizeof(block))
      throw pcl::IOException(file +
                             ": cannot read PCD file (truncated compressed data)");
    if (too_large(point_bytes, block[1]) || points * point_bytes != block[1] ||
        block[1] > LZF_MAX_EXPANSION * std::uint64_t{block[0]})
      throw pcl::IOException(claim + "disagree with the compressed block (" +
                             std::to_string(block[0]) + " bytes for " +
                             std::to_string(block[1]) + "; corrupt)");
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

  // PCL 1.13 allocates what the header claims and dereferences garbage when a header has
  // no fields or points, so the header is checked on its own first.
  checkPcdHeader(file, max_frame_pixels_);
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
  const auto field = [&](const std::string& name) -> const pcl::PCLPointField* {
    const auto found = std::find_if(blob.fields.begin(), blob.fields.end(),
                                    [&](const pcl::PCLPointField& f) {
                                      return f.name == name;
                                    });
    return found == blob.fields.end() ? nullptr : &*found;
  };
  if (!field("x") || !field("y") || !field("z"))
    throw pcl::IOException(file + ": cloud has no x, y, z fields");
  const pcl::PCLPointField* colour = field("rgb") ? field("rgb") : field("rgba");
  if (!colour)
    throw pcl::IOException(file + ": cloud has no rgb or rgba field");
  // pcl::fromPCLPointCloud2 copies 4 bytes for each of these whatever the header declares,
  // so a smaller field would be read past the data (found by fuzz_pcd_header).
  for (const pcl::PCLPointField* f : {field("x"), field("y"), field("z"), colour})
    if (pcl::getFieldSize(f->datatype) != 4 || f->count != 1 ||
        std::uint64_t{f->offset} + 4 > blob.point_step)
      throw pcl::IOException(file + ": field '" + f->name +
                             "' must hold one 4-byte value (SIZE 4, COUNT 1)");
  if (blob.data.size() < std::uint64_t{blob.point_step} * blob.width * blob.height)
    throw pcl::IOException(file + ": cannot read PCD file (less data than points)");

  Frame out;
  out.name = file;
  out.cloud = pcl::make_shared<pcl::PointCloud<pcl::PointXYZRGB>>();
  pcl::fromPCLPointCloud2(blob, *out.cloud);

  const double stamp = stampFromName(file);
  out.timestamp = out.depth_timestamp =
      std::isfinite(stamp) ? stamp : static_cast<double>(cursor_) / fps_;

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
