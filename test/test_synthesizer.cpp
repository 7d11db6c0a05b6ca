// SPDX-License-Identifier: BSD-3-Clause
// SceneSynthesizer: determinism, geometry, labels, depth model, scenarios, files.
#include <dynvo/io/trajectory_io.h>
#include <dynvo/io/tum_folder_source.h>
#include <dynvo/synth/scene_synthesizer.h>

#include "support/temp_dir.h"

#include <pcl/exceptions.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>

namespace {

namespace fs = std::filesystem;

dynvo::SynthOptions
smallOptions(const std::string& scenario, int width = 160, int height = 120)
{
  dynvo::SynthOptions options;
  options.scenario = scenario;
  options.width = width;
  options.height = height;
  return options;
}

/// Bytes of every file below root, keyed by relative path.
std::map<std::string, std::string>
readTree(const fs::path& root)
{
  std::map<std::string, std::string> files;
  for (const auto& entry : fs::recursive_directory_iterator(root)) {
    if (!entry.is_regular_file())
      continue;
    std::ifstream in(entry.path(), std::ios::binary);
    files[fs::relative(entry.path(), root).string()] =
        std::string(std::istreambuf_iterator<char>(in), {});
  }
  return files;
}

bool
sameBytes(const dynvo::SynthFrame& a, const dynvo::SynthFrame& b)
{
  return a.color.data == b.color.data && a.labels == b.labels &&
         a.depth.data.size() == b.depth.data.size() &&
         std::memcmp(a.depth.data.data(), b.depth.data.data(),
                     a.depth.data.size() * sizeof(float)) == 0;
}

/// Distance (metres) of a world point from the surface of an object's box.
double
distanceToBoxSurface(const dynvo::ObjectState& object, const Eigen::Vector3d& p_world)
{
  const Eigen::Vector3d p = object.T_world_object.inverse() * p_world;
  const Eigen::Vector3d outside = (p.cwiseAbs() - object.half_extents);
  if ((outside.array() <= 0.0).all())
    return -outside.maxCoeff();
  return outside.cwiseMax(0.0).norm();
}

Eigen::Vector3d
worldPoint(const dynvo::SynthFrame& frame,
           const dynvo::CameraIntrinsics& K,
           int u,
           int v)
{
  const float z = frame.depth.data[static_cast<std::size_t>(v) * frame.depth.width + u];
  return frame.T_world_camera * K.backproject(u, v, z).cast<double>();
}

double
rotationDeg(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b)
{
  return Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle() * 180.0 / M_PI;
}

} // namespace

TEST(SceneSynthesizer, SameSeedGivesSameBytesInAnyOrder)
{
  const dynvo::SynthOptions options = smallOptions("static_two");
  const dynvo::SceneSynthesizer first(options), second(options);
  const dynvo::SynthFrame later = first.render(7);
  EXPECT_TRUE(sameBytes(first.render(3), second.render(3)));
  EXPECT_TRUE(sameBytes(later, second.render(7)));
}

TEST(SceneSynthesizer, WrittenBytesDoNotDependOnThreads)
{
  dynvo::SynthOptions options = smallOptions("moving_crossing");
  options.frames = 4;
  const dynvo::test::TempDir dir;
  const dynvo::SceneSynthesizer synth(options);
  synth.writeSequence(dir.file("one"), 1);
  synth.writeSequence(dir.file("two"), 2);
  const auto one = readTree(dir.path() / "one");
  // 3 PNGs per frame and 4 index files.
  EXPECT_EQ(one.size(), 3U * options.frames + 4U);
  EXPECT_TRUE(one == readTree(dir.path() / "two"));
}

