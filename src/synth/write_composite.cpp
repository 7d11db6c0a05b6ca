// SPDX-License-Identifier: BSD-3-Clause
// SceneSynthesizer::writeComposite: scripted objects rendered into a real TUM recording.
#include <dynvo/io/label_io.h>
#include <dynvo/io/trajectory_io.h>
#include <dynvo/io/tum_folder_source.h>
#include <dynvo/synth/depth_sensor_model.h>
#include <dynvo/synth/scene_synthesizer.h>

#include "synthesizer_impl.h"

#include <pcl/exceptions.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <stdexcept>

namespace dynvo {

namespace fs = std::filesystem;

namespace {

/// Ground truth is interpolated across gaps up to this long (s); the TUM motion capture
/// runs at 100 Hz but drops samples (fr1/xyz has a 0.11 s gap).
constexpr double MAX_GROUNDTRUTH_GAP = 0.25;
/// Objects come no nearer than this share of the real scene's 20th depth percentile.
constexpr double DEPTH_MARGIN = 0.9;

cv::Mat
readImage(const fs::path& path, int flags, int type, const char* what)
{
  cv::Mat image;
  try {
    image = cv::imread(path.string(), flags);
  }
  catch (const cv::Exception& e) {
    throw pcl::IOException(path.string() + ": cannot read " + what + " (" + e.what() +
                           ")");
  }
  if (image.empty())
    throw pcl::IOException(path.string() + ": cannot read " + what);
  if (image.type() != type)
    throw pcl::IOException(path.string() + ": not a " + what);
  return image;
}

/// Camera-to-world at `stamp`, interpolated between the two ground-truth poses around it.
Eigen::Isometry3d
interpolatePose(const Trajectory& groundtruth, double stamp, const fs::path& file)
{
  const auto after = std::lower_bound(groundtruth.begin(), groundtruth.end(), stamp,
                                      [](const StampedPose& pose, double t) {
                                        return pose.timestamp < t;
                                      });
  if (after == groundtruth.end() || after == groundtruth.begin() ||
      after->timestamp - (after - 1)->timestamp > MAX_GROUNDTRUTH_GAP) {
    if (after != groundtruth.end() && after->timestamp == stamp)
      return after->T_world_camera;
    throw pcl::IOException(file.string() + ": no ground truth around stamp " +
                           formatStamp(stamp));
  }
  const StampedPose& a = *(after - 1);
  const StampedPose& b = *after;
  const double x = (stamp - a.timestamp) / (b.timestamp - a.timestamp);
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::Quaterniond(a.T_world_camera.linear())
                      .slerp(x, Eigen::Quaterniond(b.T_world_camera.linear()))
                      .toRotationMatrix();
  pose.translation() =
      (1.0 - x) * a.T_world_camera.translation() + x * b.T_world_camera.translation();
  return pose;
}

/// Mean of the three channels over the whole image (0-255).
double
meanBrightness(const cv::Mat& bgr)
{
  const cv::Scalar mean = cv::mean(bgr);
  return (mean[0] + mean[1] + mean[2]) / 3.0;
}

} // namespace

void
SceneSynthesizer::writeComposite(const CompositeOptions& composite,
                                 const std::string& folder) const
{
  const std::string prefix = "[dynvo::SceneSynthesizer::writeComposite] ";
  if (impl_->scenario->objects.empty())
    throw std::invalid_argument(prefix + "scenario '" + impl_->scenario->name +
                                "' has no objects to composite");
  if (composite.frames < 0)
    throw std::invalid_argument(prefix + "frames must be >= 0, got " +
                                std::to_string(composite.frames));
  const fs::path recording(composite.recording);
  TumFolderSource::Options source_options;
  source_options.intrinsics = composite.intrinsics;
  source_options.depth_scale = composite.depth_scale;
  const TumFolderSource source(composite.recording, source_options);
  const fs::path groundtruth_path = recording / "groundtruth.txt";
  const Trajectory groundtruth = readTrajectory(groundtruth_path.string());
  const std::size_t frames =
      composite.frames > 0
          ? std::min<std::size_t>(source.size(),
                                  static_cast<std::size_t>(composite.frames))
          : source.size();
  if (frames == 0)
    throw pcl::IOException(recording.string() + ": no associated colour/depth pairs");
  const auto& entries = source.entries();

  // Everything that can fail on the inputs is checked before the folder is made.
  std::vector<Eigen::Isometry3d> T_world_camera(frames);
  for (std::size_t k = 0; k < frames; ++k)
    T_world_camera[k] =
        interpolatePose(groundtruth, entries[k].rgb_stamp, groundtruth_path);
  const cv::Mat first_bgr = readImage(recording / entries[0].rgb_file, cv::IMREAD_COLOR,
                                      CV_8UC3, "8-bit colour PNG");
  const cv::Mat first_depth =
      readImage(recording / entries[0].depth_file, cv::IMREAD_UNCHANGED, CV_16UC1,
                "16-bit depth PNG");
  const int width = first_bgr.cols, height = first_bgr.rows;
  const double scale_in = source.depthScale();

  // Placement: scale about the scenario's camera at frame 0 (see the declaration).
  const double t0 = entries[0].rgb_stamp;
  const double frame_time = frames > 1 ? entries[1].rgb_stamp - t0 : 1.0 / 30.0;
  const Eigen::Isometry3d T_scenario_camera0_world =
      impl_->scriptAt(0.0, -frame_time).T_world_camera.inverse();
  std::vector<float> real_depths;
  for (int v = 0; v < height; ++v)
    for (int u = 0; u < width; ++u)
      if (const std::uint16_t raw = first_depth.at<std::uint16_t>(v, u))
        real_depths.push_back(static_cast<float>(raw / scale_in));
  if (real_depths.empty())
    throw pcl::IOException((recording / entries[0].depth_file).string() +
                           ": first depth image has no measurement");
  std::nth_element(real_depths.begin(), real_depths.begin() + real_depths.size() / 5,
                   real_depths.end());
  const double z_20 = real_depths[real_depths.size() / 5];
  double z_near = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < frames; ++k) {
    const double t = entries[k].rgb_stamp - t0;
    const FrameScript script = impl_->scriptAt(t, t - frame_time);
    for (const ObjectState& object : script.objects) {
      const Eigen::Vector3d p =
          script.T_world_camera.inverse() * object.T_world_object.translation();
      const Eigen::Vector2f uv = impl_->intrinsics.project(p.cast<float>());
      if (p.z() > 0.0 && uv.x() >= 0 && uv.x() < impl_->options.width && uv.y() >= 0 &&
          uv.y() < impl_->options.height) // in the scenario's own view
        z_near = std::min(z_near, p.z());
    }
  }
  const double scale =
      std::isfinite(z_near) ? std::min(1.0, DEPTH_MARGIN * z_20 / z_near) : 1.0;
  const auto place = [&](const Eigen::Isometry3d& T_world_object) {
    Eigen::Isometry3d T_camera0_object = T_scenario_camera0_world * T_world_object;
    T_camera0_object.translation() *= scale;
    return T_world_camera[0] * T_camera0_object;
  };
  // Albedo: the synthetic room's first frame against the real first frame.
  SynthOptions look_options = impl_->options;
  look_options.width = width;
  look_options.height = height;
  look_options.intrinsics = composite.intrinsics;
  look_options.noise = false;
  look_options.frames = 1;
  const SynthFrame synthetic = SceneSynthesizer(look_options).render(0);
  const cv::Mat synthetic_rgb(height, width, CV_8UC3,
                              const_cast<std::uint8_t*>(synthetic.color.data.data()));
  const float gain =
      static_cast<float>(meanBrightness(first_bgr) / meanBrightness(synthetic_rgb));

