// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/registration/static_mask_registration.h>
#include <dynvo/common/image.h>

#include "registration_scene.h"

#include <pcl/point_types.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

using dynvo::RegistrationBackend;
using dynvo::StaticMaskRegistrationStatus;
using namespace dynvo::test;
using Point = pcl::PointXYZRGB;

/// The clutter scene of the ICP tests with a large box in front moving across it: the box
/// covers about a third of the image and moves by 10 degrees and 8 cm, so a method fitted on
/// every pixel is pulled away from the camera motion.
BoxScene
largeObjectScene()
{
  BoxScene scene = BoxScene::makeClutter();
  scene.boxes.pop_back(); // the small moving box
  scene.add(makePose({0.0, 1.0, 0.0}, radians(15.0), {-0.05, 0.05, 1.25}),
            {0.35, 0.3, 0.15}, true);
  scene.object_motion = makePose({0.2, 1.0, 0.3}, radians(1.5), {0.02, -0.005, 0.01});
  return scene;
}

/// The cells none of whose pixels sees a moving box in a view (the static mask of a
/// segmentation that labels the object exactly).
template <typename PointT>
dynvo::FlowGrid
staticCellsOf(const RenderedView<PointT>& view,
              const BoxScene& scene,
              const dynvo::FlowGrid& grid)
{
  dynvo::FlowGrid cells = grid;
  for (std::size_t i = 0; i < cells.size(); ++i) {
    bool moving = false;
    grid.forEachPixel(i, [&](std::size_t index) {
      const int box = view.ids[index];
      moving =
          moving || (box >= 0 && scene.boxes[static_cast<std::size_t>(box)].moving);
    });
    cells.labels[i] = moving ? dynvo::LABEL_NONE : dynvo::LABEL_STATIC;
  }
  return cells;
}

/// Every cell static (the ablation without segmentation).
dynvo::FlowGrid
allCells(const dynvo::FlowGrid& grid)
{
  dynvo::FlowGrid cells = grid;
  std::fill(cells.labels.begin(), cells.labels.end(), dynvo::LABEL_STATIC);
  return cells;
}

/// The moving box's share of the pixels of a view.
template <typename PointT>
double
movingShare(const RenderedView<PointT>& view, const BoxScene& scene)
{
  std::size_t count = 0;
  for (const int box : view.ids)
    count += box >= 0 && scene.boxes[static_cast<std::size_t>(box)].moving;
  return static_cast<double>(count) / static_cast<double>(view.ids.size());
}

class StaticMaskRegistrationTest : public ::testing::Test {
protected:
  StaticMaskRegistrationTest()
      : scene_(largeObjectScene())
      , pair_(scene_)
  {
    backend_.setCameraIntrinsics(scene_.intrinsics);
    backend_.setInputSource(pair_.current.cloud);
    backend_.setInputTarget(pair_.previous.cloud);
  }

  /// T_prev_curr of the scene.
  Eigen::Matrix4d truth() const { return scene_.T_curr_prev.inverse().matrix(); }

  /// The flow estimate as a backend would get it: off by 0.5 degrees and 1 cm.
  Eigen::Matrix4f guess() const
  {
    return (makePose({1.0, -0.5, 0.3}, radians(0.5), {0.01, 0.0, 0.0}) *
            scene_.T_curr_prev)
        .inverse()
        .matrix()
        .cast<float>();
  }

  BoxScene scene_;
  FramePair<Point> pair_;
  dynvo::StaticMaskRegistration<Point> backend_;
};

class BackendTest : public StaticMaskRegistrationTest,
                    public ::testing::WithParamInterface<RegistrationBackend> {};

