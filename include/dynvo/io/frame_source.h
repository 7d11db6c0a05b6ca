// SPDX-License-Identifier: BSD-3-Clause
// The one interface through which every recording format delivers frames.
#pragma once

#include <dynvo/io/frame.h>

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

namespace dynvo {

/** \brief A sequence of RGB-D frames read in order.
 *
 * Constructors throw pcl::IOException when the source cannot be opened; next()
 * throws pcl::IOException naming the file when a frame cannot be read.
 * \code
 * dynvo::TumFolderSource source("rgbd_dataset_freiburg1_xyz",
 *                               {dynvo::CameraIntrinsics::fromPreset("fr1")});
 * dynvo::Frame frame;
 * while (source.next(frame))
 *   process(frame.timestamp, frame.cloud);
 * \endcode
 */
class FrameSource {
public:
  using Ptr = std::unique_ptr<FrameSource>;

  virtual ~FrameSource() = default;

  /** \brief Read the next frame.
   * \param[out] frame the frame; untouched when the sequence has ended
   * \return false at the end of the sequence
   */
  virtual bool next(Frame& frame) = 0;

  /// Number of frames in the whole sequence, or 0 when the source cannot tell.
  virtual std::size_t size() const = 0;

  /// The files and folders the source reads (index files, image folders, the recording),
  /// so that an app can refuse to write over them. Empty when the source cannot tell.
  virtual std::vector<std::string> inputPaths() const { return {}; }
};

} // namespace dynvo
