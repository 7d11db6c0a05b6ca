// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/common/camera.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace dynvo {

namespace {

struct Preset {
  const char* name;
  CameraIntrinsics intrinsics;
};

// TUM values: https://cvg.cit.tum.de/data/datasets/rgbd-dataset/file_formats (ROS default
// for "default"; fr3's images are already undistorted); ICSL-DE values from the dataset page
// (docs/algorithm.md §8).
const Preset PRESETS[] = {
    {"default", {525.0, 525.0, 319.5, 239.5}},
    {"fr1", {517.3, 516.5, 318.6, 255.3, {0.2624, -0.9531, -0.0054, 0.0026, 1.1633}}},
    {"fr2", {520.9, 521.0, 325.1, 249.7, {0.2312, -0.7849, -0.0033, -0.0001, 0.9172}}},
    {"fr3", {535.4, 539.2, 320.1, 247.6}},
    {"icsl", {537.5999, 539.0333, 316.1487, 245.5187}},
};

} // namespace

CameraIntrinsics
CameraIntrinsics::fromPreset(const std::string& name)
{
  for (const auto& preset : PRESETS)
    if (name == preset.name)
      return preset.intrinsics;
  std::string known;
  for (const auto& preset : PRESETS)
    known += std::string(known.empty() ? "" : ", ") + preset.name;
  throw std::invalid_argument("[dynvo::CameraIntrinsics::fromPreset] unknown camera '" +
                              name + "' (known: " + known + ")");
}

std::vector<std::string>
CameraIntrinsics::presetNames()
{
  std::vector<std::string> names;
  for (const auto& preset : PRESETS)
    names.emplace_back(preset.name);
  return names;
}

void
CameraIntrinsics::validate() const
{
  if (!(std::isfinite(fx) && std::isfinite(fy) && fx > 0.0 && fy > 0.0 &&
        std::isfinite(cx) && std::isfinite(cy)))
    throw std::invalid_argument(
        "[dynvo::CameraIntrinsics::validate] focal lengths must be positive and all "
        "values finite, got fx=" +
        std::to_string(fx) + " fy=" + std::to_string(fy) + " cx=" + std::to_string(cx) +
        " cy=" + std::to_string(cy));
  for (const double k : distortion)
    if (!std::isfinite(k))
      throw std::invalid_argument(
          "[dynvo::CameraIntrinsics::validate] distortion coefficients must be finite");
}

bool
CameraIntrinsics::distorted() const
{
  return std::any_of(distortion.begin(), distortion.end(), [](double k) {
    return k != 0.0;
  });
}

} // namespace dynvo