TEST_P(BackendTest, TheStaticMaskKeepsTheLargeMovingObjectOut)
{
  ASSERT_GT(movingShare(pair_.current, scene_), 0.2);
  ASSERT_GT(movingShare(pair_.previous, scene_), 0.2);
  backend_.setBackend(GetParam());
  backend_.setIcpStride(2);
  Eigen::Matrix4f masked, unmasked;
  backend_.setSourceStaticCells(staticCellsOf(pair_.current, scene_, pair_.grid));
  backend_.setTargetStaticCells(staticCellsOf(pair_.previous, scene_, pair_.grid));
  ASSERT_TRUE(backend_.align(guess(), masked));
  EXPECT_EQ(backend_.getStatus(), StaticMaskRegistrationStatus::converged);
  backend_.setSourceStaticCells(allCells(pair_.grid));
  backend_.setTargetStaticCells(allCells(pair_.grid));
  backend_.align(guess(), unmasked);
  const double masked_t = translationError(masked, truth());
  const double masked_r = rotationError(masked, truth());
  const double unmasked_t = translationError(unmasked, truth());
  // The box moves by 2 cm and 1.5 degrees, within every backend's outlier limits (5 cm pairs,
  // 7 cm depth difference), so without the mask its third of the image pulls the estimate
  // towards its motion; with the mask the backend sees the static scene only. The mask must
  // at least divide the translation error by 3 (measured 5 to 500).
  EXPECT_GT(unmasked_t, 3.0 * masked_t);
  // The masked accuracy is each method's own on this 160x120 scene (NOTES.md): GICP matches
  // local planes, so the different sampling of the two frames cancels (the flow fit's 1 mm /
  // 0.05 degrees); point-to-point ICP pairs each sample with the nearest one of the other
  // frame, 1.3-2 cm apart at stride 2, and stays biased by a fraction of that spacing (5 mm
  // / 0.45 degrees); cv_rgbd's coarsest pyramid level is 20x15 px and the mask leaves two
  // thirds of the textured pixels, so it stays within 12 mm / 0.35 degrees (3 mm / 0.1
  // degrees on the same scene without a moving object), still better than the 1 cm guess.
  switch (GetParam()) {
  case RegistrationBackend::gicp:
    EXPECT_LT(masked_t, TRANSLATION_TOL);
    EXPECT_LT(masked_r, ROTATION_TOL);
    break;
  case RegistrationBackend::direct:
    // Every textured masked pixel of all three levels, moved with its depth and compared by
    // bilinear interpolation: 0.63 mm / 0.018 degrees measured, a third of the bound; what is
    // left is the rendering's pixel sampling, which interpolation does not undo.
    EXPECT_LT(masked_t, 2e-3);
    EXPECT_LT(masked_r, radians(0.06));
    break;
  case RegistrationBackend::icp:
    EXPECT_LT(masked_t, 5e-3);
    EXPECT_LT(masked_r, radians(0.45));
    break;
  default:
    EXPECT_LT(masked_t, 0.012);
    EXPECT_LT(masked_r, radians(0.35));
  }
}

TEST_P(BackendTest, AFailedBackendLeavesTheGuess)
{
  backend_.setBackend(GetParam());
  dynvo::FlowGrid none = pair_.grid; // every cell LABEL_NONE: an empty mask
  backend_.setSourceStaticCells(none);
  backend_.setTargetStaticCells(allCells(pair_.grid));
  Eigen::Matrix4f result = Eigen::Matrix4f::Zero();
  EXPECT_FALSE(backend_.align(guess(), result));
  EXPECT_EQ(backend_.getStatus(), StaticMaskRegistrationStatus::too_few_points);
  EXPECT_TRUE(result.isApprox(guess()));
}

INSTANTIATE_TEST_SUITE_P(EveryMethod,
                         BackendTest,
                         ::testing::Values(RegistrationBackend::cv_rgbd,
                                           RegistrationBackend::icp,
                                           RegistrationBackend::gicp,
                                           RegistrationBackend::direct));

TEST_F(StaticMaskRegistrationTest, TheFlowBackendReturnsTheGuess)
{
  EXPECT_EQ(backend_.getBackend(), RegistrationBackend::flow);
  Eigen::Matrix4f result;
  EXPECT_TRUE(backend_.align(guess(), result));
  EXPECT_EQ(backend_.getStatus(), StaticMaskRegistrationStatus::flow);
  EXPECT_EQ(result, guess());
}

TEST_F(StaticMaskRegistrationTest, DirectBackendReadsACloudChangedInPlaceWithANewStamp)
{
  // The direct backend keeps each cloud's pyramids by pointer and header stamp (a frame is
  // read once, as frame k, and serves again as frame k-1). A cloud rewritten in place with a
  // new stamp must be read again: with the old pyramids the second alignment would find the
  // identity of the first instead of the camera's motion.
  backend_.setBackend(RegistrationBackend::direct);
  const auto target = pcl::make_shared<pcl::PointCloud<Point>>(*pair_.current.cloud);
  backend_.setInputTarget(target);
  backend_.setSourceStaticCells(staticCellsOf(pair_.current, scene_, pair_.grid));
  backend_.setTargetStaticCells(staticCellsOf(pair_.current, scene_, pair_.grid));
  Eigen::Matrix4f same, moved;
  ASSERT_TRUE(backend_.align(Eigen::Matrix4f::Identity(), same));
  EXPECT_LT(translationError(same, Eigen::Matrix4d::Identity()), TRANSLATION_TOL);
  const std::uint64_t stamp = target->header.stamp;
  *target = *pair_.previous.cloud;
  target->header.stamp = stamp + 1;
  backend_.setTargetStaticCells(staticCellsOf(pair_.previous, scene_, pair_.grid));
  ASSERT_TRUE(backend_.align(guess(), moved));
  // The masked box scene's own accuracy (TheStaticMaskKeepsTheLargeMovingObjectOut).
  EXPECT_LT(translationError(moved, truth()), 2e-3);
  EXPECT_GT(translationError(moved, Eigen::Matrix4d::Identity()),
            0.5 * translationError(Eigen::Matrix4f::Identity(), truth()));
}

