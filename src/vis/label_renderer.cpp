// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/vis/label_renderer.h>

#include "window_png_writer.h"
#include "x_connection.h"

#include <pcl/console/print.h>

#include <vtkActor.h>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkIdTypeArray.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>
#include <vtkPoints.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkProperty.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkUnsignedCharArray.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

namespace dynvo {

namespace {

/// Colour of the trajectory polyline and the camera frustum: white never occurs in the
/// palette (greys stop at 190, object colours are fully saturated).
constexpr double OVERLAY_RGB[3] = {1.0, 1.0, 1.0};

/// Copies an Eigen isometry into a VTK matrix.
void
setMatrix(vtkMatrix4x4* out, const Eigen::Matrix4d& m)
{
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c)
      out->SetElement(r, c, m(r, c));
}

/** OpenGL clip-space projection reproducing the pinhole model of `k` for an image of
 * width x height pixels. VTK's view frame is x right, y up, looking along -z, so a camera
 * point (x, y, z) arrives as (x, -y, -z). Pixel u covers [u - 0.5, u + 0.5], hence the
 * half-pixel terms. Depth maps [near, far] onto [-1, 1]. */
Eigen::Matrix4d
pinholeProjection(
    const CameraIntrinsics& k, double width, double height, double near, double far)
{
  Eigen::Matrix4d p = Eigen::Matrix4d::Zero();
  p(0, 0) = 2.0 * k.fx / width;
  p(0, 2) = 1.0 - 2.0 * (k.cx + 0.5) / width;
  p(1, 1) = 2.0 * k.fy / height;
  p(1, 2) = 2.0 * (k.cy + 0.5) / height - 1.0;
  p(2, 2) = -(far + near) / (far - near);
  p(2, 3) = -2.0 * far * near / (far - near);
  p(3, 2) = -1.0;
  return p;
}

/// Fully saturated, full-value colour of hue h (degrees in [0, 360)).
std::array<std::uint8_t, 3>
saturatedHue(double h)
{
  const double sector = h / 60.0;
  const double ramp = sector - std::floor(sector);
  const auto up = static_cast<std::uint8_t>(std::lround(255.0 * ramp));
  const auto down = static_cast<std::uint8_t>(std::lround(255.0 * (1.0 - ramp)));
  switch (static_cast<int>(sector) % 6) {
  case 0:
    return {255, up, 0};
  case 1:
    return {down, 255, 0};
  case 2:
    return {0, 255, up};
  case 3:
    return {0, down, 255};
  case 4:
    return {up, 0, 255};
  default:
    return {255, 0, down};
  }
}

} // namespace

void
LabelRenderer::Parameters::validate() const
{
  const auto fail = [](const std::string& what) {
    throw std::invalid_argument("[dynvo::LabelRenderer::Parameters::validate] " + what);
  };
  if (width == 0 || height == 0)
    fail("image size must be positive, got " + std::to_string(width) + "x" +
         std::to_string(height));
  intrinsics.validate();
  if (!(rgb_blend >= 0.0 && rgb_blend <= 1.0))
    fail("rgb_blend must be in [0, 1], got " + std::to_string(rgb_blend));
  if (!(point_size >= 1.0 && std::isfinite(point_size)))
    fail("point_size must be >= 1 px, got " + std::to_string(point_size));
  if (!(frustum_depth > 0.0 && std::isfinite(frustum_depth)))
    fail("frustum_depth must be > 0 m, got " + std::to_string(frustum_depth));
}

/// The VTK pipeline: one window, a points actor and an overlay (trajectory + frustum) actor.
struct LabelRenderer::Impl {
  std::unique_ptr<detail::XConnection>
      x; ///< first member: outlives the window using it
  vtkNew<vtkRenderWindow> window;
  vtkNew<vtkRenderer> renderer;
  vtkNew<vtkPoints> points;         ///< valid points, camera frame (metres)
  vtkNew<vtkUnsignedCharArray> rgb; ///< their blended colours
  vtkNew<vtkIdTypeArray> offsets;   ///< {0, n}: one poly-vertex cell
  vtkNew<vtkIdTypeArray> ids;       ///< 0 .. n-1
  vtkNew<vtkCellArray> vertices;
  vtkNew<vtkPolyData> cloud;
  vtkNew<vtkPolyDataMapper> cloud_mapper;
  vtkNew<vtkActor> cloud_actor;
  vtkNew<vtkMatrix4x4> T_world_camera; ///< cloud actor's user matrix
  vtkNew<vtkPolyData> overlay;         ///< trajectory polyline + frustum lines (world)
  vtkNew<vtkPolyDataMapper> overlay_mapper;
  vtkNew<vtkActor> overlay_actor;
  vtkNew<vtkMatrix4x4> projection; ///< pinhole projection of the camera view
  detail::WindowPngWriter png{window};

