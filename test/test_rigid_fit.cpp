// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/common/rigid_fit.h>
#include <dynvo/common/sensor_noise_model.h>

#include <gtest/gtest.h>

#include "support/pose_compare.h"

#include <Eigen/Geometry>

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

namespace {

Eigen::Vector3d
apply(const Eigen::Matrix4d& T, const Eigen::Vector3d& p)
{
  return T.topLeftCorner<3, 3>() * p + T.topRightCorner<3, 1>();
}

/// Rotation angle (rad) and translation distance (m) between two rigid transformations.
void
poseDifference(const Eigen::Matrix4d& A,
               const Eigen::Matrix4d& B,
               double& angle,
               double& dist)
{
  const Eigen::Matrix3d dR =
      A.topLeftCorner<3, 3>().transpose() * B.topLeftCorner<3, 3>();
  // atan2 of the skew and symmetric parts: acos((trace - 1) / 2) cannot resolve angles below
  // sqrt(2 * 1e-16) = 1.5e-8 rad in double precision.
  const Eigen::Vector3d skew(dR(2, 1) - dR(1, 2), dR(0, 2) - dR(2, 0),
                             dR(1, 0) - dR(0, 1));
  angle = std::atan2(skew.norm() / 2.0, (dR.trace() - 1.0) / 2.0);
  dist = (A.topRightCorner<3, 1>() - B.topRightCorner<3, 1>()).norm();
}

// Exact data are recovered to double round-off: 1e-9 rad / 1e-9 m is six orders of magnitude
// above the ~1e-15 relative error of the SVD and far below any physical tolerance.
constexpr double EXACT = 1e-9;

TEST(RigidFitAccumulator, RecoversRandomMotionsFromExactPairs)
{
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> coord(-2.0, 2.0), weight(0.1, 1.0),
      angle(-1.5, 1.5);
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Matrix4d T = dynvo::test::makeMotion(
        Eigen::Vector3d(coord(rng), coord(rng), coord(rng)), angle(rng),
        Eigen::Vector3d(coord(rng), coord(rng), coord(rng)));
    dynvo::RigidFitAccumulator fit;
    for (int i = 0; i < 30; ++i) {
      const Eigen::Vector3d s(coord(rng), coord(rng), coord(rng) + 3.0);
      fit.add(s, apply(T, s), weight(rng));
    }
    Eigen::Matrix4d estimate;
    ASSERT_EQ(fit.solve(estimate), dynvo::RigidFitStatus::ok);
    double dangle = 0.0, dist = 0.0;
    poseDifference(T, estimate, dangle, dist);
    EXPECT_LT(dangle, EXACT) << "trial " << trial;
    EXPECT_LT(dist, EXACT) << "trial " << trial;
    EXPECT_EQ(fit.size(), 30u);
  }
}

TEST(RigidFitAccumulator, WeightsDecideBetweenTwoMotions)
{
  // Two interleaved rigid motions: the fit follows the heavily weighted one, and pairs of
  // weight 0 are ignored exactly.
  const Eigen::Matrix4d A =
      dynvo::test::makeMotion(Eigen::Vector3d::UnitY(), 0.1, {0.05, 0.0, 0.0});
  const Eigen::Matrix4d B =
      dynvo::test::makeMotion(Eigen::Vector3d::UnitX(), -0.3, {0.0, 0.2, 0.1});
  dynvo::RigidFitAccumulator fit;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> coord(-1.0, 1.0);
  for (int i = 0; i < 40; ++i) {
    const Eigen::Vector3d s(coord(rng), coord(rng), coord(rng) + 2.0);
    fit.add(s, apply(A, s), 1.0);
    fit.add(s, apply(B, s), 0.0);
  }
  EXPECT_EQ(fit.size(), 40u);
  Eigen::Matrix4d estimate;
  ASSERT_EQ(fit.solve(estimate), dynvo::RigidFitStatus::ok);
  double dangle = 0.0, dist = 0.0;
  poseDifference(A, estimate, dangle, dist);
  EXPECT_LT(dangle, EXACT);
  EXPECT_LT(dist, EXACT);
}

