// SPDX-License-Identifier: BSD-3-Clause
// Frames from a TUM RGB-D benchmark folder (or the ICSL-DE associations.txt layout).
#pragma once

#include <dynvo/common/export.h>
#include <dynvo/io/frame_source.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace dynvo {

/** \brief Reads a TUM RGB-D folder.
 *
 * With rgb.txt and depth.txt (lines "timestamp filename", '#' comments and blank lines
 * allowed), colour and depth are associated one-to-one by nearest timestamp within
 * 0.02 s, as the benchmark's associate.py does. A folder with associations.txt
 * ("t_rgb rgb_file t_depth depth_file", the ICSL-DE layout) is used as listed.
 * Depth PNGs are 16-bit; raw 0 is a missing measurement.
 */
class DYNVO_EXPORTS TumFolderSource : public FrameSource {
public:
  struct Options {
    /// default preset (525, 525, 319.5, 239.5); with lens distortion, every frame is
    /// undistorted (Frame::undistortion)
    CameraIntrinsics intrinsics;
    double depth_scale =
        0.0; ///< raw units per metre; 0 = 5000 (TUM) or 1000 (associations.txt)
    double max_difference = 0.02; ///< association tolerance (seconds)
    std::uint64_t max_frame_pixels =
        DEFAULT_MAX_FRAME_PIXELS; ///< larger images are refused before decoding
  };

  /// One associated colour/depth pair.
  struct Entry {
    double rgb_stamp;       ///< seconds
    std::string rgb_file;   ///< path relative to the folder
    double depth_stamp;     ///< seconds
    std::string depth_file; ///< path relative to the folder
  };

  /// \throws pcl::IOException when the folder or its index files are missing or corrupt
  explicit TumFolderSource(const std::string& folder, const Options& options);

  bool next(Frame& frame) override;

  std::size_t size() const override { return entries_.size(); }

  /// The index files, groundtruth.txt (when present) and the folders of the listed images.
  std::vector<std::string> inputPaths() const override;

  /// The associated pairs, in time order.
  const std::vector<Entry>& entries() const { return entries_; }

  /// Depth scale in use (raw units per metre).
  double depthScale() const { return depth_scale_; }

  /// Read pair i (0-based) without moving the cursor. \throws pcl::IOException
  Frame read(std::size_t i) const;

private:
  std::string folder_;
  Options options_;
  double depth_scale_;
  std::vector<Entry> entries_;
  std::size_t cursor_ = 0;
  /// The intrinsics' undistortion at the last frame's size (made on the first frame)
  mutable std::shared_ptr<const LensUndistortion> undistortion_;
};

} // namespace dynvo