  explicit Impl(std::unique_ptr<detail::XConnection> connection)
      : x(std::move(connection))
  {
    window->SetDisplayId(x->get());
    window->SetOffScreenRendering(1);
    window->SetMultiSamples(0); // exact palette colours: no edge blending
    window->AddRenderer(renderer);
    renderer->SetBackground(0.0, 0.0, 0.0);

    points->SetDataTypeToFloat();
    rgb->SetNumberOfComponents(3);
    rgb->SetName("colour");
    cloud->SetPoints(points);
    cloud->SetVerts(vertices);
    cloud->GetPointData()->SetScalars(rgb);
    cloud_mapper->SetInputData(cloud);
    cloud_mapper->SetColorModeToDirectScalars();
    cloud_mapper->SetScalarModeToUsePointData();
    cloud_actor->SetMapper(cloud_mapper);
    cloud_actor->SetUserMatrix(T_world_camera);
    cloud_actor->GetProperty()->LightingOff();
    renderer->AddActor(cloud_actor);

    overlay_mapper->SetInputData(overlay);
    overlay_mapper->ScalarVisibilityOff();
    overlay_actor->SetMapper(overlay_mapper);
    overlay_actor->GetProperty()->LightingOff();
    overlay_actor->GetProperty()->SetColor(OVERLAY_RGB[0], OVERLAY_RGB[1],
                                           OVERLAY_RGB[2]);
    overlay_actor->GetProperty()->SetLineWidth(2.0);
    renderer->AddActor(overlay_actor);
  }

  /// Valid points and colours into the VTK arrays; returns the camera-frame depth range.
  std::pair<float, float> setCloud(const pcl::PointCloud<pcl::PointXYZRGB>& cloud_in,
                                   const std::vector<std::uint8_t>& labels,
                                   double rgb_blend)
  {
    const vtkIdType capacity = static_cast<vtkIdType>(cloud_in.size());
    points->SetNumberOfPoints(capacity);
    rgb->SetNumberOfTuples(capacity);
    float* xyz = static_cast<float*>(points->GetVoidPointer(0));
    std::uint8_t* colour = rgb->GetPointer(0);
    // Per-label share of the palette colour, computed once per frame rather than per point;
    // +0.5 makes the truncation below round to nearest, as blendedColor() does.
    std::array<std::array<double, 3>, 256> label_part;
    for (int label = 0; label < 256; ++label) {
      const auto base = labelColor(static_cast<std::uint8_t>(label));
      for (int c = 0; c < 3; ++c)
        label_part[label][c] = (1.0 - rgb_blend) * base[c] + 0.5;
    }
    float z_min = std::numeric_limits<float>::max();
    float z_max = 0.0f;
    vtkIdType n = 0;
    for (std::size_t i = 0; i < cloud_in.size(); ++i) {
      const pcl::PointXYZRGB& p = cloud_in[i];
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
        continue;
      xyz[3 * n] = p.x;
      xyz[3 * n + 1] = p.y;
      xyz[3 * n + 2] = p.z;
      const auto& part = label_part[labels[i]];
      colour[3 * n] = static_cast<std::uint8_t>(part[0] + rgb_blend * p.r);
      colour[3 * n + 1] = static_cast<std::uint8_t>(part[1] + rgb_blend * p.g);
      colour[3 * n + 2] = static_cast<std::uint8_t>(part[2] + rgb_blend * p.b);
      z_min = std::min(z_min, p.z);
      z_max = std::max(z_max, p.z);
      ++n;
    }
    points->SetNumberOfPoints(n);
    rgb->SetNumberOfTuples(n);
    ids->SetNumberOfValues(n);
    std::iota(ids->GetPointer(0), ids->GetPointer(0) + n, vtkIdType{0});
    offsets->SetNumberOfValues(2);
    offsets->SetValue(0, 0);
    offsets->SetValue(1, n);
    vertices->SetData(offsets, ids);
    points->Modified();
    rgb->Modified();
    cloud->Modified();
    return {z_min, z_max};
  }