  const fs::path root(folder);
  detail::prepareFolder(root);
  const std::size_t pixels = static_cast<std::size_t>(width) * height;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::vector<FrameScript> scripts;
  for (std::size_t k = 0; k < frames; ++k) {
    const TumFolderSource::Entry& entry = entries[k];
    cv::Mat bgr = k == 0 ? first_bgr.clone()
                         : readImage(recording / entry.rgb_file, cv::IMREAD_COLOR,
                                     CV_8UC3, "8-bit colour PNG");
    cv::Mat depth = k == 0
                        ? first_depth.clone()
                        : readImage(recording / entry.depth_file, cv::IMREAD_UNCHANGED,
                                    CV_16UC1, "16-bit depth PNG");
    if (bgr.cols != width || bgr.rows != height || depth.cols != width ||
        depth.rows != height)
      throw pcl::IOException((recording / entry.rgb_file).string() +
                             ": image size differs from the first frame's");
    const double t = entry.rgb_stamp - t0;
    FrameScript script = impl_->scriptAt(t, t - frame_time);
    script.timestamp = entry.rgb_stamp;
    script.depth_timestamp = entry.depth_stamp;
    script.T_world_camera = T_world_camera[k];
    for (ObjectState& object : script.objects) {
      object.T_world_object = place(object.T_world_object);
      object.half_extents *= scale;
    }
    const SceneView view(script, composite.intrinsics, impl_->options, false);
    std::vector<SurfaceSample> samples(pixels);
    std::vector<std::uint8_t> visible(pixels, 0), labels(pixels, 0);
    for (int v = 0; v < height; ++v) {
      std::uint8_t* colour = bgr.ptr<std::uint8_t>(v);
      const std::uint16_t* raw = depth.ptr<std::uint16_t>(v);
      for (int u = 0; u < width; ++u) {
        const std::size_t i = static_cast<std::size_t>(v) * width + u;
        const float real_z = raw[u] == 0 ? nan : static_cast<float>(raw[u] / scale_in);
        samples[i].z = real_z;
        PixelHit hit;
        if (!view.cast(u, v, hit) || hit.surface.z >= real_z) // NaN compares false
          continue;
        samples[i] = hit.surface;
        visible[i] = 1;
        labels[i] = hit.label;
        for (int channel = 0; channel < 3; ++channel) // OpenCV stores BGR
          colour[3 * u + channel] =
              cv::saturate_cast<std::uint8_t>(hit.rgb[2 - channel] * gain + 0.5f);
      }
    }
    std::vector<float> measured(pixels, nan);
    DepthSensorModel::measure(samples, width, height, composite.intrinsics.fx,
                              impl_->options.seed, static_cast<int>(k), visible,
                              measured);
    cv::Mat depth_out(height, width, CV_16UC1);
    for (int v = 0; v < height; ++v) {
      for (int u = 0; u < width; ++u) {
        const std::size_t i = static_cast<std::size_t>(v) * width + u;
        const std::uint16_t raw = depth.at<std::uint16_t>(v, u);
        if (!visible[i])
          depth_out.at<std::uint16_t>(v, u) =
              scale_in == DEPTH_PNG_SCALE ? raw
                                          : cv::saturate_cast<std::uint16_t>(std::round(
                                                raw * DEPTH_PNG_SCALE / scale_in));
        else
          depth_out.at<std::uint16_t>(v, u) =
              std::isnan(measured[i]) ? 0
                                      : cv::saturate_cast<std::uint16_t>(
                                            std::round(measured[i] * DEPTH_PNG_SCALE));
      }
    }
    detail::writeFrameFiles(root, entry.rgb_stamp, entry.depth_stamp, bgr, depth_out,
                            labels);
    scripts.push_back(std::move(script));
  }
  detail::writeIndexFiles(root,
                          "# dynvo composite of scenario '" + impl_->scenario->name +
                              "' (seed " + std::to_string(impl_->options.seed) +
                              ", objects scaled by " + std::to_string(scale) +
                              ") into " + recording.string() + "\n",
                          scripts, groundtruth);
}

} // namespace dynvo
