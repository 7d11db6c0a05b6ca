// SPDX-License-Identifier: BSD-3-Clause
// The frame-source flags shared by every app that reads a recording.
#pragma once

#include <dynvo/app/cli.h>
#include <dynvo/common/camera.h>
#include <dynvo/io/frame_source.h>

#include <vector>

namespace dynvo::app {

/// -tum_dir, -pcd_dir, -oni, -camera, -fx, -fy, -cx, -cy, -depth_scale, -fps.
DYNVO_EXPORTS std::vector<Option> frameSourceOptions();

/// Intrinsics from -camera (preset, default "default") overridden by -fx -fy -cx -cy.
DYNVO_EXPORTS CameraIntrinsics intrinsicsFromArguments(const Arguments& args);

/** \brief Opens the source named by exactly one of -tum_dir, -pcd_dir, -oni.
 * \throws UsageError when none or several are given, or a value is out of range
 * \throws pcl::IOException when the source cannot be opened
 */
DYNVO_EXPORTS FrameSource::Ptr openFrameSource(const Arguments& args);

} // namespace dynvo::app
