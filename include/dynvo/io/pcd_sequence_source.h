// SPDX-License-Identifier: BSD-3-Clause
// Frames from a folder of organized PCD files.
#pragma once

#include <dynvo/common/export.h>
#include <dynvo/io/frame_source.h>

#include <cstdint>
#include <string>
#include <vector>

namespace dynvo {

/** \brief Reads every `.pcd` file of a folder in order: names that are numbers by value,
 * other names in natural order ("f2" before "f10").
 *
 * The timestamp is the file name (without extension) when it parses completely as a
 * number, otherwise index / fps. Each file must hold an organized cloud with x, y, z and
 * rgb (or rgba) fields. The frame's images are made from the cloud (depth = z).
 */
class DYNVO_EXPORTS PcdSequenceSource : public FrameSource {
public:
  /** \param[in] folder the .pcd files
   * \param[in] fps frame rate for names that are not timestamps (Hz)
   * \param[in] max_frame_pixels frame-size limit: next() refuses a file whose header
   *            claims more points, or more data than the file holds, before reading it
   * \throws pcl::IOException when the folder is missing or holds no .pcd file
   * \throws std::invalid_argument when fps is not positive
   */
  explicit PcdSequenceSource(const std::string& folder,
                             double fps = 30.0,
                             std::uint64_t max_frame_pixels = DEFAULT_MAX_FRAME_PIXELS);

  bool next(Frame& frame) override;

  std::size_t size() const override { return files_.size(); }

  /// The folder.
  std::vector<std::string> inputPaths() const override { return {folder_}; }

  /// The files in the order they are delivered.
  const std::vector<std::string>& files() const { return files_; }

private:
  std::string folder_;
  std::vector<std::string> files_;
  double fps_;
  std::uint64_t max_frame_pixels_;
  std::size_t cursor_ = 0;
};

/// True when a's name sorts before b's in natural order (digit runs compared as numbers).
DYNVO_EXPORTS bool naturalLess(const std::string& a, const std::string& b);

} // namespace dynvo
