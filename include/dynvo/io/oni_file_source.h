// SPDX-License-Identifier: BSD-3-Clause
// Frames from an OpenNI (.oni) recording, played back through PCL's OpenNI2 grabber.
#pragma once

#include <dynvo/common/export.h>
#include <dynvo/io/frame_source.h>

#include <memory>
#include <string>

namespace dynvo {

/** \brief Plays an .oni recording with pcl::io::OpenNI2Grabber, delivering every
 * recorded frame in order, none dropped (playback is stepped frame by frame).
 *
 * Clouds are organized PointXYZRGB in metres (the grabber's own registration and
 * intrinsics); the timestamp is the depth frame's device time in seconds.
 * \throws pcl::IOException when the file is missing or not a valid recording, or when
 *         dynvo was built without OpenNI2 support
 */
class DYNVO_EXPORTS OniFileSource : public FrameSource {
public:
  explicit OniFileSource(const std::string& file);
  ~OniFileSource() override;

  bool
  next(Frame& frame) override;

  std::size_t
  size() const override;

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

} // namespace dynvo