  /// Trajectory polyline and the current camera's frustum, in world coordinates.
  void setOverlay(const Trajectory& trajectory,
                  const Eigen::Isometry3d& pose,
                  const Parameters& params)
  {
    vtkNew<vtkPoints> overlay_points;
    vtkNew<vtkCellArray> lines;
    if (trajectory.size() >= 2) {
      lines->InsertNextCell(static_cast<vtkIdType>(trajectory.size()));
      for (const StampedPose& p : trajectory) {
        const Eigen::Vector3d t = p.T_world_camera.translation();
        lines->InsertCellPoint(overlay_points->InsertNextPoint(t.x(), t.y(), t.z()));
      }
    }
    const Eigen::Vector3d apex = pose.translation();
    const vtkIdType apex_id =
        overlay_points->InsertNextPoint(apex.x(), apex.y(), apex.z());
    const float depth = static_cast<float>(params.frustum_depth);
    const float right = static_cast<float>(params.width) - 1.0f;
    const float bottom = static_cast<float>(params.height) - 1.0f;
    const Eigen::Vector2f image_corners[4] = {
        {0.0f, 0.0f}, {right, 0.0f}, {right, bottom}, {0.0f, bottom}};
    vtkIdType corner_ids[4];
    for (int c = 0; c < 4; ++c) {
      const Eigen::Vector3d corner =
          pose * params.intrinsics
                     .backproject(image_corners[c].x(), image_corners[c].y(), depth)
                     .cast<double>();
      corner_ids[c] =
          overlay_points->InsertNextPoint(corner.x(), corner.y(), corner.z());
    }
    for (int c = 0; c < 4; ++c) {
      const vtkIdType side[2] = {apex_id, corner_ids[c]};
      lines->InsertNextCell(2, side);
      const vtkIdType rim[2] = {corner_ids[c], corner_ids[(c + 1) % 4]};
      lines->InsertNextCell(2, rim);
    }
    overlay->SetPoints(overlay_points);
    overlay->SetLines(lines);
  }

  /// Pinhole camera at the pose, clipping just around the cloud's depth range.
  void setCameraView(const Eigen::Isometry3d& pose,
                     const Parameters& params,
                     std::pair<float, float> depth_range)
  {
    vtkCamera* camera = renderer->GetActiveCamera();
    const Eigen::Vector3d eye = pose.translation();
    const Eigen::Vector3d forward = pose.linear().col(2);
    const Eigen::Vector3d up = -pose.linear().col(1); // optical y points down
    camera->SetPosition(eye.data());
    camera->SetFocalPoint((eye + forward).eval().data());
    camera->SetViewUp(up.data());
    // 1 % margins keep the nearest and farthest points off the clipping planes; with no
    // valid point any range will do.
    const bool any = depth_range.first <= depth_range.second;
    const double near = any ? std::max(0.99 * depth_range.first, 1e-3) : 0.1;
    const double far = any ? std::max(1.01 * depth_range.second, 2.0 * near) : 10.0;
    setMatrix(projection, pinholeProjection(params.intrinsics, params.width,
                                            params.height, near, far));
    camera->SetExplicitProjectionTransformMatrix(projection);
    camera->UseExplicitProjectionTransformMatrixOn();
  }

  /// Perspective camera looking along -`towards_eye` (world) at everything drawn.
  void setSceneView(const Eigen::Vector3d& towards_eye, const Eigen::Vector3d& up)
  {
    vtkCamera* camera = renderer->GetActiveCamera();
    camera->UseExplicitProjectionTransformMatrixOff();
    camera->SetViewAngle(40.0);
    camera->SetFocalPoint(0.0, 0.0, 0.0);
    camera->SetPosition(towards_eye.data());
    camera->SetViewUp(up.data());
    renderer->ResetCamera(); // keeps the direction, fits all visible actors
    renderer->ResetCameraClippingRange();
  }
};