TEST(SceneSynthesizer, SeedChangesNoiseAndTexture)
{
  dynvo::SynthOptions options = smallOptions("static_one");
  const dynvo::SynthFrame a = dynvo::SceneSynthesizer(options).render(2);
  options.seed = 1;
  const dynvo::SynthFrame b = dynvo::SceneSynthesizer(options).render(2);
  std::size_t depth_differs = 0, colour_differs = 0;
  for (std::size_t i = 0; i < a.depth.data.size(); ++i) {
    const float da = a.depth.data[i], db = b.depth.data[i];
    depth_differs += !(da == db || (std::isnan(da) && std::isnan(db)));
    colour_differs += a.color.data[3 * i] != b.color.data[3 * i];
  }
  // Noise sigma (>= 2 mm at the nearest surfaces) exceeds half an inverse-depth step
  // almost everywhere, so independent noise changes most measured depths.
  EXPECT_GT(depth_differs, a.depth.data.size() / 3);
  EXPECT_GT(colour_differs, a.depth.data.size() / 2);
  EXPECT_EQ(a.labels, b.labels); // the geometry does not depend on the seed
}

TEST(SceneSynthesizer, StaticPixelsAgreeAcrossFramesWithGroundTruth)
{
  dynvo::SynthOptions options = smallOptions("moving_crossing");
  options.noise = false;
  const dynvo::SceneSynthesizer synth(options);
  const dynvo::CameraIntrinsics K = synth.intrinsics();
  const dynvo::SynthFrame f0 = synth.render(20), f1 = synth.render(21);
  const Eigen::Isometry3d T_1_0 = f1.T_world_camera.inverse() * f0.T_world_camera;
  const int w = options.width, h = options.height;
  const auto at = [w](const std::vector<float>& d, int u, int v) {
    return d[v * w + u];
  };
  int checked = 0, depth_ok = 0;
  double colour_error = 0.0;
  for (int v = 0; v < h; v += 2) {
    for (int u = 0; u < w; u += 2) {
      if (f0.labels[v * w + u] != 0)
        continue;
      const Eigen::Vector3f p1 =
          (T_1_0 * K.backproject(u, v, at(f0.depth.data, u, v)).cast<double>())
              .cast<float>();
      const Eigen::Vector2f uv = K.project(p1);
      const int u0 = static_cast<int>(std::floor(uv.x())),
                v0 = static_cast<int>(std::floor(uv.y()));
      if (u0 < 0 || v0 < 0 || u0 + 1 >= w || v0 + 1 >= h)
        continue;
      const float a = uv.x() - u0, b = uv.y() - v0;
      float inv[4];
      bool moving = false;
      for (int c = 0; c < 4; ++c) {
        inv[c] = 1.0f / at(f1.depth.data, u0 + c % 2, v0 + c / 2);
        moving |= f1.labels[(v0 + c / 2) * w + u0 + c % 2] != 0;
      }
      // Inverse depth is affine in (u, v) on a plane: skip 2x2 cells across a crease or
      // an occlusion boundary, where it is not.
      if (moving || std::abs(inv[0] + inv[3] - inv[1] - inv[2]) > 1e-4f * inv[0])
        continue;
      ++checked;
      const float interpolated = (1 - b) * ((1 - a) * inv[0] + a * inv[1]) +
                                 b * ((1 - a) * inv[2] + a * inv[3]);
      // Exact ray depths of planar surfaces: bilinear inverse depth is exact on a
      // plane, so only float rounding (~1e-6 relative, < 0.01 mm at 4 m) remains; 1 mm
      // leaves room for the tiny non-planarity the 2x2 test lets through.
      depth_ok += std::abs(1.0f / interpolated - p1.z()) < 1e-3f;
      for (int channel = 0; channel < 3; ++channel) {
        const auto c = [&](int du, int dv) {
          return static_cast<float>(
              f1.color.data[3 * ((v0 + dv) * w + u0 + du) + channel]);
        };
        const float expected = (1 - b) * ((1 - a) * c(0, 0) + a * c(1, 0)) +
                               b * ((1 - a) * c(0, 1) + a * c(1, 1));
        colour_error += std::abs(expected - f0.color.data[3 * (v * w + u) + channel]);
      }
    }
  }
  ASSERT_GT(checked, 2000);
  // Newly disoccluded or hidden static surfaces (a few pixels per frame) may disagree.
  EXPECT_GT(depth_ok, 0.99 * checked);
  // Lambertian shading is view-independent and the textures are band-limited (finest
  // layer >= 1.5 px), so bilinear resampling stays within a couple of grey levels on
  // average (8-bit rounding 0.25, interpolating the finest noise; measured 0.45).
  EXPECT_LT(colour_error / (3.0 * checked), 2.0);
}

