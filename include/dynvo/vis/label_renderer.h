// SPDX-License-Identifier: BSD-3-Clause
// Off-screen VTK rendering of a label-coloured organized cloud into a PNG.
#pragma once

#include <dynvo/common/camera.h>
#include <dynvo/common/export.h>
#include <dynvo/common/trajectory.h>

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace dynvo {

/// Where a LabelRenderer looks from.
enum class RenderView {
  camera, ///< the recording camera itself: the PNG lines up pixel for pixel with the RGB frame
  oblique, ///< behind, above and right of the current camera, looking at the whole scene
  top, ///< straight down the world -y axis (camera 0's "up"), world +z pointing up in the image
};

/** \brief Renders a cloud coloured by label into a PNG with VTK, off screen.
 *
 * Colours come from a fixed palette (labelColor(): 0 no measurement dark grey, 1 static
 * light grey, 2.. one saturated colour per object id) mixed with the point's own RGB in the
 * ratio Parameters::rgb_blend. The camera view reproduces the pinhole projection of
 * Parameters::intrinsics exactly, so a point seen at pixel (u, v) of the RGB frame is drawn at
 * pixel (u, v). The oblique and top views also draw the trajectory so far as a white polyline
 * and the current camera as a white frustum. The render window, actors and buffers are created
 * on the first render and reused, so later renders only upload the new points.
 *
 * Rendering needs an X display (displayAvailable()); without one render() warns once and
 * returns false without touching VTK, so a long run is never broken by it.
 * \code
 * dynvo::LabelRenderer::Parameters params;
 * params.intrinsics = dynvo::CameraIntrinsics::fromPreset("fr1");
 * dynvo::LabelRenderer renderer(params);
 * dynvo::Trajectory so_far;
 * while (source.next(frame)) {
 *   so_far.push_back({frame.timestamp, T_world_curr});
 *   renderer.render(*frame.cloud, labels, T_world_curr, so_far, "out/000123.png");
 * }
 * \endcode
 * Not thread-safe; separate instances may be used from separate threads only if the
 * X server and OpenGL driver allow it.
 */
class DYNVO_EXPORTS LabelRenderer {
public:
  /// Rendering settings; defaults match a 640x480 TUM-style camera.
  struct Parameters {
    std::uint32_t width =
        640; ///< image columns (px); the recording's width for the camera view
    std::uint32_t height =
        480; ///< image rows (px); the recording's height for the camera view
    CameraIntrinsics
        intrinsics; ///< recording camera (px), used by the camera view and the frustum
    RenderView view = RenderView::camera; ///< viewpoint
    double rgb_blend = 0.3; ///< share of the point's own RGB in its colour, in [0, 1]
    double point_size =
        2.0; ///< point diameter (px) in the oblique and top views, >= 1;
             ///< the camera view draws each point on its own pixel
    double frustum_depth =
        0.3; ///< distance of the drawn frustum's far face (metres), > 0

    /// Throws std::invalid_argument naming the first field out of range.
    void validate() const;
  };

  LabelRenderer();
  /// \throws std::invalid_argument when params.validate() fails
  explicit LabelRenderer(const Parameters& params);
  ~LabelRenderer();
  LabelRenderer(LabelRenderer&&) noexcept;
  LabelRenderer& operator=(LabelRenderer&&) noexcept;
  LabelRenderer(const LabelRenderer&) = delete;
  LabelRenderer& operator=(const LabelRenderer&) = delete;

  /// \throws std::invalid_argument when params.validate() fails (the old settings stay)
  void setParameters(const Parameters& params);

  const Parameters& getParameters() const { return params_; }

  /// Viewpoint of the next render().
  void setView(RenderView view) { params_.view = view; }

  RenderView getView() const { return params_.view; }

  /** \brief Renders one frame into a PNG (created or replaced).
   * \param[in] cloud points in the camera frame (metres); NaN points are skipped
   * \param[in] labels one label per point, row-major like the cloud (0 none, 1 static, 2.. objects)
   * \param[in] T_world_camera pose of the camera the cloud was seen from (camera-to-world)
   * \param[in] trajectory_so_far camera poses (world) drawn as a polyline in the oblique and top
   *            views; may be empty
   * \param[in] out_png destination file; its folder must exist
   * \return true when the PNG was written; false (with a PCL_ERROR) when labels and cloud sizes
   *         differ, the cloud is empty or the file cannot be written, and false (with one PCL_WARN
   *         per renderer) when no display is available
   */
  bool render(const pcl::PointCloud<pcl::PointXYZRGB>& cloud,
              const std::vector<std::uint8_t>& labels,
              const Eigen::Isometry3d& T_world_camera,
              const Trajectory& trajectory_so_far,
              const std::string& out_png);

  /// Palette colour (R, G, B) of a label, before blending with the point's RGB.
  static std::array<std::uint8_t, 3> labelColor(std::uint8_t label);

  /// Rendered colour of a point: labelColor(label) mixed with rgb at ratio rgb_blend, rounded.
  static std::array<std::uint8_t, 3> blendedColor(
      std::uint8_t label, const std::array<std::uint8_t, 3>& rgb, double rgb_blend);

  static const char* getClassName() { return "LabelRenderer"; }

private:
  struct Impl;
  Parameters params_; ///< current settings
  std::unique_ptr<Impl>
      impl_;                ///< X connection and VTK pipeline, made by the first render
  bool no_display_ = false; ///< the first render found no display (and warned)
};

} // namespace dynvo