TEST(RigidFitAccumulator, PlanarPointsGiveAProperRotation)
{
  // A plane (z = 2) rotated by 180 degrees about its normal: without the reflection guard the
  // SVD of a rank-2 cross-covariance can return a mirror (det = -1).
  const Eigen::Matrix4d T =
      dynvo::test::makeMotion(Eigen::Vector3d::UnitZ(), 3.0, {0.1, -0.2, 0.3});
  dynvo::RigidFitAccumulator fit;
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 5; ++j) {
      const Eigen::Vector3d s(0.1 * i, 0.1 * j, 2.0);
      fit.add(s, apply(T, s));
    }
  Eigen::Matrix4d estimate;
  ASSERT_EQ(fit.solve(estimate), dynvo::RigidFitStatus::ok);
  const double det = estimate.topLeftCorner<3, 3>().determinant();
  EXPECT_NEAR(det, 1.0, EXACT);
  double dangle = 0.0, dist = 0.0;
  poseDifference(T, estimate, dangle, dist);
  EXPECT_LT(dangle, EXACT);
  EXPECT_LT(dist, EXACT);
}

TEST(RigidFitAccumulator, PointsFarFromTheOriginKeepTheirPrecision)
{
  // Millimetre-scale structure 10 km from the origin: naive one-pass moments would cancel
  // (1e4^2 * 1e-16 = 1e-8 m^2 of round-off against 1e-6 m^2 of spread); the first-pair
  // origin keeps the error at round-off of the offsets (~1e-12 m), so 1e-7 rad / 1e-9 m hold.
  const Eigen::Vector3d far(1e4, -1e4, 1e4);
  const Eigen::Matrix4d T =
      dynvo::test::makeMotion(Eigen::Vector3d(1, 2, 3), 0.2, {0.001, 0.002, 0.0});
  const Eigen::Matrix4d T_centred =
      dynvo::test::makeMotion(Eigen::Vector3d(1, 2, 3), 0.2, Eigen::Vector3d::Zero());
  dynvo::RigidFitAccumulator fit;
  const double mm = 1e-3;
  const Eigen::Vector3d offsets[] = {
      {0, 0, 0}, {mm, 0, 0}, {0, mm, 0}, {0, 0, mm}, {mm, mm, mm}};
  for (const auto& o : offsets)
    fit.add(far + o, far + apply(T_centred, o) + T.topRightCorner<3, 1>());
  Eigen::Matrix4d estimate;
  ASSERT_EQ(fit.solve(estimate), dynvo::RigidFitStatus::ok);
  double dangle = 0.0, dist = 0.0;
  poseDifference(T, estimate, dangle, dist);
  EXPECT_LT(dangle, 1e-7);
  for (const auto& o : offsets)
    EXPECT_LT(dynvo::squaredTransferError(estimate, far + o,
                                          far + apply(T_centred, o) +
                                              T.topRightCorner<3, 1>()),
              1e-18);
}

TEST(RigidFitAccumulator, ReportsTooFewAndDegenerateInputs)
{
  Eigen::Matrix4d estimate = 2.0 * Eigen::Matrix4d::Identity();
  const Eigen::Matrix4d untouched = estimate;
  dynvo::RigidFitAccumulator fit;
  EXPECT_EQ(fit.solve(estimate), dynvo::RigidFitStatus::too_few_points);
  fit.add({0, 0, 1}, {0, 0, 1});
  fit.add({1, 0, 1}, {1, 0, 1});
  fit.add({5, 5, 5}, {0, 0, 0}, 0.0); // zero weight: not counted
  EXPECT_EQ(fit.solve(estimate), dynvo::RigidFitStatus::too_few_points);
  fit.add({2, 0, 1}, {2, 0, 1}); // collinear with the first two
  EXPECT_EQ(fit.solve(estimate), dynvo::RigidFitStatus::degenerate);
  EXPECT_EQ(estimate, untouched);

  fit.clear();
  for (int i = 0; i < 4; ++i)
    fit.add({1, 2, 3}, {1, 2, 3}); // one point repeated: no spread at all
  EXPECT_EQ(fit.solve(estimate), dynvo::RigidFitStatus::degenerate);

  fit.clear();
  EXPECT_EQ(fit.size(), 0u);
  fit.add({0, 0, 1}, {0, 0, 1});
  fit.add({1, 0, 1}, {1, 0, 1});
  fit.add({0, 1, 1}, {0, 1, 1}); // three non-collinear points suffice
  EXPECT_EQ(fit.solve(estimate), dynvo::RigidFitStatus::ok);
  EXPECT_TRUE(estimate.isIdentity(EXACT));
}