TEST(SceneSynthesizer, LabelsMarkExactlyTheMovingObjects)
{
  dynvo::SynthOptions options = smallOptions("stop_and_go");
  options.noise = false;
  const dynvo::SceneSynthesizer synth(options);
  const dynvo::CameraIntrinsics K = synth.intrinsics();
  const int w = options.width, h = options.height;
  int moving_views = 0, still_views = 0;
  for (int k = 0; k < options.frames; k += 9) {
    const dynvo::SynthFrame frame = synth.render(k);
    for (const dynvo::ObjectState& object : frame.objects) {
      int on_surface = 0, labelled = 0, wrong = 0;
      for (int v = 0; v < h; ++v) {
        for (int u = 0; u < w; ++u) {
          // Exact ray depth puts the back-projected point on the surface to float
          // precision (< 0.1 mm); 1 mm separates it from every other surface.
          const bool on =
              std::abs(distanceToBoxSurface(object, worldPoint(frame, K, u, v))) < 1e-3;
          const bool is_labelled = frame.labels[v * w + u] == object.id;
          on_surface += on;
          labelled += is_labelled;
          wrong += is_labelled != (on && object.moving);
        }
      }
      EXPECT_EQ(wrong, 0) << "frame " << k << " object " << object.id;
      if (on_surface > 20)
        (object.moving ? moving_views : still_views) += 1;
      if (!object.moving) {
        EXPECT_EQ(labelled, 0);
      }
    }
  }
  EXPECT_GT(moving_views, 3);
  EXPECT_GT(still_views, 3);
}