TEST_F(StaticMaskRegistrationTest, DirectBackendTakesTheImagesAnEarlierStageRead)
{
  // The pipeline hands the direct backend the grey levels and depths the scene flow already
  // read from frame k. Built from the same values, the pyramids and so the estimate must be
  // exactly those of reading the cloud; images of the wrong size fall back to the cloud; and
  // images that differ from the cloud must be what the backend uses.
  const auto& cloud = pair_.current.cloud;
  std::vector<std::uint8_t> grey(cloud->size());
  std::vector<float> depth(cloud->size());
  for (std::size_t i = 0; i < cloud->size(); ++i) {
    const Point& p = (*cloud)[i];
    grey[i] = dynvo::luma(p.r, p.g, p.b);
    depth[i] = p.z;
  }
  const auto estimate = [&](const std::vector<std::uint8_t>* source_grey) {
    dynvo::StaticMaskRegistration<Point> backend;
    backend.setBackend(RegistrationBackend::direct);
    backend.setCameraIntrinsics(scene_.intrinsics);
    if (source_grey)
      backend.setInputSource(cloud, *source_grey, depth);
    else
      backend.setInputSource(cloud);
    backend.setInputTarget(pair_.previous.cloud);
    backend.setSourceStaticCells(staticCellsOf(pair_.current, scene_, pair_.grid));
    backend.setTargetStaticCells(staticCellsOf(pair_.previous, scene_, pair_.grid));
    Eigen::Matrix4f result = Eigen::Matrix4f::Zero();
    backend.align(guess(), result);
    return result;
  };
  const Eigen::Matrix4f from_cloud = estimate(nullptr);
  EXPECT_LT(translationError(from_cloud, truth()), 2e-3);
  EXPECT_EQ(estimate(&grey), from_cloud);
  const std::vector<std::uint8_t> none;
  EXPECT_EQ(estimate(&none), from_cloud);
  std::vector<std::uint8_t> inverted(grey);
  for (std::uint8_t& level : inverted)
    level = static_cast<std::uint8_t>(255 - level);
  EXPECT_GT(translationError(estimate(&inverted), truth()), 2e-3);
}

TEST_F(StaticMaskRegistrationTest, DirectTargetPrecomputedGivesTheSameEstimate)
{
  // The pipeline builds the target's samples beside other work (precomputeTarget()); align()
  // must then reuse them and return exactly what it returns when it chooses them itself. Called
  // before the target or its cells are set, it does nothing.
  const auto estimate = [&](bool precompute) {
    dynvo::StaticMaskRegistration<Point> backend;
    backend.setBackend(RegistrationBackend::direct);
    backend.setCameraIntrinsics(scene_.intrinsics);
    backend.setInputSource(pair_.current.cloud);
    if (precompute)
      backend.precomputeTarget(); // no target yet
    backend.setInputTarget(pair_.previous.cloud);
    if (precompute)
      backend.precomputeTarget(); // no target cells yet
    backend.setTargetStaticCells(staticCellsOf(pair_.previous, scene_, pair_.grid));
    if (precompute)
      backend.precomputeTarget();
    backend.setSourceStaticCells(staticCellsOf(pair_.current, scene_, pair_.grid));
    Eigen::Matrix4f result = Eigen::Matrix4f::Zero();
    EXPECT_TRUE(backend.align(guess(), result));
    return result;
  };
  const Eigen::Matrix4f chosen_in_align = estimate(false);
  EXPECT_LT(translationError(chosen_in_align, truth()), 2e-3);
  EXPECT_EQ(estimate(true), chosen_in_align);
}

TEST_F(StaticMaskRegistrationTest, DirectEstimateIsIdenticalForOneAndTwoThreads)
{
  // The residuals are computed in stripes, the sums in sample order: the thread count must
  // not change a single bit of the estimate.
  const auto estimate = [&](unsigned threads) {
    dynvo::StaticMaskRegistration<Point> backend;
    backend.setBackend(RegistrationBackend::direct);
    backend.setCameraIntrinsics(scene_.intrinsics);
    backend.setNumberOfThreads(threads);
    backend.setInputSource(pair_.current.cloud);
    backend.setInputTarget(pair_.previous.cloud);
    backend.setSourceStaticCells(staticCellsOf(pair_.current, scene_, pair_.grid));
    backend.setTargetStaticCells(staticCellsOf(pair_.previous, scene_, pair_.grid));
    Eigen::Matrix4f result = Eigen::Matrix4f::Zero();
    EXPECT_TRUE(backend.align(guess(), result));
    return result;
  };
  const Eigen::Matrix4f one = estimate(1);
  EXPECT_LT(translationError(one, truth()), 2e-3);
  EXPECT_EQ(estimate(2), one);
  EXPECT_EQ(estimate(3), one);
  EXPECT_THROW(backend_.setNumberOfThreads(0), std::invalid_argument);
  EXPECT_EQ(backend_.getNumberOfThreads(), 1u);
}

