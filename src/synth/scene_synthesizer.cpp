// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/synth/scene_synthesizer.h>

#include "procedural_texture.h"
#include "scene_script.h"
#include "synthesizer_impl.h"

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
constexpr float AMBIENT = 0.45f; ///< light reaching faces turned away from the lamp
constexpr float DIFFUSE = 0.55f; ///< Lambertian part at normal incidence
constexpr float MIN_COSINE =
    0.25f; ///< footprint growth is capped at 4x at grazing angles
constexpr int ROOM_SURFACES = 6;
constexpr int FURNITURE_SURFACE_BASE = 6;
constexpr int OBJECT_SURFACE_BASE = 64;

/// Direction towards the (directional) light in the world: above, behind-left.
Eigen::Vector3d
lightDirection()
{
  return Eigen::Vector3d(0.3, -0.8, -0.5).normalized();
}

/// Texture seed, base colour and shading of one flat face.
struct SurfaceLook {
  std::uint32_t salt;
  float base[3];
  float shade;
};

SurfaceLook
surfaceLook(std::uint32_t seed, int surface, const Eigen::Vector3d& normal_world)
{
  SurfaceLook look;
  look.salt = detail::mix32(detail::mix32(seed) ^ static_cast<std::uint32_t>(surface));
  const std::uint32_t colour = detail::mix32(look.salt);
  for (int channel = 0; channel < 3; ++channel)
    look.base[channel] =
        0.5f + 0.5f * static_cast<float>((colour >> (8 * channel)) & 255U) / 255.0f;
  look.shade =
      AMBIENT +
      DIFFUSE * static_cast<float>(std::max(0.0, normal_world.dot(lightDirection())));
  return look;
}

/// An oriented box as seen from one camera pose.
struct FrameBox {
  Eigen::Matrix3f ray_to_box;       ///< camera-frame ray direction to box frame
  Eigen::Vector3f origin;           ///< camera centre in the box frame (metres)
  Eigen::Vector3f half;             ///< half extents (metres)
  std::uint8_t label;               ///< label written for its pixels (0 unless moving)
  std::array<SurfaceLook, 6> faces; ///< face 2a + s: axis a, s = 1 on the + side
  int u0, u1, v0, v1; ///< inclusive pixel rectangle holding its projection
};

FrameBox
frameBox(const Eigen::Isometry3d& T_world_box,
         const Eigen::Vector3d& half,
         std::uint8_t label,
         int surface_base,
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
                                  T_world_box.linear() * normal_box);
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

/// Depth model of SceneSynthesizer's class documentation, applied in place.
void
applyDepthModel(
    std::uint32_t seed, int k, int width, int height, std::vector<float>& depth)
{
  const std::vector<float> exact = depth;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const std::uint64_t frame_key = detail::splitMix64(
      (static_cast<std::uint64_t>(seed) << 32) | static_cast<std::uint32_t>(k));
  const float jump = static_cast<float>(SceneSynthesizer::EDGE_JUMP_RATIO);
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * width + u;
      const float z = exact[i];
      const auto nearer = [&](std::size_t n) {
        return z - exact[n] > jump * z;
      };
      const bool edge = (u > 0 && nearer(i - 1)) || (u + 1 < width && nearer(i + 1)) ||
                        (v > 0 && nearer(i - width)) ||
                        (v + 1 < height && nearer(i + width));
      const std::uint64_t r1 = detail::splitMix64(frame_key + i);
      const std::uint64_t r2 = detail::splitMix64(r1);
      const double dropout = static_cast<double>(r1 >> 40) / 16777216.0;
      if (edge || dropout < SceneSynthesizer::DROPOUT_RATE) {
        depth[i] = nan;
        continue;
      }
      // Box-Muller from two 24-bit uniforms (u1 in (0, 1], so the log is finite).
      const double u1 = (static_cast<double>(r2 >> 40) + 1.0) / 16777216.0;
      const double u2 = static_cast<double>(r2 & 0xFFFFFFU) / 16777216.0;
      const double gauss = std::sqrt(-2.0 * std::log(u1)) * std::cos(TWO_PI * u2);
      const double noisy = z + SceneSynthesizer::NOISE_SIGMA_PER_Z2 * z * z * gauss;
      const double step = SceneSynthesizer::INVERSE_DEPTH_STEP;
      const double measured = 1.0 / (std::round(1.0 / noisy / step) * step);
      depth[i] = measured >= SceneSynthesizer::MIN_DEPTH &&
                         measured <= SceneSynthesizer::MAX_DEPTH
                     ? static_cast<float>(measured)
                     : nan;
    }
  }
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
  const double t = k / options.fps;
  const double t_previous = (k - 1) / options.fps;
  FrameScript frame;
  // Whole microseconds, so the "%.6f" stamps of the files parse back to these values.
  frame.timestamp = std::round((FIRST_STAMP + t) * 1e6) / 1e6;
  frame.depth_timestamp = std::round((frame.timestamp + DEPTH_STAMP_DELAY) * 1e6) / 1e6;
  frame.T_world_camera = scenario->camera.pose(t);
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