TEST(SceneSynthesizer, DepthModelFollowsKinect)
{
  dynvo::SynthOptions options = smallOptions("moving_occluder", 320, 240);
  dynvo::SynthOptions exact_options = options;
  exact_options.noise = false;
  const dynvo::SceneSynthesizer noisy(options), exact(exact_options);
  const int w = options.width, h = options.height;
  constexpr double BIN = 0.4;
  std::vector<double> sum(12, 0.0), sum2(12, 0.0), count(12, 0.0);
  double smooth = 0, smooth_missing = 0, far_edges = 0, far_edges_missing = 0;
  for (int k : {0, 90, 110}) { // box face at about 1.65 m, 1.0 m and 0.8 m
    const dynvo::SynthFrame measured = noisy.render(k), truth = exact.render(k);
    for (int v = 1; v + 1 < h; ++v) {
      for (int u = 1; u + 1 < w; ++u) {
        const std::size_t i = static_cast<std::size_t>(v) * w + u;
        const float z = truth.depth.data[i], m = measured.depth.data[i];
        if (!std::isnan(m)) {
          ASSERT_GE(m, dynvo::SceneSynthesizer::MIN_DEPTH);
          ASSERT_LE(m, dynvo::SceneSynthesizer::MAX_DEPTH);
        }
        float min_neighbour = z, max_neighbour = z;
        for (const std::size_t n : {i - 1, i + 1, i - w, i + w}) {
          min_neighbour = std::min(min_neighbour, truth.depth.data[n]);
          max_neighbour = std::max(max_neighbour, truth.depth.data[n]);
        }
        if (z - min_neighbour > 0.2f * z) { // far side of a clear depth edge
          far_edges += 1;
          far_edges_missing += std::isnan(m);
        }
        if (max_neighbour - min_neighbour > 0.01f * z || z < 0.6f || z > 4.2f)
          continue;
        smooth += 1;
        smooth_missing += std::isnan(m);
        if (std::isnan(m))
          continue;
        const double r = (m - z) / (z * z);
        const std::size_t bin = static_cast<std::size_t>(z / BIN);
        sum[bin] += r;
        sum2[bin] += r * r;
        count[bin] += 1;
      }
    }
  }
  EXPECT_GT(far_edges, 100);
  EXPECT_EQ(far_edges_missing, far_edges);
  // Only dropouts remove smooth in-range pixels: 1 % (binomial sd < 0.05 % here).
  EXPECT_NEAR(smooth_missing / smooth, dynvo::SceneSynthesizer::DROPOUT_RATE, 0.003);
  // Gaussian noise and the inverse-depth step both scale with z^2, so std / z^2 is
  // constant: sqrt(sigma^2 + step^2 / 12) with sigma = 1.2e-3 z^2 and step 2.87e-3 z^2.
  const double step = dynvo::SceneSynthesizer::INVERSE_DEPTH_STEP;
  const double sigma = dynvo::SceneSynthesizer::NOISE_SIGMA_PER_Z2;
  const double expected = std::sqrt(sigma * sigma + step * step / 12.0);
  double nearest = 100.0, farthest = 0.0;
  for (std::size_t bin = 0; bin < count.size(); ++bin) {
    if (count[bin] < 500)
      continue;
    const double mean = sum[bin] / count[bin];
    const double sd = std::sqrt(sum2[bin] / count[bin] - mean * mean);
    // 10 %: sampling error of >= 500 samples (~3 %) plus the quantiser being only
    // roughly dithered (sigma = 0.42 step); measured within 5 % in every bin.
    EXPECT_NEAR(sd, expected, 0.1 * expected) << "bin at " << bin * BIN << " m";
    nearest = std::min(nearest, bin * BIN);
    farthest = std::max(farthest, bin * BIN);
  }
  EXPECT_GT(farthest, 2.5 * nearest); // the check covers a wide depth range
}

