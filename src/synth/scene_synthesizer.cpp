// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/synth/scene_synthesizer.h>

#include "procedural_texture.h"
#include "scene_script.h"
#include "synthesizer_impl.h"

#include <dynvo/synth/depth_sensor_model.h>

#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace dynvo {

namespace {

using detail::Room;
using detail::Scenario;

constexpr float INF = std::numeric_limits<float>::infinity();
constexpr double TWO_PI = 6.28318530717958647692;
constexpr float AMBIENT = 0.45f;     ///< light reaching faces turned away from the lamp
constexpr float DIFFUSE = 0.55f;     ///< Lambertian part at normal incidence
constexpr float DARK_ALBEDO = 0.12f; ///< brightness of dark materials
constexpr float MIN_COSINE =
    0.25f; ///< footprint growth is capped at 4x at grazing angles
constexpr int ROOM_SURFACES = 6;
constexpr int FURNITURE_SURFACE_BASE = 6;
constexpr int OBJECT_SURFACE_BASE = 64;
constexpr int BLUR_SAMPLES = 7; ///< sub-frames averaged over a moving object's exposure
/// Camera blur: sub-frames are at most this far apart in the image (px), so a streak is
/// a smooth smear rather than separate copies; the count is capped (rendering cost).
constexpr double CAMERA_BLUR_STEP = 3.0;
constexpr int MAX_CAMERA_BLUR_SAMPLES = 9;
constexpr int BLUR_PROBES = 9; ///< probe pixels per image axis for the streak length

/// Direction towards the (directional) light in the world: above, behind-left.
Eigen::Vector3d
lightDirection()
{
  return Eigen::Vector3d(0.3, -0.8, -0.5).normalized();
}

SurfaceLook
surfaceLook(std::uint32_t seed,
            int surface,
            const Eigen::Vector3d& normal_world,
            bool dark = false,
            bool plain = false)
{
  SurfaceLook look;
  look.salt = detail::mix32(detail::mix32(seed) ^ static_cast<std::uint32_t>(surface));
  look.dark = dark;
  look.plain = plain;
  const std::uint32_t colour = detail::mix32(look.salt);
  const float brightness = dark ? DARK_ALBEDO : 1.0f;
  for (int channel = 0; channel < 3; ++channel)
    look.base[channel] =
        brightness *
        (0.5f + 0.5f * static_cast<float>((colour >> (8 * channel)) & 255U) / 255.0f);
  look.shade =
      AMBIENT +
      DIFFUSE * static_cast<float>(std::max(0.0, normal_world.dot(lightDirection())));
  return look;
}

FrameBox
frameBox(const Eigen::Isometry3d& T_world_box,
         const Eigen::Vector3d& half,
         std::uint8_t label,
         int surface_base,
         bool dark,
         bool plain,
         const Eigen::Isometry3d& T_world_camera,
         const CameraIntrinsics& intrinsics,
         const SynthOptions& options)
{
  const Eigen::Isometry3d T_box_camera = T_world_box.inverse() * T_world_camera;
  FrameBox box;
  box.ray_to_box = T_box_camera.linear().cast<float>();
  box.origin = T_box_camera.translation().cast<float>();
  box.half = half.cast<float>();
  box.label = label;
  for (int face = 0; face < 6; ++face) {
    const Eigen::Vector3d normal_box =
        (face % 2 == 1 ? 1.0 : -1.0) * Eigen::Vector3d::Unit(face / 2);
    box.faces[face] = surfaceLook(options.seed, surface_base + face,
                                  T_world_box.linear() * normal_box, dark, plain);
  }
  // Rectangle of the projected corners; a corner near or behind the camera plane
  // makes the whole image a candidate.
  const Eigen::Isometry3d T_camera_box = T_world_camera.inverse() * T_world_box;
  double u_min = INF, u_max = -INF, v_min = INF, v_max = -INF;
  bool whole_image = false;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d local((corner & 1 ? 1 : -1) * half.x(),
                                (corner & 2 ? 1 : -1) * half.y(),
                                (corner & 4 ? 1 : -1) * half.z());
    const Eigen::Vector3d p = T_camera_box * local;
    if (p.z() < 1e-3) {
      whole_image = true;
      break;
    }
    const double u = intrinsics.fx * p.x() / p.z() + intrinsics.cx;
    const double v = intrinsics.fy * p.y() / p.z() + intrinsics.cy;
    u_min = std::min(u_min, u);
    u_max = std::max(u_max, u);
    v_min = std::min(v_min, v);
    v_max = std::max(v_max, v);
  }
  if (whole_image) {
    box.u0 = box.v0 = 0;
    box.u1 = options.width - 1;
    box.v1 = options.height - 1;
    return box;
  }
  const auto clampPixel = [](double value, int size) {
    return static_cast<int>(std::clamp(value, -1.0, static_cast<double>(size)));
  };
  box.u0 = clampPixel(std::floor(u_min) - 1.0, options.width);
  box.u1 = clampPixel(std::ceil(u_max) + 1.0, options.width);
  box.v0 = clampPixel(std::floor(v_min) - 1.0, options.height);
  box.v1 = clampPixel(std::ceil(v_max) + 1.0, options.height);
  return box;
}

