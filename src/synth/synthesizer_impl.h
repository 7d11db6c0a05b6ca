// SPDX-License-Identifier: BSD-3-Clause
// SceneSynthesizer's private state, shared by its rendering and writing sources.
#pragma once

#include <dynvo/synth/scene_synthesizer.h>

#include "scene_script.h"

#include <Eigen/Geometry>

#include <vector>

namespace dynvo {

/// Scripted state of one frame (no rendering involved).
struct FrameScript {
  double timestamp;                 ///< colour stamp (s)
  double depth_timestamp;           ///< depth stamp (s)
  Eigen::Isometry3d T_world_camera; ///< camera-to-world
  std::vector<ObjectState> objects; ///< every scripted object
};

struct SceneSynthesizer::Impl {
  SynthOptions options;
  const detail::Scenario* scenario = nullptr;
  CameraIntrinsics intrinsics; ///< scaled to the image size

  /// Poses, motion flags and stamps of frame k (0 <= k < frames).
  FrameScript script(int k) const;
};

} // namespace dynvo