TEST(SceneSynthesizer, ScenariosHaveTheirDefiningProperties)
{
  const auto scenarios = dynvo::SceneSynthesizer::scenarios();
  ASSERT_EQ(scenarios.size(), 6U);
  EXPECT_EQ(scenarios[2].name, dynvo::SynthOptions().scenario);
  for (const dynvo::ScenarioInfo& info : scenarios) {
    const bool static_camera = info.name.rfind("static_", 0) == 0;
    // 32x24 keeps this fast: only poses, motion flags, coverage and range are examined.
    dynvo::SynthOptions options = smallOptions(info.name, 32, 24);
    options.noise = false; // missing depth then means out of range only
    const dynvo::SceneSynthesizer synth(options);
    std::map<int, int> moving_frames, still_frames;
    double max_coverage = 0.0, max_camera_speed = 0.0, max_camera_rate = 0.0;
    double min_measured = 1.0; // smallest fraction of pixels with depth
    dynvo::SynthFrame previous = synth.render(0);
    for (int k = 1; k < 300; ++k) {
      const dynvo::SynthFrame frame = synth.render(k);
      const double camera_step =
          (frame.T_world_camera.translation() - previous.T_world_camera.translation())
              .norm();
      max_camera_speed = std::max(max_camera_speed, camera_step * 30.0);
      max_camera_rate =
          std::max(max_camera_rate,
                   rotationDeg(frame.T_world_camera, previous.T_world_camera) * 30.0);
      if (static_camera) {
        EXPECT_TRUE(frame.T_world_camera.isApprox(previous.T_world_camera, 0.0))
            << info.name;
      }
      for (std::size_t j = 0; j < frame.objects.size(); ++j) {
        const dynvo::ObjectState& now = frame.objects[j];
        const double step = (now.T_world_object.translation() -
                             previous.objects[j].T_world_object.translation())
                                .norm();
        if (now.moving) {
          ++moving_frames[now.id];
          EXPECT_LE(step, 0.05) << info.name << " frame " << k; // <= 5 cm per frame
        }
        else {
          ++still_frames[now.id];
          EXPECT_TRUE(
              now.T_world_object.isApprox(previous.objects[j].T_world_object, 0.0));
        }
      }
      const double labelled =
          std::count_if(frame.labels.begin(), frame.labels.end(), [](auto l) {
            return l != 0;
          });
      max_coverage = std::max(max_coverage, labelled / frame.labels.size());
      const double measured =
          std::count_if(frame.depth.data.begin(), frame.depth.data.end(), [](float z) {
            return std::isfinite(z);
          });
      min_measured = std::min(min_measured, measured / frame.depth.data.size());
      previous = frame;
    }
    // Hand-held motion: at most 0.5 m/s and 10 deg/s.
    EXPECT_LE(max_camera_speed, 0.5) << info.name;
    EXPECT_LE(max_camera_rate, 10.0) << info.name;
    if (static_camera)
      EXPECT_EQ(previous.objects.size(), info.name == "static_one" ? 1U : 2U);
    else
      EXPECT_GT(max_camera_speed, 0.1) << info.name;
    // Every frame keeps depth on part of the static scene, so the camera's motion stays
    // observable: an occluder hiding everything nearer than MIN_DEPTH would leave frames
    // that no depth odometry can measure.
    if (info.name == "moving_occluder") {
      EXPECT_GT(max_coverage, 0.75);
      EXPECT_GT(min_measured, 0.1);
    }
    else {
      EXPECT_GT(min_measured, 0.95) << info.name;
    }
    if (info.name == "moving_static") {
      EXPECT_TRUE(previous.objects.empty());
      EXPECT_EQ(max_coverage, 0.0);
    }
    if (info.name == "stop_and_go") {
      EXPECT_EQ(previous.objects.size(), 2U);
      for (int id : {1, 2}) {
        EXPECT_GT(moving_frames[id], 30) << id;
        EXPECT_GT(still_frames[id], 30) << id;
      }
    }
    else {
      for (const auto& [id, still] : still_frames)
        EXPECT_EQ(still, 0) << info.name << " object " << id;
    }
  }
}

TEST(SceneSynthesizer, RejectsBadOptions)
{
  const auto rejects = [](void (*change)(dynvo::SynthOptions&)) {
    dynvo::SynthOptions options;
    change(options);
    EXPECT_THROW(options.validate(), std::invalid_argument);
    EXPECT_THROW(dynvo::SceneSynthesizer{options}, std::invalid_argument);
  };
  rejects([](dynvo::SynthOptions& o) {
    o.scenario = "moving";
  });
  rejects([](dynvo::SynthOptions& o) {
    o.frames = 0;
  });
  rejects([](dynvo::SynthOptions& o) {
    o.width = 4;
  });
  rejects([](dynvo::SynthOptions& o) {
    o.height = 100000;
  });
  rejects([](dynvo::SynthOptions& o) {
    o.fps = 0.0;
  });
  rejects([](dynvo::SynthOptions& o) {
    o.fps = std::nan("");
  });
  rejects([](dynvo::SynthOptions& o) {
    o.intrinsics.fx = -1.0;
  });
  EXPECT_NO_THROW(dynvo::SynthOptions().validate());

  dynvo::SynthOptions options = smallOptions("static_one");
  options.frames = 3;
  const dynvo::SceneSynthesizer synth(options);
  EXPECT_THROW(synth.render(-1), std::invalid_argument);
  EXPECT_THROW(synth.render(3), std::invalid_argument);
  const dynvo::test::TempDir dir;
  EXPECT_THROW(synth.writeSequence(dir.file("out"), 0), std::invalid_argument);
  EXPECT_FALSE(fs::exists(dir.file("out")));
}