/// Longest image path (px) of a scene point seen by `view` (the camera at T_world_mid)
/// between the camera poses T_world_start and T_world_end; probes a grid of pixels.
double
streakLength(const SceneView& view,
             const CameraIntrinsics& K,
             int width,
             int height,
             const Eigen::Isometry3d& T_world_mid,
             const Eigen::Isometry3d& T_world_start,
             const Eigen::Isometry3d& T_world_end)
{
  const Eigen::Isometry3d T_start_mid = T_world_start.inverse() * T_world_mid;
  const Eigen::Isometry3d T_end_mid = T_world_end.inverse() * T_world_mid;
  double longest = 0.0;
  for (int i = 0; i < BLUR_PROBES; ++i) {
    for (int j = 0; j < BLUR_PROBES; ++j) {
      const int u = (width - 1) * i / (BLUR_PROBES - 1);
      const int v = (height - 1) * j / (BLUR_PROBES - 1);
      PixelHit hit;
      if (!view.cast(u, v, hit))
        continue;
      const Eigen::Vector3d p_mid = K.backproject(u, v, hit.surface.z).cast<double>();
      const Eigen::Vector3d a = T_start_mid * p_mid, b = T_end_mid * p_mid;
      if (a.z() <= 0.0 || b.z() <= 0.0)
        continue;
      const Eigen::Vector2d uv_a(K.fx * a.x() / a.z(), K.fy * a.y() / a.z());
      const Eigen::Vector2d uv_b(K.fx * b.x() / b.z(), K.fy * b.y() / b.z());
      longest = std::max(longest, (uv_a - uv_b).norm());
    }
  }
  return longest;
}

} // namespace

void
SynthOptions::validate() const
{
  const std::string prefix = "[dynvo::SynthOptions::validate] ";
  const auto& all = detail::allScenarios();
  if (std::none_of(all.begin(), all.end(), [this](const Scenario& s) {
        return s.name == scenario;
      }))
    throw std::invalid_argument(prefix + "unknown scenario '" + scenario +
                                "' (see SceneSynthesizer::scenarios())");
  if (frames < 1 || frames > 1000000)
    throw std::invalid_argument(prefix + "frames must be in [1, 1000000], got " +
                                std::to_string(frames));
  if (width < 8 || width > 8192 || height < 8 || height > 8192)
    throw std::invalid_argument(prefix + "image size must be in [8, 8192] px, got " +
                                std::to_string(width) + "x" + std::to_string(height));
  if (!std::isfinite(fps) || fps <= 0.0 || fps > 1000.0)
    throw std::invalid_argument(prefix + "fps must be in (0, 1000] Hz, got " +
                                std::to_string(fps));
  intrinsics.validate();
}

SceneSynthesizer::SceneSynthesizer(const SynthOptions& options)
    : impl_(std::make_unique<Impl>())
{
  options.validate();
  impl_->options = options;
  for (const Scenario& scenario : detail::allScenarios())
    if (scenario.name == options.scenario)
      impl_->scenario = &scenario;
  // Scale about pixel corners: pixel centres stay at integer coordinates.
  const double sx = options.width / 640.0, sy = options.height / 480.0;
  impl_->intrinsics.fx = options.intrinsics.fx * sx;
  impl_->intrinsics.fy = options.intrinsics.fy * sy;
  impl_->intrinsics.cx = (options.intrinsics.cx + 0.5) * sx - 0.5;
  impl_->intrinsics.cy = (options.intrinsics.cy + 0.5) * sy - 0.5;
}

