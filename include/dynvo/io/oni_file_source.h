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
 * The grabber's separate depth-image and image signals are used; each depth frame is
 * paired with the colour frame nearest in time (the grabber's own image+depth
 * synchronizer would hold back the last pair). OpenNI2 runs the file device in manual
 * mode (playback speed -1, repeat off) and next() steps it, so reading is not paced by
 * the recorded clock (it runs as fast as decoding allows).
 *
 * Each Frame has:
 * - timestamp: the depth frame's device time in seconds (OpenNI's player starts the
 *   recording's clock at 0 for the first frame);
 * - name: "<file>#<index>" (0-based frame index);
 * - depth: metres (OpenNI millimetres x 0.001), NaN where OpenNI reports 0;
 * - color: RGB8 at the depth resolution (PCL subsamples by an integer factor if the
 *   colour stream is larger);
 * - cloud: organized PointXYZRGB made from depth and colour with the grabber's own
 *   projection model for its XYZRGBA clouds (fx = fy from the depth stream's
 *   horizontal field of view, cx = (width - 1) / 2, cy = (height - 1) / 2; 525 px at
 *   VGA when the recording carries no field of view, with a PCL_WARN).
 *
 * size() is the recording's depth frame count. The device must be an OpenNI2 file
 * device with depth and colour streams.
 * \throws pcl::IOException naming the file when it is missing, not a regular file,
 *         does not start with the ONI magic "NI10" (checked before OpenNI2 sees it),
 *         cannot be played, or when dynvo was built without OpenNI2 support. next()
 *         throws when a frame cannot be read or playback delivers nothing for 10 s
 *         (e.g. a truncated recording).
 */
class DYNVO_EXPORTS OniFileSource : public FrameSource {
public:
  explicit OniFileSource(const std::string& file);
  ~OniFileSource() override;

  bool next(Frame& frame) override;

  std::size_t size() const override;

  /// The recording.
  std::vector<std::string> inputPaths() const override { return {file_}; }

private:
  std::string file_;
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

} // namespace dynvo
