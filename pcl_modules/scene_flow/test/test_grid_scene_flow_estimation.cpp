// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/scene_flow/grid_scene_flow_estimation.h>
#include <dynvo/common/image.h>

#include "support/pose_compare.h"
#include "support/synthetic_scene.h"

#include <pcl/point_types.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

using dynvo::CameraIntrinsics;
using dynvo::PointFlow;
using dynvo::test::SceneBox;
using FlowCloud = pcl::PointCloud<PointFlow>;

/// The "default" preset scaled from 640x480 to the test image size.
CameraIntrinsics
scaledIntrinsics(std::uint32_t width)
{
  const double s = width / 640.0;
  return {525.0 * s, 525.0 * s, (319.5 + 0.5) * s - 0.5, (239.5 + 0.5) * s - 0.5};
}

Eigen::Isometry3d
pose(double rx_deg, double ry_deg, double rz_deg, double tx, double ty, double tz)
{
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  using dynvo::test::radians;
  T.linear() = (Eigen::AngleAxisd(radians(rz_deg), Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(radians(ry_deg), Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(radians(rx_deg), Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  T.translation() = Eigen::Vector3d(tx, ty, tz);
  return T;
}

/// A static room seen from about 1.2-2 m: a back wall and a slanted board in front of it.
std::vector<SceneBox>
staticRoom()
{
  return {dynvo::test::texturedQuad(pose(0, 0, 0, 0, 0, 2.0), 3.0, 2.5, 1),
          dynvo::test::texturedQuad(pose(10, -25, 0, -0.35, 0.1, 1.4), 0.35, 0.3, 2)};
}

double
median(std::vector<double> values)
{
  const auto mid = values.begin() + values.size() / 2;
  std::nth_element(values.begin(), mid, values.end());
  return *mid;
}

Eigen::Vector3d
prevPoint(const PointFlow& f)
{
  return Eigen::Vector3d(f.prev_x, f.prev_y, f.prev_z);
}

Eigen::Vector3d
currPoint(const PointFlow& f)
{
  return f.getVector3fMap().cast<double>();
}

/// Output invariants of the class doc, checked on every cell.
void
expectCellContract(const FlowCloud& flow)
{
  for (const PointFlow& f : flow) {
    if (f.valid_3d) {
      EXPECT_TRUE(f.valid_2d);
      EXPECT_TRUE(std::isfinite(f.prev_z) && std::isfinite(f.z));
      EXPECT_GT(f.weight, 0.0f);
      EXPECT_LE(f.weight, 1.0f);
    }
    else {
      EXPECT_EQ(f.weight, 0.0f);
      EXPECT_TRUE(std::isnan(f.prev_x) && std::isnan(f.prev_y) && std::isnan(f.prev_z));
    }
    if (!f.valid_2d)
      EXPECT_TRUE(std::isnan(f.prev_u) && std::isnan(f.prev_v));
  }
}

/// The same float, bit for bit (so NaN equals NaN, but 0 differs from -0).
bool
sameBits(float a, float b)
{
  std::uint32_t x = 0, y = 0;
  std::memcpy(&x, &a, sizeof(x));
  std::memcpy(&y, &b, sizeof(y));
  return x == y;
}

/// Field-by-field bitwise equality of two flow grids (struct padding is not compared).
bool
identical(const FlowCloud& a, const FlowCloud& b)
{
  if (a.width != b.width || a.height != b.height || a.size() != b.size())
    return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const PointFlow &p = a[i], &q = b[i];
    for (const auto field :
         {&PointFlow::x, &PointFlow::y, &PointFlow::z, &PointFlow::prev_x,
          &PointFlow::prev_y, &PointFlow::prev_z, &PointFlow::u, &PointFlow::v,
          &PointFlow::prev_u, &PointFlow::prev_v, &PointFlow::weight})
      if (!sameBits(p.*field, q.*field))
        return false;
    if (p.valid_2d != q.valid_2d || p.valid_3d != q.valid_3d)
      return false;
  }
  return true;
}

/// Cells with a valid 3D flow.
std::size_t
validCells(const FlowCloud& flow)
{
  return static_cast<std::size_t>(
      std::count_if(flow.begin(), flow.end(), [](const PointFlow& f) {
        return f.valid_3d != 0;
      }));
}

template <typename PointT> class GridSceneFlowTest : public ::testing::Test {
protected:
  using Cloud = pcl::PointCloud<PointT>;
  static constexpr std::uint32_t WIDTH = 160;
  static constexpr std::uint32_t HEIGHT = 120;

  GridSceneFlowTest() { estimation_.setCameraIntrinsics(intrinsics_); }

  dynvo::test::RenderedView<PointT> view(const std::vector<SceneBox>& quads,
                                         const Eigen::Isometry3d& T_world_camera) const
  {
    return dynvo::test::render<PointT>(quads, T_world_camera, intrinsics_, WIDTH,
                                       HEIGHT);
  }

  void run(const typename Cloud::ConstPtr& previous,
           const typename Cloud::ConstPtr& current)
  {
    estimation_.setPreviousCloud(previous);
    estimation_.setInputCloud(current);
    estimation_.compute(flow_);
  }

  CameraIntrinsics intrinsics_ = scaledIntrinsics(WIDTH);
  dynvo::GridSceneFlowEstimation<PointT> estimation_;
  FlowCloud flow_;
};

using PointTypes = ::testing::Types<pcl::PointXYZRGB, pcl::PointXYZRGBA>;
TYPED_TEST_SUITE(GridSceneFlowTest, PointTypes);

TYPED_TEST(GridSceneFlowTest, SameFrameTwiceGivesZeroFlowOnEveryTexturedCell)
{
  const auto frame = this->view(staticRoom(), Eigen::Isometry3d::Identity());
  this->run(frame.cloud, frame.cloud);
  ASSERT_EQ(this->flow_.width, 10u); // 160 / 16
  ASSERT_EQ(this->flow_.height, 7u); // 120 / 16
  expectCellContract(this->flow_);
  for (const PointFlow& f : this->flow_) {
    // Every cell sees texture at valid depth, so every cell must be tracked.
    ASSERT_TRUE(f.valid_3d) << "cell at " << f.u << "," << f.v;
    // Identical images give a zero LK residual at every level, so the track cannot move;
    // 1e-3 px and 1e-6 m only absorb float rounding.
    EXPECT_NEAR(f.prev_u, f.u, 1e-3f);
    EXPECT_NEAR(f.prev_v, f.v, 1e-3f);
    EXPECT_LT((prevPoint(f) - currPoint(f)).norm(), 1e-6);
  }
}

TYPED_TEST(GridSceneFlowTest, KnownCameraMotionIsRecoveredForwardAndInverse)
{
  const auto scene = staticRoom();
  // The camera moves by ~2.6 cm and ~1.1 deg between the poses: 3-5 px of flow.
  const Eigen::Isometry3d T_world_a = Eigen::Isometry3d::Identity();
  const Eigen::Isometry3d T_world_b = pose(0.5, 1.0, 0.3, 0.02, -0.01, 0.015);
  const auto view_a = this->view(scene, T_world_a);
  const auto view_b = this->view(scene, T_world_b);
  for (const auto check :
       {dynvo::ForwardBackwardCheck::local, dynvo::ForwardBackwardCheck::full}) {
    this->estimation_.setForwardBackwardCheck(check);
    for (const bool inverse : {false, true}) {
      SCOPED_TRACE(std::string(inverse ? "b -> a" : "a -> b") +
                   (check == dynvo::ForwardBackwardCheck::full ? ", full check"
                                                               : ", local check"));
      const Eigen::Isometry3d T_prev_curr =
          inverse ? T_world_b.inverse() * T_world_a : T_world_a.inverse() * T_world_b;
      this->run(inverse ? view_b.cloud : view_a.cloud,
                inverse ? view_a.cloud : view_b.cloud);
      expectCellContract(this->flow_);
      std::vector<double> error_3d, error_2d;
      for (const PointFlow& f : this->flow_) {
        if (!f.valid_3d)
          continue;
        // b_i is exact (noise-free depth at an integer pixel): its true previous position is known.
        const Eigen::Vector3d a_true = T_prev_curr * currPoint(f);
        const Eigen::Vector2f p_true = this->intrinsics_.project(a_true.cast<float>());
        error_3d.push_back((prevPoint(f) - a_true).norm());
        error_2d.push_back((Eigen::Vector2f(f.prev_u, f.prev_v) - p_true).norm());
      }
      // Cells whose window leaves the image or straddles the board's outline may be rejected.
      ASSERT_GE(error_3d.size(), this->flow_.size() * 8 / 10);
      const std::string key =
          std::string(inverse ? "inverse_" : "forward_") +
          (check == dynvo::ForwardBackwardCheck::full ? "full_" : "local_");
      this->RecordProperty(key + "median_error_2d_px",
                           std::to_string(median(error_2d)));
      this->RecordProperty(key + "median_error_3d_mm",
                           std::to_string(median(error_3d) * 1000.0));
      // 0.2 px at 1.2-2 m and fx = 131 px is 2-3 mm laterally; 5 mm leaves room for the
      // bilinear depth on the slanted board.
      EXPECT_LT(median(error_2d), 0.2);
      EXPECT_LT(median(error_3d), 0.005);
    }
  }
}

TYPED_TEST(GridSceneFlowTest, KeyframeFlowStartsFromThePredictionAndOutlivesLaterFrames)
{
  const auto scene = staticRoom();
  // Keyframe a, then b and c: c is 9 cm and 5 deg from a, 10-16 px of flow at this size,
  // beyond what LK on the finest level finds from c_i alone (a 16 px window).
  const Eigen::Isometry3d T_world_a = Eigen::Isometry3d::Identity();
  const Eigen::Isometry3d T_world_b = pose(0.5, 2.0, 0.3, 0.03, -0.01, 0.02);
  const Eigen::Isometry3d T_world_c = pose(1.0, 5.0, 0.6, 0.08, -0.02, 0.04);
  auto& estimation = this->estimation_;
  this->run(this->view(scene, T_world_b).cloud, this->view(scene, T_world_a).cloud);
  ASSERT_TRUE(estimation.setCurrentAsKeyframe());
  // b and c are prepared into the slots after the keyframe: its pyramid and depth must stay.
  for (const auto& T_world : {T_world_b, T_world_c}) {
    estimation.shiftCurrentToPrevious();
    estimation.setInputCloud(this->view(scene, T_world).cloud);
    estimation.compute(this->flow_);
  }
  const Eigen::Isometry3d T_a_c = T_world_a.inverse() * T_world_c;
  const auto track = [&](const Eigen::Isometry3d& seed_motion) {
    FlowCloud flow;
    estimation.computeToKeyframe(seed_motion.matrix().cast<float>(), 0,
                                 dynvo::FlowGrid(), flow);
    expectCellContract(flow);
    std::vector<double> error_2d;
    for (const PointFlow& f : flow)
      if (f.valid_3d) {
        const Eigen::Vector2f p_true =
            this->intrinsics_.project((T_a_c * currPoint(f)).cast<float>());
        error_2d.push_back((Eigen::Vector2f(f.prev_u, f.prev_v) - p_true).norm());
      }
    return error_2d;
  };
  // Seeded with the true motion: tracked as well as a small frame-to-frame motion (0.2 px,
  // KnownCameraMotionIsRecoveredForwardAndInverse); cells whose window leaves the image or
  // straddles the board's outline may be rejected.
  const auto seeded = track(T_a_c);
  ASSERT_GE(seeded.size(), this->flow_.size() * 7 / 10);
  EXPECT_LT(median(seeded), 0.2);
  // Seeded with a prediction 2 cm and 1 deg off (a lost frame's constant velocity): still
  // within the window's reach on the finest level.
  const auto off = track(T_a_c * pose(0.0, 1.0, 0.0, 0.02, 0.0, 0.0));
  ASSERT_GE(off.size(), this->flow_.size() * 7 / 10);
  EXPECT_LT(median(off), 0.2);
  // Without the prediction (identity) the finest level alone does not reach the keyframe
  // positions: few cells pass the forward-backward check, and not at the true positions.
  const auto unseeded = track(Eigen::Isometry3d::Identity());
  EXPECT_TRUE(unseeded.size() < seeded.size() / 2 || median(unseeded) > 1.0);

  // Only the selected cells are tracked: here the left half of the grid.
  dynvo::FlowGrid left(TestFixture::WIDTH, TestFixture::HEIGHT, 16);
  for (std::size_t i = 0; i < left.size(); ++i)
    left.labels[i] =
        i % left.cols < left.cols / 2 ? dynvo::LABEL_STATIC : dynvo::LABEL_NONE;
  FlowCloud flow;
  estimation.computeToKeyframe(T_a_c.matrix().cast<float>(), 0, left, flow);
  ASSERT_EQ(flow.size(), left.size());
  std::size_t tracked_left = 0;
  for (std::size_t i = 0; i < flow.size(); ++i) {
    if (left.labels[i] == dynvo::LABEL_NONE)
      EXPECT_FALSE(flow[i].valid_2d) << "cell " << i;
    else
      tracked_left += flow[i].valid_3d;
  }
  EXPECT_GE(tracked_left, left.size() / 2 * 7 / 10);
  // A grid of another geometry is refused.
  estimation.computeToKeyframe(
      T_a_c.matrix().cast<float>(), 0,
      dynvo::FlowGrid(TestFixture::WIDTH, TestFixture::HEIGHT, 8), flow);
  EXPECT_TRUE(flow.empty());

  // New parameters drop the keyframe (its pyramid was built with the old ones).
  estimation.setWindowSize(15);
  EXPECT_EQ(estimation.getKeyframeCloud(), nullptr);
  estimation.computeToKeyframe(T_a_c.matrix().cast<float>(), 0, dynvo::FlowGrid(),
                               flow);
  EXPECT_TRUE(flow.empty());
}

TYPED_TEST(GridSceneFlowTest, MovingObjectCellsCarryTheObjectMotion)
{
  auto scene = staticRoom();
  scene.resize(1); // the wall only
  const SceneBox box =
      dynvo::test::texturedQuad(pose(0, 0, 0, 0.1, 0.0, 1.2), 0.35, 0.25, 5, true);
  const Eigen::Isometry3d T_world_curr = pose(0, 0.5, 0, 0.01, 0, 0);
  const auto previous = [&] {
    auto quads = scene;
    quads.push_back(box);
    return this->view(quads, Eigen::Isometry3d::Identity());
  }();
  // The object moves 4 cm and turns 3 deg about its own z axis, far beyond the static motion.
  const Eigen::Isometry3d motion = pose(0, 0, 3, -0.03, 0.02, -0.01);
  auto quads = scene;
  quads.push_back(box);
  auto current = this->view(dynvo::test::moveBoxes(quads, motion), T_world_curr);
  // A missing-depth block (48x32 px, wider than any fillable hole) over the top-left cells.
  for (std::uint32_t v = 0; v < 32; ++v)
    for (std::uint32_t u = 0; u < 48; ++u) {
      auto& p = (*current.cloud)(u, v);
      p.x = p.y = p.z = std::numeric_limits<float>::quiet_NaN();
    }
  this->run(previous.cloud, current.cloud);
  expectCellContract(this->flow_);

  std::vector<double> object_error;
  std::size_t object_cells = 0;
  for (const PointFlow& f : this->flow_) {
    if (f.u < 48 && f.v < 32) {
      EXPECT_FALSE(f.valid_3d) << "cell at " << f.u << "," << f.v << " has no depth";
      EXPECT_TRUE(std::isnan(f.z));
      continue;
    }
    const auto pixel =
        static_cast<std::size_t>(f.v) * this->WIDTH + static_cast<std::size_t>(f.u);
    if (current.ids[pixel] != 1) // the box, second in the list
      continue;
    ++object_cells;
    if (!f.valid_3d)
      continue;
    // World point now -> same object point before the motion -> previous camera (= world).
    const Eigen::Vector3d a_true = motion.inverse() * (T_world_curr * currPoint(f));
    object_error.push_back((prevPoint(f) - a_true).norm());
  }
  ASSERT_GE(object_cells, 8u); // the box spans ~4x3 cells at this size
  // Cells near the outline see both motions and may be rejected; most must survive.
  ASSERT_GE(object_error.size() * 2, object_cells);
  this->RecordProperty("object_median_error_3d_mm",
                       std::to_string(median(object_error) * 1000.0));
  EXPECT_LT(median(object_error),
            0.005); // as for camera motion; the object moves 4-5 cm
}

TYPED_TEST(GridSceneFlowTest, ShiftCurrentToPreviousMatchesAFreshComputation)
{
  const auto scene = staticRoom();
  const auto f0 = this->view(scene, Eigen::Isometry3d::Identity());
  const auto f1 = this->view(scene, pose(0, 0.4, 0, 0.01, 0, 0));
  const auto f2 = this->view(scene, pose(0, 0.8, 0, 0.02, 0.005, 0));
  this->run(f0.cloud, f1.cloud);
  this->estimation_.shiftCurrentToPrevious();
  EXPECT_EQ(this->estimation_.getPreviousCloud(), f1.cloud);
  EXPECT_FALSE(this->estimation_.getInputCloud());
  this->estimation_.setInputCloud(f2.cloud);
  this->estimation_.compute(this->flow_);

  dynvo::GridSceneFlowEstimation<TypeParam> fresh;
  fresh.setCameraIntrinsics(this->intrinsics_);
  fresh.setPreviousCloud(f1.cloud);
  fresh.setInputCloud(f2.cloud);
  FlowCloud expected;
  fresh.compute(expected);
  ASSERT_FALSE(expected.empty());
  EXPECT_GE(validCells(expected),
            60u); // of 70: the comparison is not between empty grids
  EXPECT_TRUE(identical(this->flow_, expected));

  // A parameter change after the shift must rebuild both frames, not reuse stale pyramids.
  this->estimation_.setWindowSize(11);
  this->estimation_.compute(this->flow_);
  fresh.setWindowSize(11);
  fresh.compute(expected);
  EXPECT_TRUE(identical(this->flow_, expected));
}

TYPED_TEST(GridSceneFlowTest, InputDepthAndGreyAreThoseOfTheInputCloud)
{
  const auto scene = staticRoom();
  const auto f0 = this->view(scene, Eigen::Isometry3d::Identity());
  const auto f1 = this->view(scene, pose(0, 0.4, 0, 0.01, 0, 0));
  const auto f2 = this->view(scene, pose(0, 0.8, 0, 0.02, 0.005, 0));
  // z and grey level of every point, NaN where it has no z; the views differ, so a mix-up
  // shows.
  const auto sameZ = [](const std::vector<float>& depth, const auto& cloud) {
    if (depth.size() != cloud.size())
      return false;
    for (std::size_t i = 0; i < depth.size(); ++i)
      if (!(depth[i] == cloud[i].z || (std::isnan(depth[i]) && !std::isfinite(cloud[i].z))))
        return false;
    return true;
  };
  const auto matches = [&](const auto& estimation, const auto& cloud) {
    const std::vector<std::uint8_t>& grey = estimation.getInputGrey();
    if (!estimation.getInputDepth() || !sameZ(*estimation.getInputDepth(), cloud) ||
        grey.size() != cloud.size())
      return false;
    for (std::size_t i = 0; i < grey.size(); ++i)
      if (grey[i] != dynvo::luma(cloud[i].r, cloud[i].g, cloud[i].b))
        return false;
    return true;
  };
  auto& estimation = this->estimation_;
  // The first pair prepares the previous cloud too: depth and grey stay the input's.
  this->run(f0.cloud, f1.cloud);
  EXPECT_TRUE(matches(estimation, *f1.cloud));
  EXPECT_FALSE(matches(estimation, *f0.cloud));
  // A later stage keeps the image it was given (shared, not copied): the next frames'
  // compute() write other images.
  const auto kept = estimation.getInputDepth();
  estimation.shiftCurrentToPrevious();
  EXPECT_FALSE(estimation.getInputDepth());
  EXPECT_TRUE(estimation.getInputGrey().empty());
  estimation.setInputCloud(f2.cloud);
  EXPECT_FALSE(estimation.getInputDepth()); // not read before compute()
  EXPECT_TRUE(estimation.getInputGrey().empty());
  estimation.compute(this->flow_);
  EXPECT_TRUE(matches(estimation, *f2.cloud));
  const auto* f2_image = estimation.getInputDepth().get();
  estimation.shiftCurrentToPrevious();
  estimation.setInputCloud(f0.cloud);
  estimation.compute(this->flow_);
  EXPECT_TRUE(matches(estimation, *f0.cloud));
  EXPECT_EQ(estimation.getInputDepth().get(), f2_image); // let go of: written again
  ASSERT_TRUE(kept);
  EXPECT_TRUE(sameZ(*kept, *f1.cloud));
}

/// The camera of a steady sweep at t seconds: 60 deg/s about y, 0.3 m/s sideways and
/// 0.4 m/s forward (a fast hand-held motion).
Eigen::Isometry3d
sweepPose(double t)
{
  return pose(0, 60.0 * t, 0, 0.3 * t, 0, 0.4 * t);
}

TYPED_TEST(GridSceneFlowTest, FlowEndsAreThePointsAtTheDepthInstants)
{
  // A sensor whose streams are not synchronised (TUM fr1): colour at 0 and 1/30 s, depth
  // 15 ms before and 13 ms after. Each frame has the colour of one view and the points of
  // another; the sweep moves the image by 137 px/s (about 2 px between colour and depth),
  // 2-3 cm at 1.2-2 m.
  const auto scene = staticRoom();
  const double colour[2] = {0.0, 1.0 / 30.0};
  const double depth[2] = {colour[0] - 0.015, colour[1] + 0.013};
  typename TestFixture::Cloud::Ptr frames[2];
  for (int k = 0; k < 2; ++k) {
    frames[k] = this->view(scene, sweepPose(colour[k])).cloud;
    const auto points = this->view(scene, sweepPose(depth[k])).cloud;
    for (std::size_t i = 0; i < frames[k]->size(); ++i) {
      (*frames[k])[i].x = (*points)[i].x;
      (*frames[k])[i].y = (*points)[i].y;
      (*frames[k])[i].z = (*points)[i].z;
    }
  }
  // The points of a static scene at the two depth instants: b_i = T_curr_prev a_i.
  const Eigen::Isometry3d T_prev_curr =
      sweepPose(depth[0]).inverse() * sweepPose(depth[1]);
  const auto median_error = [&](bool with_stamps) {
    auto& estimation = this->estimation_;
    estimation.setInputCloud(frames[0]);
    if (with_stamps)
      estimation.setInputStamps(colour[0], depth[0]);
    estimation.shiftCurrentToPrevious();
    estimation.setInputCloud(frames[1]);
    if (with_stamps)
      estimation.setInputStamps(colour[1], depth[1]);
    estimation.compute(this->flow_);
    expectCellContract(this->flow_);
    std::vector<double> error;
    for (const PointFlow& f : this->flow_)
      if (f.valid_3d)
        error.push_back((prevPoint(f) - T_prev_curr * currPoint(f)).norm());
    // Cells leaving the view or straddling the board's outline may be rejected.
    EXPECT_GE(error.size(), this->flow_.size() * 7 / 10);
    return median(error);
  };
  const double without = median_error(false);
  const double with = median_error(true);
  this->RecordProperty("median_error_mm_without_stamps",
                       std::to_string(without * 1000.0));
  this->RecordProperty("median_error_mm_with_stamps", std::to_string(with * 1000.0));
  // With the stamps, the tolerance of the synchronised test (5 mm: LK's 0.2 px and the
  // bilinear depth on the slanted board); the velocity is the track's over one interval,
  // exact for a steady sweep up to the image-plane curvature of the rotation.
  EXPECT_LT(with, 0.005);
  // Without them, each end is off by the ~2 px the image moves between colour and depth.
  EXPECT_GT(without, 3.0 * with);
}

TYPED_TEST(GridSceneFlowTest, KeyframeCellsWithoutATrackTakeTheirNeighboursVelocity)
{
  // The sweep and stream offsets of FlowEndsAreThePointsAtTheDepthInstants over three frames;
  // frame 1 is the keyframe. Frame 0's colour is blank over a block of cells, so frame 1's
  // tracks there fail and those keyframe cells have no velocity of their own. Frame 2 is
  // tracked into the keyframe: its points falling in that block are read at the keyframe's
  // depth instant only if the block's cells carry the image velocity of the cells around
  // them (with none, each is read ~2 px off: 2-3 cm at 1.2-2 m).
  const auto scene = staticRoom();
  const double colour[3] = {0.0, 1.0 / 30.0, 2.0 / 30.0};
  const double depth[3] = {colour[0] - 0.015, colour[1] + 0.013, colour[2] - 0.010};
  constexpr int cell = 16, first_col = 3, last_col = 6, first_row = 2, last_row = 4;
  typename TestFixture::Cloud::Ptr frames[3];
  for (int k = 0; k < 3; ++k) {
    frames[k] = this->view(scene, sweepPose(colour[k])).cloud;
    const auto points = this->view(scene, sweepPose(depth[k])).cloud;
    for (std::size_t i = 0; i < frames[k]->size(); ++i) {
      auto& point = (*frames[k])[i];
      point.x = (*points)[i].x;
      point.y = (*points)[i].y;
      point.z = (*points)[i].z;
      const int col = static_cast<int>(i % TestFixture::WIDTH) / cell;
      const int row = static_cast<int>(i / TestFixture::WIDTH) / cell;
      if (k == 0 && col >= first_col && col <= last_col && row >= first_row &&
          row <= last_row)
        point.r = point.g = point.b = 128;
    }
  }
  auto& estimation = this->estimation_;
  estimation.setInputCloud(frames[0]);
  estimation.setInputStamps(colour[0], depth[0]);
  estimation.shiftCurrentToPrevious();
  estimation.setInputCloud(frames[1]);
  estimation.setInputStamps(colour[1], depth[1]);
  estimation.compute(this->flow_);
  const FlowCloud keyframe_flow = this->flow_;
  ASSERT_TRUE(estimation.setCurrentAsKeyframe());
  estimation.shiftCurrentToPrevious();
  estimation.setInputCloud(frames[2]);
  estimation.setInputStamps(colour[2], depth[2]);
  estimation.compute(this->flow_);
  const Eigen::Isometry3d T_keyframe_curr =
      sweepPose(depth[1]).inverse() * sweepPose(depth[2]);
  FlowCloud flow;
  estimation.computeToKeyframe(T_keyframe_curr.matrix().cast<float>(), 0,
                               dynvo::FlowGrid(), flow);
  expectCellContract(flow);
  std::vector<double> error;
  for (const PointFlow& f : flow) {
    if (!f.valid_3d)
      continue;
    const std::size_t k =
        static_cast<std::size_t>(f.prev_v) / cell * keyframe_flow.width +
        static_cast<std::size_t>(f.prev_u) / cell;
    if (!keyframe_flow[k].valid_2d)
      error.push_back((prevPoint(f) - T_keyframe_curr * currPoint(f)).norm());
  }
  this->RecordProperty("cells_in_untracked_keyframe_cells",
                       std::to_string(error.size()));
  // The block's inner cells at least (its border cells' windows may still find texture).
  ASSERT_GE(error.size(), 3u);
  // The synchronised tolerance of FlowEndsAreThePointsAtTheDepthInstants (5 mm).
  EXPECT_LT(median(error), 0.005);
}

TYPED_TEST(GridSceneFlowTest, EqualOrUnknownStampsLeaveTheFlowAsTracked)
{
  const auto scene = staticRoom();
  const auto previous = this->view(scene, sweepPose(0.0)).cloud;
  const auto current = this->view(scene, sweepPose(1.0 / 30.0)).cloud;
  this->run(previous, current);
  const FlowCloud unknown = this->flow_;
  ASSERT_GE(validCells(unknown), 40u); // not two empty grids
  auto& estimation = this->estimation_;
  estimation.setInputCloud(previous);
  estimation.setInputStamps(0.0, 0.0);
  estimation.shiftCurrentToPrevious();
  estimation.setInputCloud(current);
  estimation.setInputStamps(1.0 / 30.0, 1.0 / 30.0);
  estimation.compute(this->flow_);
  EXPECT_TRUE(identical(this->flow_, unknown));
}

TYPED_TEST(GridSceneFlowTest, ResultIsIdenticalForOneAndTwoThreads)
{
  const auto scene = staticRoom();
  const auto previous = this->view(scene, Eigen::Isometry3d::Identity());
  const auto current = this->view(scene, pose(0.3, 0.6, 0, 0.015, 0, 0.01));
  this->run(previous.cloud, current.cloud);
  const FlowCloud single = this->flow_;
  // Not vacuous: the camera moved and most of the 10x7 cells were tracked in 3D with a
  // non-zero flow (two empty grids would compare equal too).
  ASSERT_EQ(single.size(), 70u);
  EXPECT_GE(validCells(single), 60u);
  EXPECT_GT(std::count_if(single.begin(), single.end(),
                          [](const PointFlow& f) {
                            return f.valid_2d && std::abs(f.prev_u - f.u) > 0.5f;
                          }),
            30);
  this->estimation_.setNumberOfThreads(2);
  this->run(previous.cloud, current.cloud);
  EXPECT_EQ(validCells(this->flow_), validCells(single));
  EXPECT_TRUE(identical(this->flow_, single));
}

// --- contract ---------------------------------------------------------------------------

TEST(GridSceneFlowPrediction, IsTurnedOntoTheImagesShiftBeyondThePyramidsReach)
{
  // VGA, as the pipeline runs: a pan and tilt of 5 and 4 deg with the prediction at rest is
  // about 59 px of flow at fx = 525 px, beyond the pyramid's reach of (16 / 2) * 2^2 =
  // 32 px, as a hand-held sweep whose velocity changed after a dropped frame.
  constexpr std::uint32_t WIDTH = 640, HEIGHT = 480;
  const CameraIntrinsics intrinsics = scaledIntrinsics(WIDTH);
  const auto view = [&](const Eigen::Isometry3d& T_world_camera) {
    return dynvo::test::render<pcl::PointXYZRGB>(staticRoom(), T_world_camera,
                                                 intrinsics, WIDTH, HEIGHT)
        .cloud;
  };
  const Eigen::Isometry3d T_prev_curr = pose(-4.0, 5.0, 0.0, 0.0, 0.0, 0.0);
  const auto previous = view(Eigen::Isometry3d::Identity());
  const auto current = view(T_prev_curr);
  dynvo::GridSceneFlowEstimation<pcl::PointXYZRGB> estimation;
  estimation.setCameraIntrinsics(intrinsics);
  FlowCloud flow;
  const auto run = [&] {
    estimation.setPreviousCloud(previous);
    estimation.setInputCloud(current);
    estimation.compute(flow);
    expectCellContract(flow);
  };
  run();
  // The correction is the rotation the image shows: phase correlation on the 160 x 120 top
  // level measures the shift to about a pixel there (4 px, 0.4 deg at VGA), and the image's
  // edges move a few pixels more than its centre.
  const Eigen::Matrix3d R_shift = estimation.getPredictionCorrection().cast<double>();
  EXPECT_LT(Eigen::AngleAxisd(R_shift.transpose() * T_prev_curr.linear()).angle(),
            dynvo::test::radians(1.0));
  // Seeded from it, the cells are tracked as precisely as a small motion
  // (KnownCameraMotionIsRecoveredForwardAndInverse: 0.2 px); about a tenth of the image
  // leaves the view.
  std::vector<double> error_2d;
  for (const PointFlow& f : flow)
    if (f.valid_3d)
      error_2d.push_back(
          (Eigen::Vector2f(f.prev_u, f.prev_v) -
           intrinsics.project((T_prev_curr * currPoint(f)).cast<float>()))
              .norm());
  ASSERT_GE(error_2d.size(), flow.size() * 7 / 10);
  EXPECT_LT(median(error_2d), 0.2);

  // A prediction within the reach of the motion (1 deg off, 9 px) is kept as it is.
  estimation.setPredictedMotion((T_prev_curr * pose(0.0, 1.0, 0.0, 0.0, 0.0, 0.0))
                                    .inverse()
                                    .matrix()
                                    .cast<float>());
  run();
  EXPECT_TRUE(estimation.getPredictionCorrection().isIdentity());
}

class GridSceneFlowContractTest : public ::testing::Test {
protected:
  using Cloud = pcl::PointCloud<pcl::PointXYZRGB>;

  /// Runs compute() on an output holding stale content; returns what PCL_ERROR printed.
  std::string computeCapturingErrors()
  {
    flow_.resize(3, 1);
    ::testing::internal::CaptureStderr();
    estimation_.compute(flow_);
    return ::testing::internal::GetCapturedStderr();
  }

  static Cloud::Ptr organized(std::uint32_t width, std::uint32_t height)
  {
    return dynvo::test::render<pcl::PointXYZRGB>(staticRoom(),
                                                 Eigen::Isometry3d::Identity(),
                                                 scaledIntrinsics(width), width, height)
        .cloud;
  }

  dynvo::GridSceneFlowEstimation<pcl::PointXYZRGB> estimation_;
  FlowCloud flow_;
};

TEST_F(GridSceneFlowContractTest, MissingInputsGiveClearedOutputAndAnError)
{
  EXPECT_NE(computeCapturingErrors().find("[dynvo::GridSceneFlowEstimation::compute]"),
            std::string::npos);
  EXPECT_TRUE(flow_.empty());
  estimation_.setInputCloud(organized(32, 32));
  EXPECT_NE(computeCapturingErrors().find("previous"), std::string::npos);
  EXPECT_TRUE(flow_.empty());
}

TEST_F(GridSceneFlowContractTest,
       UnorganizedMismatchedOrTooSmallInputsGiveClearedOutput)
{
  const Cloud::Ptr frame = organized(32, 32);
  Cloud::Ptr unorganized(new Cloud(*frame));
  unorganized->width = static_cast<std::uint32_t>(unorganized->size());
  unorganized->height = 1;
  estimation_.setPreviousCloud(frame);
  estimation_.setInputCloud(unorganized);
  EXPECT_NE(computeCapturingErrors().find("not organized"), std::string::npos);
  EXPECT_TRUE(flow_.empty());

  estimation_.setInputCloud(organized(48, 32));
  EXPECT_NE(computeCapturingErrors().find("48x32 but previous cloud is 32x32"),
            std::string::npos);
  EXPECT_TRUE(flow_.empty());

  estimation_.setInputCloud(frame);
  estimation_.setCellSize(40); // larger than the 32x32 image
  EXPECT_NE(computeCapturingErrors().find("no 40 px grid cell"), std::string::npos);
  EXPECT_TRUE(flow_.empty());

  // 12 px cells on 32 px: 2 columns, from which the consumers would infer 16 px cells.
  estimation_.setCellSize(12);
  EXPECT_NE(computeCapturingErrors().find("could not be inferred"), std::string::npos);
  EXPECT_TRUE(flow_.empty());
}

TEST_F(GridSceneFlowContractTest, VgaPairGivesAFortyByThirtyGridOnCellCentres)
{
  const Cloud::Ptr previous = organized(640, 480);
  const Cloud::Ptr current =
      dynvo::test::render<pcl::PointXYZRGB>(staticRoom(), pose(0, 0.5, 0, 0.01, 0, 0),
                                            scaledIntrinsics(640), 640, 480)
          .cloud;
  current->header.stamp = 42;
  estimation_.setCameraIntrinsics(scaledIntrinsics(640));
  estimation_.setPreviousCloud(previous);
  estimation_.setInputCloud(current);
  estimation_.compute(flow_);
  ASSERT_EQ(flow_.width, 40u);
  ASSERT_EQ(flow_.height, 30u);
  EXPECT_FALSE(flow_.is_dense);
  EXPECT_EQ(flow_.header.stamp, 42u);
  for (std::uint32_t row = 0; row < 30; ++row)
    for (std::uint32_t col = 0; col < 40; ++col) {
      EXPECT_EQ(flow_(col, row).u, 16.0f * col + 8.0f);
      EXPECT_EQ(flow_(col, row).v, 16.0f * row + 8.0f);
    }
  expectCellContract(flow_);
  const auto valid = std::count_if(flow_.begin(), flow_.end(), [](const PointFlow& f) {
    return f.valid_3d != 0;
  });
  EXPECT_GE(valid, 1100); // textured scene, small motion: only border cells may fail
}

TEST_F(GridSceneFlowContractTest, BadParametersThrowAndKeepTheOldValue)
{
  EXPECT_THROW(estimation_.setCellSize(1), std::invalid_argument);
  EXPECT_EQ(estimation_.getCellSize(), 16);
  EXPECT_THROW(estimation_.setWindowSize(2), std::invalid_argument);
  EXPECT_THROW(estimation_.setMaxPyramidLevel(-1), std::invalid_argument);
  EXPECT_THROW(estimation_.setMaxIterations(0), std::invalid_argument);
  EXPECT_THROW(estimation_.setEpsilon(0.0), std::invalid_argument);
  EXPECT_THROW(estimation_.setMinEigenThreshold(-1.0), std::invalid_argument);
  EXPECT_THROW(estimation_.setForwardBackwardThreshold(0.0f), std::invalid_argument);
  EXPECT_THROW(estimation_.setDepthEdgeTolerance(-0.1f), std::invalid_argument);
  EXPECT_THROW(estimation_.setMaxFlow(0.0f), std::invalid_argument);
  EXPECT_THROW(estimation_.setWeightReferenceDepth(0.0f), std::invalid_argument);
  EXPECT_THROW(estimation_.setMinDepth(-1.0f), std::invalid_argument);
  EXPECT_EQ(estimation_.getMinDepth(), 0.3f);
  EXPECT_THROW(estimation_.setMaxHoleWidth(-2), std::invalid_argument);
  EXPECT_THROW(estimation_.setFlyingPixelTolerance(0.0f), std::invalid_argument);
  EXPECT_THROW(estimation_.setHoleFillTolerance(std::nanf("")), std::invalid_argument);
  EXPECT_THROW(estimation_.setNumberOfThreads(0), std::invalid_argument);
  EXPECT_THROW(estimation_.setCameraIntrinsics({0.0, 525.0, 319.5, 239.5}),
               std::invalid_argument);
  dynvo::GridSceneFlowParameters parameters;
  parameters.max_flow = -1.0f;
  EXPECT_THROW(estimation_.setParameters(parameters), std::invalid_argument);
  EXPECT_EQ(estimation_.getMaxFlow(), dynvo::GridSceneFlowParameters{}.max_flow);
}

TEST_F(GridSceneFlowContractTest,
       DepthRangeIsCheckedWhenComputingSoSettersWorkInAnyOrder)
{
  // Moving the range to [6, 8] m raises min_depth first: above the old max_depth, which a
  // setter must not reject, since its own range (> 0) is met.
  EXPECT_NO_THROW(estimation_.setMinDepth(6.0f));
  flow_.resize(3);
  EXPECT_THROW(estimation_.compute(flow_), std::invalid_argument);
  EXPECT_TRUE(flow_.empty());
  EXPECT_NO_THROW(estimation_.setMaxDepth(8.0f));
  EXPECT_NO_THROW(estimation_.getParameters().validate());
}

} // namespace