TEST_F(StaticMaskRegistrationTest, BrokenInputIsReportedAndLeavesTheGuess)
{
  backend_.setBackend(RegistrationBackend::cv_rgbd);
  Eigen::Matrix4f result;
  ::testing::internal::CaptureStderr();
  EXPECT_FALSE(backend_.align(guess(), result)); // no static cells set
  EXPECT_NE(::testing::internal::GetCapturedStderr().find(
                "[dynvo::StaticMaskRegistration::align]"),
            std::string::npos);
  EXPECT_EQ(backend_.getStatus(), StaticMaskRegistrationStatus::invalid_input);
  EXPECT_EQ(result, guess());
  backend_.setSourceStaticCells(allCells(pair_.grid));
  backend_.setTargetStaticCells(allCells(pair_.grid));
  backend_.setInputTarget(BoxScene::make(320, 240).render<Point>(false).cloud);
  ::testing::internal::CaptureStderr();
  EXPECT_FALSE(backend_.align(guess(), result)); // sizes differ
  ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(backend_.getStatus(), StaticMaskRegistrationStatus::invalid_input);
  backend_.setInputTarget(nullptr);
  ::testing::internal::CaptureStderr();
  EXPECT_FALSE(backend_.align(guess(), result));
  ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(backend_.getStatus(), StaticMaskRegistrationStatus::invalid_input);
}

TEST(StaticMaskRegistrationParameters, BadValuesThrowAndKeepTheOldValue)
{
  const dynvo::StaticMaskRegistrationParameters defaults;
  EXPECT_NO_THROW(defaults.validate());
  EXPECT_EQ(defaults.backend, RegistrationBackend::flow);
  dynvo::StaticMaskRegistration<Point> backend;
  EXPECT_THROW(backend.setBackend(static_cast<RegistrationBackend>(7)),
               std::invalid_argument);
  EXPECT_THROW(backend.setIcpStride(0), std::invalid_argument);
  EXPECT_EQ(backend.getIcpStride(), defaults.icp_stride);
  dynvo::StaticMaskRegistrationParameters bad;
  bad.icp_max_correspondence_distance = 0.0;
  EXPECT_THROW(backend.setParameters(bad), std::invalid_argument);
  bad = defaults;
  bad.icp_max_iterations = 0;
  EXPECT_THROW(backend.setParameters(bad), std::invalid_argument);
  bad = defaults;
  bad.rgbd_max_depth_difference = 0.0f;
  EXPECT_THROW(backend.setParameters(bad), std::invalid_argument);
  dynvo::CameraIntrinsics bad_camera;
  bad_camera.fx = 0.0;
  EXPECT_THROW(backend.setCameraIntrinsics(bad_camera), std::invalid_argument);
}

template <typename PointT> class StaticMaskRegistrationTyped : public ::testing::Test {
};
using PointTypes = ::testing::Types<pcl::PointXYZRGB, pcl::PointXYZRGBA>;
TYPED_TEST_SUITE(StaticMaskRegistrationTyped, PointTypes);

TYPED_TEST(StaticMaskRegistrationTyped, SameFrameTwiceGivesIdentity)
{
  const BoxScene scene = largeObjectScene();
  const FramePair<TypeParam> pair(scene);
  dynvo::StaticMaskRegistration<TypeParam> backend;
  backend.setCameraIntrinsics(scene.intrinsics);
  backend.setInputSource(pair.current.cloud);
  backend.setInputTarget(pair.current.cloud);
  backend.setSourceStaticCells(allCells(pair.grid));
  backend.setTargetStaticCells(allCells(pair.grid));
  for (const auto method : {RegistrationBackend::cv_rgbd, RegistrationBackend::icp,
                            RegistrationBackend::gicp, RegistrationBackend::direct}) {
    backend.setBackend(method);
    Eigen::Matrix4f result;
    ASSERT_TRUE(backend.align(Eigen::Matrix4f::Identity(), result));
    // Identical frames: every residual vanishes at identity, which the methods keep up to
    // their round-off.
    EXPECT_LT(translationError(result, Eigen::Matrix4d::Identity()), TRANSLATION_TOL);
    EXPECT_LT(rotationError(result, Eigen::Matrix4d::Identity()), ROTATION_TOL);
  }
}

} // namespace