TEST(RigidFitAccumulator, RejectsNonFiniteInputAndNegativeWeights)
{
  dynvo::RigidFitAccumulator fit;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(fit.add({nan, 0, 1}, {0, 0, 1}), std::invalid_argument);
  EXPECT_THROW(fit.add({0, 0, 1}, {0, nan, 1}), std::invalid_argument);
  EXPECT_THROW(fit.add({0, 0, 1}, {0, 0, 1}, -1.0), std::invalid_argument);
  EXPECT_THROW(fit.add({0, 0, 1}, {0, 0, 1}, nan), std::invalid_argument);
  EXPECT_EQ(fit.size(), 0u);
}

TEST(RigidFitAccumulator, SquaredTransferErrorIsTheResidualOfEquationOne)
{
  const Eigen::Matrix4d T =
      dynvo::test::makeMotion(Eigen::Vector3d::UnitZ(), M_PI / 2, {1.0, 0.0, 0.0});
  // R (1,0,0) + t = (0,1,0) + (1,0,0) = (1,1,0); the target is 3 cm away along z.
  EXPECT_NEAR(dynvo::squaredTransferError(T, {1, 0, 0}, {1, 1, 0.03}), 9e-4, 1e-15);
}

} // namespace

namespace {

/// One draw of structured-light noise at p: sigma_z(z) along the viewing ray, z sigma_px / f
/// across it (SensorNoiseModel's model, the one refineRigidFit is given).
Eigen::Vector3d
sensorNoise(const dynvo::SensorNoiseModel& model,
            const Eigen::Vector3d& p,
            double focal,
            std::mt19937& rng)
{
  std::normal_distribution<double> n(0.0, 1.0);
  const Eigen::Vector3d ray = p.normalized();
  const Eigen::Vector3d side = ray.unitOrthogonal(), up = ray.cross(side);
  const double axial = model.axialSigma(static_cast<float>(p.z()));
  const double lateral =
      model.lateralSigma(static_cast<float>(p.z()), static_cast<float>(focal));
  return axial * n(rng) * ray + lateral * (n(rng) * side + n(rng) * up);
}

/// Pairs of a static scene 0.6-4.5 m in front of a camera that moved by T (target = T source),
/// with the model's information matrix and, when rng is given, noise on both points.
std::vector<dynvo::InformationPair>
scenePairs(const Eigen::Matrix4d& T,
           const dynvo::SensorNoiseModel& model,
           double focal,
           std::mt19937& rng,
           bool noisy)
{
  std::uniform_real_distribution<double> depth(0.6, 4.5), image(-0.5, 0.5);
  std::vector<dynvo::InformationPair> pairs;
  for (int i = 0; i < 300; ++i) {
    const double z = depth(rng);
    const Eigen::Vector3d s(image(rng) * z * 1.2, image(rng) * z * 0.9, z);
    dynvo::InformationPair pair{s, apply(T, s), Eigen::Matrix3d::Zero(), 1.0};
    if (noisy) {
      pair.source += sensorNoise(model, pair.source, focal, rng);
      pair.target += sensorNoise(model, pair.target, focal, rng);
    }
    pair.information =
        model
            .transferInformation(pair.target.cast<float>(), pair.source.cast<float>(),
                                 static_cast<float>(focal))
            .cast<double>();
    pairs.push_back(pair);
  }
  return pairs;
}

Eigen::Matrix4d
metricFit(const std::vector<dynvo::InformationPair>& pairs)
{
  dynvo::RigidFitAccumulator fit;
  for (const auto& pair : pairs)
    fit.add(pair.source, pair.target, pair.weight);
  Eigen::Matrix4d T;
  EXPECT_EQ(fit.solve(T), dynvo::RigidFitStatus::ok);
  return T;
}

constexpr double FOCAL = 525.0; // px, Kinect v1

} // namespace

