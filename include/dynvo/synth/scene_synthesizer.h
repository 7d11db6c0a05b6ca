// SPDX-License-Identifier: BSD-3-Clause
// Deterministic synthetic RGB-D sequences of textured rooms with rigid moving objects.
#pragma once

#include <dynvo/common/camera.h>
#include <dynvo/common/export.h>
#include <dynvo/common/image.h>

#include <Eigen/Geometry>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace dynvo {

/// A named scripted scenario.
struct ScenarioInfo {
  std::string name;        ///< e.g. "moving_crossing"
  std::string description; ///< one line
};

/// Pose and state of one scripted object at one frame.
struct ObjectState {
  int id = 0; ///< 1, 2, ... (label value)
  Eigen::Isometry3d T_world_object =
      Eigen::Isometry3d::Identity(); ///< object-to-world (metres)
  bool moving =
      false; ///< true when the object moves between the previous frame and this one
  /// Half sizes of the box along the object's x, y, z axes (metres); the box is centred
  /// on the object frame's origin.
  Eigen::Vector3d half_extents = Eigen::Vector3d::Zero();
};

/// One rendered frame with its ground truth.
struct SynthFrame {
  double timestamp = 0.0; ///< seconds (the colour and the depth image's stamp)
  ColorImage color;       ///< shaded, textured colour image
  DepthImage depth;       ///< metres after the depth model; NaN = no measurement
  std::vector<std::uint8_t>
      labels; ///< per pixel: 0 static, k for object k while it moves
  Eigen::Isometry3d T_world_camera = Eigen::Isometry3d::Identity(); ///< camera-to-world
  std::vector<ObjectState> objects; ///< every object of the scenario
};

/// Options of a synthetic sequence.
struct DYNVO_EXPORTS SynthOptions {
  std::string scenario = "moving_crossing"; ///< one of SceneSynthesizer::scenarios()
  int frames = 300;                         ///< number of frames (> 0)
  std::uint32_t seed = 0; ///< seeds textures' jitter and the depth noise
  int width = 640;        ///< image columns (px)
  int height = 480;       ///< image rows (px)
  double fps = 30.0;      ///< frame rate (Hz)
  bool noise = true;      ///< DepthSensorModel on; off = exact depth everywhere
  /// Motion blur of the scenarios with an exposure; off = colour of the frame's instant
  bool motion_blur = true;
  /// The scripted objects in one flat colour per face, without texture (the room keeps
  /// its texture): a plain box, on which Lucas-Kanade has nothing to track
  bool plain_objects = false;
  /// Intrinsics at 640x480 (scaled with width/height); the "default" preset.
  CameraIntrinsics intrinsics;

  /// \throws std::invalid_argument on an unknown scenario or an out-of-range value
  void validate() const;
};

