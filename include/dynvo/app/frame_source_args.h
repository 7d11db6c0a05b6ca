// SPDX-License-Identifier: BSD-3-Clause
// The frame-source flags shared by every app that reads a recording.
#pragma once

#include <dynvo/app/cli.h>
#include <dynvo/common/camera.h>
#include <dynvo/io/frame_source.h>

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

namespace dynvo::app {

/// -tum_dir, -pcd_dir, -oni, -camera, -fx, -fy, -cx, -cy, -depth_scale, -fps,
/// -max_frame_pixels.
DYNVO_EXPORTS std::vector<Option> frameSourceOptions();

/// Intrinsics from -camera (preset, default "default") overridden by -fx -fy -cx -cy.
DYNVO_EXPORTS CameraIntrinsics intrinsicsFromArguments(const Arguments& args);

/** \brief Opens the source named by exactly one of -tum_dir, -pcd_dir, -oni.
 * \throws UsageError when none or several are given, or a value is out of range
 * \throws pcl::IOException when the source cannot be opened
 */
DYNVO_EXPORTS FrameSource::Ptr openFrameSource(const Arguments& args);

/// How a pass over a recording ended.
struct FrameLoopEnd {
  std::size_t frames = 0; ///< frames processed completely
  std::string error;      ///< why it stopped early; "" at the end or after max_frames
};

/** \brief Hands each frame of the source to process() until the recording ends,
 * max_frames are done, or anything throws (a file that cannot be read, a frame the
 * pipeline refuses, std::bad_alloc). The exception is caught and reported with
 * pcl::console::print_error as "Error: <frame file>: <why> (stopped after N frames ...)",
 * so that the app still writes what was computed and then exits 1.
 * \param[in] max_frames frames to process at most (0 = all)
 * \param[in] read_ahead read the next frame on a thread of its own while process() runs.
 * Reading (decoding, undistortion, the cloud) is a third to a half of a TUM run's work, so
 * the run ends sooner, but on two cores the reader takes time from process(). The frames,
 * their order and what stops the run are the same: a frame beyond max_frames is never
 * read, and an error reading frame k + 1 stops the run after frame k.
 */
DYNVO_EXPORTS FrameLoopEnd
processFrames(FrameSource& source,
              std::size_t max_frames,
              const std::function<void(const Frame&)>& process,
              bool read_ahead = false);

} // namespace dynvo::app
