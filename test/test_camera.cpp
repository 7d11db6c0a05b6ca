// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/common/camera.h>

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace {

TEST(CameraIntrinsics, PresetsCarryTheDatasetCalibrations)
{
  const auto fr1 = dynvo::CameraIntrinsics::fromPreset("fr1");
  EXPECT_DOUBLE_EQ(fr1.fx, 517.3);
  EXPECT_DOUBLE_EQ(fr1.cy, 255.3);
  const auto tum = dynvo::CameraIntrinsics::fromPreset("default");
  EXPECT_DOUBLE_EQ(tum.fx, 525.0);
  EXPECT_DOUBLE_EQ(tum.cx, 319.5);
  // Every listed name resolves, and a default-constructed value is the "default" preset.
  for (const auto& name : dynvo::CameraIntrinsics::presetNames())
    EXPECT_NO_THROW(dynvo::CameraIntrinsics::fromPreset(name)) << name;
  EXPECT_DOUBLE_EQ(dynvo::CameraIntrinsics{}.fy, tum.fy);
}

TEST(CameraIntrinsics, UnknownPresetNamesTheKnownOnes)
{
  try {
    dynvo::CameraIntrinsics::fromPreset("fr9");
    FAIL() << "expected std::invalid_argument";
  }
  catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("fr9"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("fr3"), std::string::npos);
  }
}

TEST(CameraIntrinsics, BackprojectThenProjectIsIdentity)
{
  const auto camera = dynvo::CameraIntrinsics::fromPreset("fr3");
  for (float z : {0.5f, 1.7f, 4.0f}) {
    const Eigen::Vector3f p = camera.backproject(100.25f, 400.5f, z);
    EXPECT_FLOAT_EQ(p.z(), z);
    const Eigen::Vector2f uv = camera.project(p);
    // float round trip: 1e-3 px is far below any tracking accuracy we rely on.
    EXPECT_NEAR(uv.x(), 100.25f, 1e-3f);
    EXPECT_NEAR(uv.y(), 400.5f, 1e-3f);
  }
  // The principal point back-projects onto the optical axis.
  const Eigen::Vector3f axis = camera.backproject(320.1f, 247.6f, 2.0f);
  EXPECT_NEAR(axis.x(), 0.0f, 1e-5f);
  EXPECT_NEAR(axis.y(), 0.0f, 1e-5f);
}

TEST(CameraIntrinsics, ValidateRejectsNonPositiveOrNonFinite)
{
  dynvo::CameraIntrinsics camera;
  camera.fx = 0.0;
  EXPECT_THROW(camera.validate(), std::invalid_argument);
  camera = {};
  camera.cy = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(camera.validate(), std::invalid_argument);
  EXPECT_NO_THROW(dynvo::CameraIntrinsics{}.validate());
}

} // namespace
