// SPDX-License-Identifier: BSD-3-Clause
#include "image_file.h"

#include <dynvo/io/frame.h>

#include <pcl/exceptions.h>

#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <vector>

namespace dynvo {

namespace {

const unsigned char PNG_SIGNATURE[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
/// The last 12 bytes of every complete PNG: the empty IEND chunk and its CRC.
const unsigned char PNG_END[12] = {0,   0,   0,    0,    'I',  'E',
                                   'N', 'D', 0xae, 0x42, 0x60, 0x82};
/// Signature (8) + IHDR length, type, width, height (16) + the rest of IHDR (9 + CRC 4).
constexpr std::size_t PNG_MIN_SIZE = 8 + 25 + 12;

std::uint32_t
bigEndian32(const unsigned char* bytes)
{
  return std::uint32_t{bytes[0]} << 24 | std::uint32_t{bytes[1]} << 16 |
         std::uint32_t{bytes[2]} << 8 | std::uint32_t{bytes[3]};
}

} // namespace

cv::Mat
readImageFile(const std::string& path,
              const std::string& what,
              std::uint64_t max_pixels)
{
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw pcl::IOException(path + ": cannot read " + what + " (no such file)");
  // Whole blocks at a time (a byte at a time cost 0.5 ms per VGA frame's two PNGs).
  std::vector<unsigned char> bytes;
  char block[1 << 16];
  while (in.read(block, sizeof block) || in.gcount() > 0)
    bytes.insert(bytes.end(), block, block + in.gcount());
  if (bytes.empty()) // cv::imdecode would only say "!buf.empty()"
    throw pcl::IOException(path + ": " + what + " is empty (0 bytes)");
  if (bytes.size() >= sizeof(PNG_SIGNATURE) &&
      std::equal(std::begin(PNG_SIGNATURE), std::end(PNG_SIGNATURE), bytes.begin())) {
    if (bytes.size() < PNG_MIN_SIZE)
      throw pcl::IOException(path + ": " + what + " is a truncated PNG (" +
                             std::to_string(bytes.size()) + " bytes)");
    checkFrameSize(path, bigEndian32(&bytes[16]), bigEndian32(&bytes[20]), max_pixels);
    if (!std::equal(std::begin(PNG_END), std::end(PNG_END), bytes.end() - 12))
      throw pcl::IOException(path + ": " + what +
                             " is a truncated PNG (it does not end with IEND)");
  }
  cv::Mat image;
  try {
    image = cv::imdecode(bytes, cv::IMREAD_UNCHANGED);
  }
  catch (const cv::Exception& e) {
    throw pcl::IOException(path + ": cannot decode " + what + " (" + e.err + ")");
  }
  if (image.empty())
    throw pcl::IOException(path + ": cannot read " + what + " (missing or corrupt)");
  checkFrameSize(path, image.cols, image.rows, max_pixels);
  return image;
}

} // namespace dynvo