LabelRenderer::LabelRenderer() = default;

LabelRenderer::LabelRenderer(const Parameters& params)
{
  setParameters(params);
}

LabelRenderer::~LabelRenderer() = default;
LabelRenderer::LabelRenderer(LabelRenderer&&) noexcept = default;
LabelRenderer& LabelRenderer::operator=(LabelRenderer&&) noexcept = default;

void
LabelRenderer::setParameters(const Parameters& params)
{
  params.validate();
  params_ = params;
}

std::array<std::uint8_t, 3>
LabelRenderer::labelColor(std::uint8_t label)
{
  if (label == 0)
    return {64, 64, 64};
  if (label == 1)
    return {190, 190, 190};
  // Golden-angle hue steps: consecutive object ids get clearly different hues, and the
  // sequence does not repeat within the 254 possible ids.
  return saturatedHue(std::fmod((label - 2) * 137.507764, 360.0));
}

std::array<std::uint8_t, 3>
LabelRenderer::blendedColor(std::uint8_t label,
                            const std::array<std::uint8_t, 3>& rgb,
                            double rgb_blend)
{
  const auto base = labelColor(label);
  std::array<std::uint8_t, 3> out{};
  for (int c = 0; c < 3; ++c)
    out[c] = static_cast<std::uint8_t>(
        std::lround((1.0 - rgb_blend) * base[c] + rgb_blend * rgb[c]));
  return out;
}

bool
LabelRenderer::render(const pcl::PointCloud<pcl::PointXYZRGB>& cloud,
                      const std::vector<std::uint8_t>& labels,
                      const Eigen::Isometry3d& T_world_camera,
                      const Trajectory& trajectory_so_far,
                      const std::string& out_png)
{
  const char* const prefix = "[dynvo::LabelRenderer::render]";
  if (cloud.empty()) {
    PCL_ERROR("%s the cloud is empty\n", prefix);
    return false;
  }
  if (labels.size() != cloud.size()) {
    PCL_ERROR("%s %zu labels for %zu points\n", prefix, labels.size(), cloud.size());
    return false;
  }
  if (no_display_)
    return false;
  if (!impl_) {
    auto connection = std::make_unique<detail::XConnection>();
    if (!connection->get()) {
      no_display_ = true;
      PCL_WARN(
          "%s no display (%s): no images are written; run under `xvfb-run -a` on a "
          "headless machine\n",
          prefix, connection->reason().c_str());
      return false;
    }
    impl_ = std::make_unique<Impl>(std::move(connection));
  }

  Impl& vtk = *impl_;
  vtk.window->SetSize(static_cast<int>(params_.width),
                      static_cast<int>(params_.height));
  const auto depth_range = vtk.setCloud(cloud, labels, params_.rgb_blend);
  // In the camera view every point sits on its own pixel centre, so one pixel per point
  // fills the image exactly and keeps neighbouring labels from bleeding into each other.
  const bool camera_view = params_.view == RenderView::camera;
  vtk.cloud_actor->GetProperty()->SetPointSize(
      camera_view ? 1.0f : static_cast<float>(params_.point_size));
  setMatrix(vtk.T_world_camera, T_world_camera.matrix());
  vtk.setOverlay(trajectory_so_far, T_world_camera, params_);
  vtk.overlay_actor->SetVisibility(!camera_view);
  switch (params_.view) {
  case RenderView::camera:
    vtk.setCameraView(T_world_camera, params_, depth_range);
    break;
  case RenderView::oblique:
    // Behind (-z), above (-y) and right (+x) of the current camera, in its own frame.
    vtk.setSceneView(T_world_camera.linear() * Eigen::Vector3d(0.4, -0.7, -1.0),
                     -T_world_camera.linear().col(1));
    break;
  case RenderView::top:
    vtk.setSceneView(Eigen::Vector3d(0.0, -1.0, 0.0), Eigen::Vector3d(0.0, 0.0, 1.0));
    break;
  }
  vtk.window->Render();
  return vtk.png.write(out_png, prefix);
}

} // namespace dynvo