SceneSynthesizer::~SceneSynthesizer() = default;

std::vector<ScenarioInfo>
SceneSynthesizer::scenarios()
{
  std::vector<ScenarioInfo> infos;
  for (const Scenario& scenario : detail::allScenarios())
    infos.push_back({scenario.name, scenario.description});
  return infos;
}

CameraIntrinsics
SceneSynthesizer::intrinsics() const
{
  return impl_->intrinsics;
}

FrameScript
SceneSynthesizer::Impl::script(int k) const
{
  return scriptAt(k / options.fps, (k - 1) / options.fps);
}

FrameScript
SceneSynthesizer::Impl::scriptAt(double t, double t_previous) const
{
  FrameScript frame;
  // Whole microseconds, so the "%.6f" stamps of the files parse back to these values.
  frame.timestamp = std::round((FIRST_STAMP + t) * 1e6) / 1e6;
  frame.T_world_camera = scenario->camera.pose(scenario->camera_schedule.progress(t));
  for (const detail::ScriptedBox& box : scenario->objects) {
    const double s = box.schedule.progress(t);
    ObjectState state;
    state.id = box.id;
    state.T_world_object = box.path.pose(s);
    state.moving = s != box.schedule.progress(t_previous);
    state.half_extents = box.half_extents;
    frame.objects.push_back(state);
  }
  return frame;
}

SceneView::SceneView(const FrameScript& script,
                     const CameraIntrinsics& intrinsics,
                     const SynthOptions& options,
                     bool with_room)
    : intrinsics_(intrinsics)
    , with_room_(with_room)
{
  const Room& room = detail::room();
  if (with_room) {
    for (std::size_t f = 0; f < room.furniture.size(); ++f) {
      Eigen::Isometry3d T_world_box = Eigen::Isometry3d::Identity();
      T_world_box.translation() = room.furniture[f].centre;
      boxes_.push_back(frameBox(T_world_box, room.furniture[f].half_extents, 0,
                                FURNITURE_SURFACE_BASE + 6 * static_cast<int>(f),
                                room.furniture[f].dark, false, script.T_world_camera,
                                intrinsics, options));
    }
    for (int face = 0; face < ROOM_SURFACES; ++face) // normals point into the room
      room_faces_[face] =
          surfaceLook(options.seed, face,
                      (face % 2 == 1 ? -1.0 : 1.0) * Eigen::Vector3d::Unit(face / 2));
  }
  for (const ObjectState& object : script.objects)
    boxes_.push_back(frameBox(object.T_world_object, object.half_extents,
                              object.moving ? static_cast<std::uint8_t>(object.id) : 0,
                              OBJECT_SURFACE_BASE + 6 * object.id, false,
                              options.plain_objects, script.T_world_camera, intrinsics,
                              options));
  R_ = script.T_world_camera.linear().cast<float>();
  o_ = script.T_world_camera.translation().cast<float>();
  room_min_ = room.min_corner.cast<float>();
  room_max_ = room.max_corner.cast<float>();
}

SceneView::~SceneView() = default;

bool
SceneView::movingRectangle(int& u0, int& u1, int& v0, int& v1) const
{
  bool any = false;
  for (const FrameBox& box : boxes_) {
    if (box.label == 0)
      continue;
    u0 = any ? std::min(u0, box.u0) : box.u0;
    u1 = any ? std::max(u1, box.u1) : box.u1;
    v0 = any ? std::min(v0, box.v0) : box.v0;
    v1 = any ? std::max(v1, box.v1) : box.v1;
    any = true;
  }
  return any;
}

