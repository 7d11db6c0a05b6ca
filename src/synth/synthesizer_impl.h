// SPDX-License-Identifier: BSD-3-Clause
// SceneSynthesizer's private state, shared by its rendering and writing sources.
#pragma once

#include <dynvo/synth/scene_synthesizer.h>

#include "scene_script.h"

#include <dynvo/synth/depth_sensor_model.h>

#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace dynvo {

/// Scripted state of one frame (no rendering involved).
struct FrameScript {
  double timestamp;                 ///< colour and depth stamp (s)
  Eigen::Isometry3d T_world_camera; ///< camera-to-world
  std::vector<ObjectState> objects; ///< every scripted object
};

/// Texture seed, base colour, shading and material of one flat face.
struct SurfaceLook {
  std::uint32_t salt;
  float base[3];
  float shade;
  bool dark;  ///< dark or shiny: no structured-light return (DepthSensorModel)
  bool plain; ///< one flat colour (SynthOptions::plain_objects), no texture
};

/// An oriented box as seen from one camera pose.
struct FrameBox {
  Eigen::Matrix3f ray_to_box;       ///< camera-frame ray direction to box frame
  Eigen::Vector3f origin;           ///< camera centre in the box frame (metres)
  Eigen::Vector3f half;             ///< half extents (metres)
  std::uint8_t label;               ///< label written for its pixels (0 unless moving)
  std::array<SurfaceLook, 6> faces; ///< face 2a + s: axis a, s = 1 on the + side
  int u0, u1, v0, v1; ///< inclusive pixel rectangle holding its projection
};

/// One pixel's ray hit: colour before rounding, the surface, and its label.
struct PixelHit {
  float rgb[3] = {0.0f, 0.0f, 0.0f}; ///< 0-255
  SurfaceSample surface;             ///< z NaN when nothing was hit
  std::uint8_t label = 0;            ///< object id while it moves, else 0
};

/// The scene of one instant as seen by the camera: ray casting per pixel.
class SceneView {
public:
  /// with_room false: only the scripted objects (for compositing into real frames)
  SceneView(const FrameScript& script,
            const CameraIntrinsics& intrinsics,
            const SynthOptions& options,
            bool with_room);
  ~SceneView();

  /// Casts the ray of pixel (u, v) (pinhole, sub-pixel allowed); false (and `out`
  /// untouched) when nothing is hit.
  bool cast(float u, float v, PixelHit& out) const;

  /// Pixel rectangle holding every moving object (inclusive); false when none moves.
  bool movingRectangle(int& u0, int& u1, int& v0, int& v1) const;

  /// Replaces the colour of the pixels [u0, u1] x [v0, v1] (inclusive, inside the
  /// image) by the mean over the views of one exposure.
  static void meanColour(const std::vector<SceneView>& exposure,
                         int u0,
                         int u1,
                         int v0,
                         int v1,
                         int width,
                         ColorImage& color);

  /// Replaces the colour inside the moving objects' rectangles by the mean over the
  /// views of one exposure (motion blur).
  static void blurColour(const std::vector<SceneView>& exposure,
                         int width,
                         int height,
                         ColorImage& color);

private:
  CameraIntrinsics intrinsics_;
  bool with_room_;
  std::vector<FrameBox> boxes_;
  std::array<SurfaceLook, 6> room_faces_;
  Eigen::Matrix3f R_;
  Eigen::Vector3f o_, room_min_, room_max_;
};

struct SceneSynthesizer::Impl {
  SynthOptions options;
  const detail::Scenario* scenario = nullptr;
  CameraIntrinsics intrinsics; ///< scaled to the image size

  /// Poses, motion flags and stamps of frame k (0 <= k < frames).
  FrameScript script(int k) const;

  /// Poses at time t (s); objects are "moving" when their pose differs at t_previous.
  FrameScript scriptAt(double t, double t_previous) const;
};

} // namespace dynvo
