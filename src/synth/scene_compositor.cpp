// SPDX-License-Identifier: BSD-3-Clause
// SceneCompositor: scripted objects rendered into the frames of a real recording.
#include <dynvo/synth/depth_sensor_model.h>
#include <dynvo/synth/scene_compositor.h>

#include "synthesizer_impl.h"

#include <opencv2/core.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace dynvo {

namespace {

/// Objects come no nearer than this share of the real scene's 20th depth percentile.
constexpr double DEPTH_MARGIN = 0.9;

/// Mean of the three channels over the whole image (0-255), summed in the channel
/// order given (0, 1, 2 or 2, 1, 0).
double
meanBrightness(const ColorImage& color, bool reversed)
{
  const cv::Mat image(static_cast<int>(color.height), static_cast<int>(color.width),
                      CV_8UC3, const_cast<std::uint8_t*>(color.data.data()));
  const cv::Scalar mean = cv::mean(image);
  return reversed ? (mean[2] + mean[1] + mean[0]) / 3.0
                  : (mean[0] + mean[1] + mean[2]) / 3.0;
}

const std::string PREFIX = "[dynvo::SceneCompositor] ";

} // namespace

SceneCompositor::SceneCompositor(const SynthOptions& options)
    : synth_(options)
{
  if (synth_.impl_->scenario->objects.empty())
    throw std::invalid_argument(PREFIX + "scenario '" + synth_.impl_->scenario->name +
                                "' has no objects to composite");
}

void
SceneCompositor::setRecording(const CameraIntrinsics& intrinsics,
                              double depth_scale,
                              const std::vector<double>& rgb_stamps,
                              const std::vector<Eigen::Isometry3d>& T_world_camera,
                              const ColorImage& first_color,
                              const RawDepthImage& first_depth)
{
  if (rgb_stamps.empty() || rgb_stamps.size() != T_world_camera.size())
    throw std::invalid_argument(PREFIX + "need one camera pose per colour stamp, got " +
                                std::to_string(rgb_stamps.size()) + " stamps and " +
                                std::to_string(T_world_camera.size()) + " poses");
  if (!(depth_scale > 0.0))
    throw std::invalid_argument(PREFIX + "depth scale must be positive");
  if (first_color.width != first_depth.width ||
      first_color.height != first_depth.height ||
      first_color.data.size() != 3 * first_depth.data.size() ||
      first_depth.data.size() != std::size_t{first_depth.width} * first_depth.height)
    throw std::invalid_argument(PREFIX +
                                "first colour and depth images differ in size");
  const SceneSynthesizer::Impl& impl = *synth_.impl_;
  intrinsics_ = intrinsics;
  depth_scale_ = depth_scale;
  rgb_stamps_ = rgb_stamps;
  T_world_camera_ = T_world_camera;
  width_ = first_color.width;
  height_ = first_color.height;
  lens_ = intrinsics.distorted()
              ? std::make_shared<const LensUndistortion>(intrinsics, width_, height_)
              : nullptr;

  // Placement: scale about the scenario's camera at frame 0 (see the class docs).
  const double t0 = rgb_stamps_[0];
  const std::size_t frames = rgb_stamps_.size();
  frame_time_ = frames > 1 ? rgb_stamps_[1] - t0 : 1.0 / 30.0;
  T_scenario_camera0_world_ = impl.scriptAt(0.0, -frame_time_).T_world_camera.inverse();
  std::vector<float> real_depths;
  for (const std::uint16_t raw : first_depth.data)
    if (raw != 0)
      real_depths.push_back(static_cast<float>(raw / depth_scale_));
  if (real_depths.empty())
    throw std::invalid_argument(PREFIX + "first depth image has no measurement");
  std::nth_element(real_depths.begin(), real_depths.begin() + real_depths.size() / 5,
                   real_depths.end());
  const double z_20 = real_depths[real_depths.size() / 5];
  double z_near = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < frames; ++k) {
    const double t = rgb_stamps_[k] - t0;
    const FrameScript script = impl.scriptAt(t, t - frame_time_);
    for (const ObjectState& object : script.objects) {
      const Eigen::Vector3d p =
          script.T_world_camera.inverse() * object.T_world_object.translation();
      const Eigen::Vector2f uv = impl.intrinsics.project(p.cast<float>());
      if (p.z() > 0.0 && uv.x() >= 0 && uv.x() < impl.options.width && uv.y() >= 0 &&
          uv.y() < impl.options.height) // in the scenario's own view
        z_near = std::min(z_near, p.z());
    }
  }
  scale_ = std::isfinite(z_near) ? std::min(1.0, DEPTH_MARGIN * z_20 / z_near) : 1.0;

  // Albedo: the synthetic room's first frame against the real first frame.
  SynthOptions look_options = impl.options;
  look_options.width = static_cast<int>(width_);
  look_options.height = static_cast<int>(height_);
  look_options.intrinsics = intrinsics_;
  look_options.noise = false;
  look_options.frames = 1;
  const SynthFrame synthetic = SceneSynthesizer(look_options).render(0);
  // The real image's channel sums are taken in the order B, G, R, as OpenCV stores it.
  gain_ = static_cast<float>(meanBrightness(first_color, true) /
                             meanBrightness(synthetic.color, false));
}