/** \brief Renders scripted dynamic scenes by ray casting (deterministic for a seed).
 *
 * World frame: x right, y down (floor at y = +1.0), z forward, metres. The room spans
 * [-2.2, 2.2] x [-1.4, 1.0] x [-1.0, 4.0] (the far wall 3.7-4.3 m from the camera, as in
 * real rooms) and holds five static furniture boxes at 1.5-3.9 m, one of them dark (no
 * depth return); the scripted objects are oriented boxes. Every pixel casts one ray through its centre; the
 * depth is the hit point's z in the camera frame (TUM convention, not the range).
 *
 * Appearance: every face carries its own procedural texture (seeded): two layers of
 * smoothly interpolated colour value noise (0.35 m and 0.09 m lattices) times four
 * octaves of luminance value noise (48, 24, 12 and 6 mm lattices). Octaves whose lattice
 * would span fewer than 3 px fade out (gone below 1.5 px) using the pixel footprint at
 * the hit point, so the image is band-limited and sub-pixel tracking stays accurate.
 * Shading is Lambertian under one fixed directional light plus ambient light, so a
 * surface looks the same from every viewpoint (no shadows, no specular highlights).
 * SynthOptions::plain_objects paints each face of the scripted objects in its base colour
 * times the textures' mean factor instead: one flat colour per face, no image noise.
 *
 * Motion: the camera follows sums of sinusoids (about 0.1-0.3 m/s and up to about
 * 4 deg/s; circling_bobbing circles its box at up to 9 deg/s) in the moving-camera
 * scenarios and is fixed (constant, non-identity pose looking 11.5 deg down) in the
 * static ones; fast_sweep is a hand-held sweep at up to about 1 m/s and 90 deg/s (the
 * fastest stretches of TUM fr1/desk) in the static room, moving for 2.5 s and holding
 * still for 0.75 s in turn (0.25 s raised-cosine speed ramps). Objects follow smooth 6-DoF scripts (sinusoids, Hermite splines through
 * waypoints, or a shallow arc) at 0.3-5 cm per frame at 30 Hz, except the cube of
 * thrown_object (about 13 cm, up to 35 px per frame); stop_and_go and enter_stop_leave
 * objects rest for stretches and move with 0.25 s raised-cosine speed ramps. Object k is "moving" at frame k exactly when its pose
 * differs from the one at the previous frame, and only then labels its pixels with k.
 *
 * Depth model (SynthOptions::noise): DepthSensorModel (Kinect v1 / Xtion: axial noise
 * growing with (z - 0.4 m)^2, 1/8 px disparity quantisation, projector shadows, dropouts
 * at depth edges, at grazing angles and on dark surfaces, speckle, 0.5-4.5 m range).
 * Without noise the depth is the exact ray depth everywhere.
 *
 * Motion blur (SynthOptions::motion_blur): scenarios with an exposure (20 ms in
 * thrown_object and fast_sweep, the middle of a Kinect v1's 10-30 ms indoor auto
 * exposure), centred on the colour stamp, average the colour of evenly spread instants
 * across it. Camera motion blurs the whole image: as many instants as keep the
 * image of every scene point moving at most CAMERA_BLUR_STEP (3 px) between two (the
 * streak is measured on a grid of probe pixels), at most MAX_CAMERA_BLUR_SAMPLES (9,
 * for the rendering cost; longer streaks get wider gaps); a camera at rest over the
 * exposure leaves the frame's instant untouched. Moving objects then average
 * BLUR_SAMPLES (7) instants inside their pixel rectangle. Depth and labels show the
 * frame's instant.
 *
 * Timestamps: FIRST_STAMP + k / fps, rounded to whole microseconds (the "%.6f" of the
 * files parses back exactly), one stamp for colour and depth: both images show the scene
 * at that instant (a synchronised, registered sensor). A depth stamp that differed would
 * tell the odometry, which reports the pose at the colour stamp, that the depth was taken
 * at another instant (docs/algorithm.md §7.4).
 *
 * \code
 * dynvo::SynthOptions options;
 * options.scenario = "static_two";
 * dynvo::SceneSynthesizer synth(options);
 * dynvo::SynthFrame f0 = synth.render(0), f1 = synth.render(1);
 * \endcode
 */
class DYNVO_EXPORTS SceneSynthesizer {
public:
  static constexpr double FIRST_STAMP = 1.0;        ///< colour stamp of frame 0 (s)
  static constexpr double DEPTH_PNG_SCALE = 5000.0; ///< depth PNG units per metre

  /// \throws std::invalid_argument when options.validate() fails
  explicit SceneSynthesizer(const SynthOptions& options);
  ~SceneSynthesizer();

  /// Every scenario, in a fixed order.
  static std::vector<ScenarioInfo> scenarios();

  /// Intrinsics actually used (scaled to the image size).
  CameraIntrinsics intrinsics() const;

  /// Largest share of the image labelled as moving over all frames (labels only: no
  /// shading, no depth model).
  double largestMovingShare() const;

  /// Render frame k (0 <= k < frames). Independent of call order; thread-safe.
  /// \throws std::invalid_argument when k is out of range
  SynthFrame render(int k) const;

private:
  friend class SceneCompositor; // renders the objects only, into real frames
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

} // namespace dynvo