TEST(SceneSynthesizer, RefusesNonEmptyFolderAndTouchesNothing)
{
  dynvo::SynthOptions options = smallOptions("static_one");
  options.frames = 2;
  const dynvo::test::TempDir dir;
  dynvo::test::writeText(dir.file("rgb.txt"), "keep me\n");
  const auto before = readTree(dir.path());
  try {
    dynvo::SceneSynthesizer(options).writeSequence(dir.path().string(), 2);
    FAIL() << "expected pcl::IOException";
  }
  catch (const pcl::IOException& e) {
    EXPECT_NE(std::string(e.what()).find(dir.path().string()), std::string::npos);
  }
  EXPECT_EQ(readTree(dir.path()), before);
  EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), {}), 1);
}

TEST(SceneSynthesizer, WrittenSequenceReadsBackAsTum)
{
  dynvo::SynthOptions options = smallOptions("static_two");
  options.frames = 3;
  const dynvo::test::TempDir dir;
  const dynvo::SceneSynthesizer synth(options);
  synth.writeSequence(dir.file("seq"), 2);

  dynvo::TumFolderSource::Options read_options;
  read_options.intrinsics = synth.intrinsics();
  const dynvo::TumFolderSource source(dir.file("seq"), read_options);
  ASSERT_EQ(source.size(), 3U);
  const dynvo::Trajectory groundtruth =
      dynvo::readTrajectory(dir.file("seq/groundtruth.txt"));
  ASSERT_EQ(groundtruth.size(), 3U);
  std::ifstream objects(dir.file("seq/objects.txt"));
  std::string line;
  std::vector<std::string> object_lines;
  while (std::getline(objects, line))
    if (!line.empty() && line[0] != '#')
      object_lines.push_back(line);
  ASSERT_EQ(object_lines.size(), 6U);

  for (int k = 0; k < 3; ++k) {
    const dynvo::SynthFrame rendered = synth.render(k);
    const dynvo::Frame frame = source.read(k);
    EXPECT_DOUBLE_EQ(frame.timestamp, rendered.timestamp);
    EXPECT_NEAR(source.entries()[k].depth_stamp - frame.timestamp,
                dynvo::SceneSynthesizer::DEPTH_STAMP_DELAY, 1e-6);
    EXPECT_EQ(frame.color.data, rendered.color.data);
    for (std::size_t i = 0; i < rendered.depth.data.size(); ++i) {
      const float z = rendered.depth.data[i];
      if (std::isnan(z))
        EXPECT_TRUE(std::isnan(frame.depth.data[i]));
      else // half a PNG step (0.1 mm) plus float rounding
        EXPECT_NEAR(frame.depth.data[i], z, 0.5 / 5000.0 + 1e-6);
    }
    // %.9f in the files: 1e-8 m and 1e-8 in each quaternion component.
    EXPECT_TRUE(groundtruth[k].T_world_camera.isApprox(rendered.T_world_camera, 1e-7));
    for (std::size_t j = 0; j < rendered.objects.size(); ++j) {
      std::istringstream fields(object_lines[2 * k + j]);
      double stamp, t[3], q[4];
      int id, moving;
      fields >> stamp >> id >> t[0] >> t[1] >> t[2] >> q[0] >> q[1] >> q[2] >> q[3] >>
          moving;
      ASSERT_TRUE(fields) << object_lines[2 * k + j];
      const dynvo::ObjectState& object = rendered.objects[j];
      EXPECT_EQ(id, object.id);
      EXPECT_EQ(moving == 1, object.moving);
      EXPECT_NEAR(
          (Eigen::Vector3d(t[0], t[1], t[2]) - object.T_world_object.translation())
              .norm(),
          0.0, 1e-7);
      EXPECT_NEAR(
          std::abs(Eigen::Quaterniond(q[3], q[0], q[1], q[2])
                       .dot(Eigen::Quaterniond(object.T_world_object.linear()))),
          1.0, 1e-7);
    }
  }
}