CompositeFrame
SceneCompositor::composite(std::size_t k,
                           const ColorImage& color,
                           const RawDepthImage& depth) const
{
  if (k >= rgb_stamps_.size())
    throw std::invalid_argument(PREFIX + "frame " + std::to_string(k) +
                                " is outside the recording set by setRecording()");
  if (color.width != width_ || color.height != height_ || depth.width != width_ ||
      depth.height != height_ || color.data.size() != 3 * depth.data.size() ||
      depth.data.size() != std::size_t{width_} * height_)
    throw std::invalid_argument(PREFIX + "frame " + std::to_string(k) +
                                ": image size differs from the first frame's");
  const SceneSynthesizer::Impl& impl = *synth_.impl_;
  const int width = static_cast<int>(width_), height = static_cast<int>(height_);
  const std::size_t pixels = std::size_t{width_} * height_;
  const float nan = std::numeric_limits<float>::quiet_NaN();

  const double t = rgb_stamps_[k] - rgb_stamps_[0];
  FrameScript script = impl.scriptAt(t, t - frame_time_);
  script.timestamp = rgb_stamps_[k];
  script.T_world_camera = T_world_camera_[k];
  for (ObjectState& object : script.objects) {
    Eigen::Isometry3d T_camera0_object =
        T_scenario_camera0_world_ * object.T_world_object;
    T_camera0_object.translation() *= scale_;
    object.T_world_object = T_world_camera_[0] * T_camera0_object;
    object.half_extents *= scale_;
  }
  const SceneView view(script, intrinsics_, impl.options, false);

  CompositeFrame out;
  out.color = color;
  out.labels = {width_, height_, std::vector<std::uint8_t>(pixels, 0)};
  std::vector<SurfaceSample> samples(pixels);
  std::vector<std::uint8_t> visible(pixels, 0);
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * width + u;
      const std::uint16_t raw = depth.data[i];
      const float real_z = raw == 0 ? nan : static_cast<float>(raw / depth_scale_);
      samples[i].z = real_z;
      PixelHit hit;
      const Eigen::Vector2f ray =
          lens_ ? lens_->undistortedPixel(u, v)
                : Eigen::Vector2f(static_cast<float>(u), static_cast<float>(v));
      if (!view.cast(ray.x(), ray.y(), hit) || hit.surface.z >= real_z) // NaN: false
        continue;
      samples[i] = hit.surface;
      visible[i] = 1;
      out.labels.data[i] = hit.label;
      for (int channel = 0; channel < 3; ++channel)
        out.color.data[3 * i + channel] =
            cv::saturate_cast<std::uint8_t>(hit.rgb[channel] * gain_ + 0.5f);
    }
  }
  std::vector<float> measured(pixels, nan);
  DepthSensorModel::measure(samples, width, height, intrinsics_.fx, impl.options.seed,
                            static_cast<int>(k), visible, measured);
  const double out_scale = SceneSynthesizer::DEPTH_PNG_SCALE;
  out.depth = {width_, height_, std::vector<std::uint16_t>(pixels, 0)};
  for (std::size_t i = 0; i < pixels; ++i) {
    const std::uint16_t raw = depth.data[i];
    if (!visible[i])
      out.depth.data[i] = depth_scale_ == out_scale
                              ? raw
                              : cv::saturate_cast<std::uint16_t>(
                                    std::round(raw * out_scale / depth_scale_));
    else
      out.depth.data[i] =
          std::isnan(measured[i])
              ? 0
              : cv::saturate_cast<std::uint16_t>(std::round(measured[i] * out_scale));
  }
  out.objects = std::move(script.objects);
  return out;
}

} // namespace dynvo