SynthFrame
SceneSynthesizer::render(int k) const
{
  const SynthOptions& options = impl_->options;
  if (k < 0 || k >= options.frames)
    throw std::invalid_argument("[dynvo::SceneSynthesizer::render] frame " +
                                std::to_string(k) + " is outside [0, " +
                                std::to_string(options.frames) + ")");
  FrameScript script = impl_->script(k);
  const CameraIntrinsics& K = impl_->intrinsics;
  const Room& room = detail::room();

  std::vector<FrameBox> boxes;
  for (std::size_t f = 0; f < room.furniture.size(); ++f) {
    Eigen::Isometry3d T_world_box = Eigen::Isometry3d::Identity();
    T_world_box.translation() = room.furniture[f].centre;
    boxes.push_back(frameBox(T_world_box, room.furniture[f].half_extents, 0,
                             FURNITURE_SURFACE_BASE + 6 * static_cast<int>(f),
                             script.T_world_camera, K, options));
  }
  for (const ObjectState& object : script.objects)
    boxes.push_back(frameBox(object.T_world_object, object.half_extents,
                             object.moving ? static_cast<std::uint8_t>(object.id) : 0,
                             OBJECT_SURFACE_BASE + 6 * object.id, script.T_world_camera,
                             K, options));
  std::array<SurfaceLook, ROOM_SURFACES> room_faces;
  for (int face = 0; face < ROOM_SURFACES; ++face) // normals point into the room
    room_faces[face] =
        surfaceLook(options.seed, face,
                    (face % 2 == 1 ? -1.0 : 1.0) * Eigen::Vector3d::Unit(face / 2));

  const int width = options.width, height = options.height;
  const std::size_t pixels = static_cast<std::size_t>(width) * height;
  SynthFrame frame;
  frame.timestamp = script.timestamp;
  frame.depth_timestamp = script.depth_timestamp;
  frame.T_world_camera = script.T_world_camera;
  frame.objects = std::move(script.objects);
  frame.color.width = frame.depth.width = width;
  frame.color.height = frame.depth.height = height;
  frame.color.data.resize(3 * pixels);
  frame.depth.data.resize(pixels);
  frame.labels.assign(pixels, 0);

  const Eigen::Matrix3f R = frame.T_world_camera.linear().cast<float>();
  const Eigen::Vector3f o = frame.T_world_camera.translation().cast<float>();
  const Eigen::Vector3f room_min = room.min_corner.cast<float>();
  const Eigen::Vector3f room_max = room.max_corner.cast<float>();
  const float inv_fx = static_cast<float>(1.0 / K.fx),
              inv_fy = static_cast<float>(1.0 / K.fy);
  const float focal = static_cast<float>(std::min(K.fx, K.fy));

  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * width + u;
      // Ray with unit z in the camera frame: its parameter at a hit is the depth z.
      const Eigen::Vector3f ray(static_cast<float>(u - K.cx) * inv_fx,
                                static_cast<float>(v - K.cy) * inv_fy, 1.0f);
      const Eigen::Vector3f ray_world = R * ray;
      // Leaving the room through the nearest of the three walls ahead.
      float t_best = INF;
      int axis = 0;
      for (int a = 0; a < 3; ++a) {
        const float bound = std::signbit(ray_world[a]) ? room_min[a] : room_max[a];
        const float t = (bound - o[a]) / ray_world[a];
        if (t < t_best) {
          t_best = t;
          axis = a;
        }
      }
      const SurfaceLook* look =
          &room_faces[2 * axis + (ray_world[axis] > 0.0f ? 1 : 0)];
      Eigen::Vector3f hit = o + t_best * ray_world;
      float ray_along_normal = ray_world[axis];
      std::uint8_t label = 0;
      for (const FrameBox& box : boxes) {
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
      const float ray_norm = ray.norm();
      const float cosine = std::max(std::abs(ray_along_normal) / ray_norm, MIN_COSINE);
      const float footprint = t_best * ray_norm / (focal * cosine);
      float albedo[3];
      detail::surfaceAlbedo(hit[(axis + 1) % 3], hit[(axis + 2) % 3], look->base,
                            look->salt, footprint, albedo);
      for (int channel = 0; channel < 3; ++channel)
        frame.color.data[3 * i + channel] =
            static_cast<std::uint8_t>(albedo[channel] * look->shade * 255.0f + 0.5f);
      frame.depth.data[i] = t_best;
      frame.labels[i] = label;
    }
  }
  if (options.noise)
    applyDepthModel(options.seed, k, width, height, frame.depth.data);
  return frame;
}

} // namespace dynvo