bool
SceneView::cast(float u, float v, PixelHit& out) const
{
  const CameraIntrinsics& K = intrinsics_;
  // Ray with unit z in the camera frame: its parameter at a hit is the depth z.
  const Eigen::Vector3f ray(static_cast<float>((u - K.cx) / K.fx),
                            static_cast<float>((v - K.cy) / K.fy), 1.0f);
  float t_best = INF;
  int axis = 0;
  const SurfaceLook* look = nullptr;
  Eigen::Vector3f hit = Eigen::Vector3f::Zero();
  float ray_along_normal = 1.0f;
  std::uint8_t label = 0;
  if (with_room_) {
    // Leaving the room through the nearest of the three walls ahead.
    const Eigen::Vector3f ray_world = R_ * ray;
    for (int a = 0; a < 3; ++a) {
      const float bound = std::signbit(ray_world[a]) ? room_min_[a] : room_max_[a];
      const float t = (bound - o_[a]) / ray_world[a];
      if (t < t_best) {
        t_best = t;
        axis = a;
      }
    }
    look = &room_faces_[2 * axis + (ray_world[axis] > 0.0f ? 1 : 0)];
    hit = o_ + t_best * ray_world;
    ray_along_normal = ray_world[axis];
  }
  for (const FrameBox& box : boxes_) {
    if (u < box.u0 || u > box.u1 || v < box.v0 || v > box.v1)
      continue;
    const Eigen::Vector3f d = box.ray_to_box * ray;
    float t_near = -INF, t_far = INF;
    int near_axis = 0;
    for (int a = 0; a < 3; ++a) {
      const float inv = 1.0f / d[a];
      const float t1 = (-box.half[a] - box.origin[a]) * inv;
      const float t2 = (box.half[a] - box.origin[a]) * inv;
      const float lo = std::min(t1, t2);
      if (lo > t_near) {
        t_near = lo;
        near_axis = a;
      }
      t_far = std::min(t_far, std::max(t1, t2));
    }
    if (t_near > t_far || t_near <= 0.0f || t_near >= t_best)
      continue;
    t_best = t_near;
    axis = near_axis;
    look = &box.faces[2 * axis + (d[axis] < 0.0f ? 1 : 0)];
    hit = box.origin + t_near * d;
    ray_along_normal = d[axis];
    label = box.label;
  }
  if (look == nullptr)
    return false;
  const float ray_norm = ray.norm();
  const float cosine = std::abs(ray_along_normal) / ray_norm;
  const float footprint =
      t_best * ray_norm /
      (static_cast<float>(std::min(K.fx, K.fy)) * std::max(cosine, MIN_COSINE));
  float albedo[3];
  if (look->plain)
    for (int channel = 0; channel < 3; ++channel)
      albedo[channel] = look->base[channel] * detail::MEAN_ALBEDO;
  else
    detail::surfaceAlbedo(hit[(axis + 1) % 3], hit[(axis + 2) % 3], look->base,
                          look->salt, footprint, albedo);
  for (int channel = 0; channel < 3; ++channel)
    out.rgb[channel] = albedo[channel] * look->shade * 255.0f;
  out.surface = {t_best, cosine, look->dark};
  out.label = label;
  return true;
}

void
SceneView::meanColour(const std::vector<SceneView>& exposure,
                      int u0,
                      int u1,
                      int v0,
                      int v1,
                      int width,
                      ColorImage& color)
{
  for (int v = v0; v <= v1; ++v) {
    for (int u = u0; u <= u1; ++u) {
      float sum[3] = {0.0f, 0.0f, 0.0f};
      for (const SceneView& view : exposure) {
        PixelHit hit;
        view.cast(u, v, hit);
        for (int channel = 0; channel < 3; ++channel)
          sum[channel] += hit.rgb[channel];
      }
      const std::size_t i = static_cast<std::size_t>(v) * width + u;
      for (int channel = 0; channel < 3; ++channel)
        color.data[3 * i + channel] =
            static_cast<std::uint8_t>(sum[channel] / exposure.size() + 0.5f);
    }
  }
}