TEST(RefineRigidFit, ConvergesToTheExactMotionFromAFitOffByCentimetres)
{
  std::mt19937 rng(3);
  const dynvo::SensorNoiseModel model;
  const Eigen::Matrix4d T = dynvo::test::makeMotion(Eigen::Vector3d(0.3, 1.0, 0.2),
                                                    0.03, {0.02, -0.01, 0.015});
  const auto pairs = scenePairs(T, model, FOCAL, rng, false);
  // A start 2 cm and 0.02 rad away: more than a frame's error of the metric fit on real data.
  Eigen::Matrix4d estimate =
      dynvo::test::makeMotion(Eigen::Vector3d::UnitX(), 0.02, {0.02, 0.0, 0.0}) * T;
  ASSERT_EQ(dynvo::refineRigidFit(pairs, 6, 3.0, estimate), dynvo::RigidFitStatus::ok);
  double angle = 0.0, dist = 0.0;
  poseDifference(T, estimate, angle, dist);
  // Gauss-Newton converges about quadratically on exact data: 6 steps reach round-off.
  EXPECT_LT(angle, EXACT);
  EXPECT_LT(dist, EXACT);
}

TEST(RefineRigidFit, FitsSensorNoiseBetterThanTheMetricFit)
{
  std::mt19937 rng(11);
  const dynvo::SensorNoiseModel model;
  double metric_sq = 0.0, refined_sq = 0.0, metric_angle_sq = 0.0,
         refined_angle_sq = 0.0;
  const int trials = 60;
  for (int trial = 0; trial < trials; ++trial) {
    const Eigen::Matrix4d T = dynvo::test::makeMotion(Eigen::Vector3d(0.2, 1.0, -0.3),
                                                      0.02, {0.01, 0.005, -0.02});
    const auto pairs = scenePairs(T, model, FOCAL, rng, true);
    Eigen::Matrix4d estimate = metricFit(pairs);
    double angle = 0.0, dist = 0.0;
    poseDifference(T, estimate, angle, dist);
    metric_sq += dist * dist;
    metric_angle_sq += angle * angle;
    ASSERT_EQ(dynvo::refineRigidFit(pairs, 4, 3.0, estimate),
              dynvo::RigidFitStatus::ok);
    poseDifference(T, estimate, angle, dist);
    refined_sq += dist * dist;
    refined_angle_sq += angle * angle;
  }
  const double metric = std::sqrt(metric_sq / trials),
               refined = std::sqrt(refined_sq / trials);
  const double metric_angle = std::sqrt(metric_angle_sq / trials),
               refined_angle = std::sqrt(refined_angle_sq / trials);
  RecordProperty("metric_translation_rms_m", std::to_string(metric));
  RecordProperty("refined_translation_rms_m", std::to_string(refined));
  RecordProperty("metric_rotation_rms_rad", std::to_string(metric_angle));
  RecordProperty("refined_rotation_rms_rad", std::to_string(refined_angle));
  // Axial noise is 1.6-6.4x the lateral one over 0.6-4.5 m, and the far points carry most of the
  // metric fit's error: the maximum-likelihood fit must be clearly better in both
  // translation and rotation (measured: 0.20x and 0.44x; the bounds leave room for the
  // draw, whose RMS over 60 trials varies by about 10%).
  EXPECT_LT(refined, 0.4 * metric);
  EXPECT_LT(refined_angle, 0.6 * metric_angle);
}

TEST(RefineRigidFit, ReportsTooFewAndDegeneratePairsAndLeavesTheFitAlone)
{
  std::mt19937 rng(5);
  const dynvo::SensorNoiseModel model;
  const Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  auto pairs = scenePairs(T, model, FOCAL, rng, false);
  Eigen::Matrix4d estimate =
      dynvo::test::makeMotion(Eigen::Vector3d::UnitY(), 0.1, {0.1, 0, 0});
  const Eigen::Matrix4d start = estimate;
  // 0 steps: the start is the result.
  ASSERT_EQ(dynvo::refineRigidFit(pairs, 0, 3.0, estimate), dynvo::RigidFitStatus::ok);
  EXPECT_EQ(estimate, start);
  pairs.resize(2);
  EXPECT_EQ(dynvo::refineRigidFit(pairs, 4, 3.0, estimate),
            dynvo::RigidFitStatus::too_few_points);
  // Points on one line: the rotation about it is not observable.
  pairs.clear();
  for (int i = 0; i < 10; ++i) {
    const Eigen::Vector3d p(0.1 * i, 0.0, 2.0);
    pairs.push_back({p, p, Eigen::Matrix3d::Identity(), 1.0});
  }
  EXPECT_EQ(dynvo::refineRigidFit(pairs, 4, 3.0, estimate),
            dynvo::RigidFitStatus::degenerate);
  EXPECT_EQ(estimate, start);
}
