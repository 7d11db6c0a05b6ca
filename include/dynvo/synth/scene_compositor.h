// SPDX-License-Identifier: BSD-3-Clause
// A scenario's rigid objects rendered into the frames of a real RGB-D recording.
#pragma once

#include <dynvo/common/camera.h>
#include <dynvo/common/export.h>
#include <dynvo/common/image.h>
#include <dynvo/common/lens_undistortion.h>
#include <dynvo/synth/scene_synthesizer.h>

#include <Eigen/Geometry>

#include <cstddef>
#include <memory>
#include <vector>

namespace dynvo {

/// One composited frame.
struct CompositeFrame {
  ColorImage color;    ///< the real colour, object pixels replaced where visible
  RawDepthImage depth; ///< raw depth, SceneSynthesizer::DEPTH_PNG_SCALE units per metre
  LabelImage labels;   ///< object id on its visible pixels while it moves, else 0
  std::vector<ObjectState> objects; ///< every object, placed in the recording's world
};

/** \brief Composites a scenario's rigid objects into the frames of a real recording.
 *
 * Works on plain data: the caller reads the recording (colour, raw depth, the camera pose
 * of each frame at its colour stamp) and writes the results.
 *
 * Placement: the objects are placed as the scenario places them relative to its camera
 * at frame 0, scaled about that camera by s = min(1, 0.9 z_20 / z_near) (z_20: 20th
 * percentile of the real depth of the first frame; z_near: the nearest the objects'
 * centres come to the scenario's camera while in its view), so they keep their image
 * size and speed and pass in front of most of the real scene; from there they move
 * rigidly in the recording's world, time taken from the stamps.
 *
 * Per frame: an object pixel is visible where the real depth is missing or farther;
 * visible pixels get the object's colour times the ratio of the real to the synthetic
 * first frame's mean brightness, and depth through DepthSensorModel (its edges and
 * shadows seeing the real depth around them). Every other pixel keeps the recording's
 * colour and depth (depth rescaled to DEPTH_PNG_SCALE when the recording's scale
 * differs). No motion blur (it would smear into real pixels). With a lens that distorts
 * (CameraIntrinsics::distortion), each pixel casts the ray the lens gives it, so the objects
 * are distorted as the recording is.
 */
class DYNVO_EXPORTS SceneCompositor {
public:
  /// \throws std::invalid_argument when options.validate() fails or the scenario has no
  ///         objects
  explicit SceneCompositor(const SynthOptions& options);

  /** \brief Plans the placement for a recording.
   * \param[in] intrinsics the recording's camera
   * \param[in] depth_scale raw depth units per metre of the recording (> 0)
   * \param[in] rgb_stamps colour stamp of every frame to composite (s), increasing
   * \param[in] T_world_camera the recording's camera-to-world at each colour stamp
   * \param[in] first_color colour image of frame 0
   * \param[in] first_depth raw depth image of frame 0, same size
   * \throws std::invalid_argument on empty or mismatched inputs, or when the first depth
   *         image has no measurement
   */
  void setRecording(const CameraIntrinsics& intrinsics,
                    double depth_scale,
                    const std::vector<double>& rgb_stamps,
                    const std::vector<Eigen::Isometry3d>& T_world_camera,
                    const ColorImage& first_color,
                    const RawDepthImage& first_depth);

  /// Scale s applied to the objects' positions and sizes (1 = unscaled).
  double objectScale() const { return scale_; }

  /** \brief Frame k composited (0 <= k < rgb_stamps.size()).
   * \param[in] color the recording's colour image of frame k
   * \param[in] depth the recording's raw depth image of frame k
   * \throws std::invalid_argument before setRecording(), for k out of range, or when an
   *         image's size differs from the first frame's
   */
  CompositeFrame
  composite(std::size_t k, const ColorImage& color, const RawDepthImage& depth) const;

private:
  SceneSynthesizer synth_;
  CameraIntrinsics intrinsics_;
  std::shared_ptr<const LensUndistortion> lens_; ///< null without distortion
  double depth_scale_ = 0.0;
  std::vector<double> rgb_stamps_;
  std::vector<Eigen::Isometry3d> T_world_camera_;
  std::uint32_t width_ = 0, height_ = 0;
  double frame_time_ = 1.0 / 30.0;
  Eigen::Isometry3d T_scenario_camera0_world_ = Eigen::Isometry3d::Identity();
  double scale_ = 1.0;
  float gain_ = 1.0f;
};

} // namespace dynvo