void
SceneView::blurColour(const std::vector<SceneView>& exposure,
                      int width,
                      int height,
                      ColorImage& color)
{
  int u0 = 0, u1 = 0, v0 = 0, v1 = 0;
  bool any = false;
  for (const SceneView& view : exposure) {
    int a0, a1, b0, b1;
    if (!view.movingRectangle(a0, a1, b0, b1))
      continue;
    u0 = any ? std::min(u0, a0) : a0;
    u1 = any ? std::max(u1, a1) : a1;
    v0 = any ? std::min(v0, b0) : b0;
    v1 = any ? std::max(v1, b1) : b1;
    any = true;
  }
  if (any)
    meanColour(exposure, std::max(u0, 0), std::min(u1, width - 1), std::max(v0, 0),
               std::min(v1, height - 1), width, color);
}

double
SceneSynthesizer::largestMovingShare() const
{
  const SynthOptions& options = impl_->options;
  std::size_t largest = 0;
  for (int k = 0; k < options.frames; ++k) {
    const SceneView view(impl_->script(k), impl_->intrinsics, options, true);
    std::size_t moving = 0;
    for (int v = 0; v < options.height; ++v) {
      for (int u = 0; u < options.width; ++u) {
        PixelHit hit;
        moving += view.cast(u, v, hit) && hit.label != 0;
      }
    }
    largest = std::max(largest, moving);
  }
  return static_cast<double>(largest) / (options.width * options.height);
}

SynthFrame
SceneSynthesizer::render(int k) const
{
  const SynthOptions& options = impl_->options;
  if (k < 0 || k >= options.frames)
    throw std::invalid_argument("[dynvo::SceneSynthesizer::render] frame " +
                                std::to_string(k) + " is outside [0, " +
                                std::to_string(options.frames) + ")");
  FrameScript script = impl_->script(k);
  const SceneView view(script, impl_->intrinsics, options, true);

  const int width = options.width, height = options.height;
  const std::size_t pixels = static_cast<std::size_t>(width) * height;
  SynthFrame frame;
  frame.timestamp = script.timestamp;
  frame.T_world_camera = script.T_world_camera;
  frame.objects = std::move(script.objects);
  frame.color.width = frame.depth.width = width;
  frame.color.height = frame.depth.height = height;
  frame.color.data.resize(3 * pixels);
  frame.labels.assign(pixels, 0);
  std::vector<SurfaceSample> samples(pixels);
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * width + u;
      PixelHit hit;
      view.cast(u, v, hit); // inside the room every ray hits
      for (int channel = 0; channel < 3; ++channel)
        frame.color.data[3 * i + channel] =
            static_cast<std::uint8_t>(hit.rgb[channel] + 0.5f);
      samples[i] = hit.surface;
      frame.labels[i] = hit.label;
    }
  }
  const double exposure = options.motion_blur ? impl_->scenario->exposure : 0.0;
  if (exposure > 0.0) {
    const double t = k / options.fps, t_previous = (k - 1) / options.fps;
    // n instants evenly spread over the exposure, centred on the colour stamp.
    const auto exposureViews = [&](int n) {
      std::vector<SceneView> views;
      for (int j = 0; j < n; ++j)
        views.emplace_back(
            impl_->scriptAt(t + exposure * (j / (n - 1.0) - 0.5), t_previous),
            impl_->intrinsics, options, true);
      return views;
    };
    // Camera blur over the whole image; none while the camera rests (streak 0 px).
    const double streak =
        streakLength(view, impl_->intrinsics, width, height, frame.T_world_camera,
                     impl_->scriptAt(t - 0.5 * exposure, t_previous).T_world_camera,
                     impl_->scriptAt(t + 0.5 * exposure, t_previous).T_world_camera);
    if (streak > 0.0) {
      const int n = std::min(MAX_CAMERA_BLUR_SAMPLES,
                             2 + static_cast<int>(streak / CAMERA_BLUR_STEP));
      SceneView::meanColour(exposureViews(n), 0, width - 1, 0, height - 1, width,
                            frame.color);
    }
    SceneView::blurColour(exposureViews(BLUR_SAMPLES), width, height, frame.color);
  }
  if (options.noise) {
    DepthSensorModel::measure(samples, width, height, impl_->intrinsics.fx,
                              options.seed, k, {}, frame.depth.data);
  }
  else {
    frame.depth.data.resize(pixels);
    for (std::size_t i = 0; i < pixels; ++i)
      frame.depth.data[i] = samples[i].z;
  }
  return frame;
}

} // namespace dynvo
