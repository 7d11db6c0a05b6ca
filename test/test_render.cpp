// SPDX-License-Identifier: BSD-3-Clause
// Off-screen rendering: label palette, camera-view registration, scene views, trajectory plot.
// Render cases need an X display (run `xvfb-run -a ctest`); without one they skip.
#include <dynvo/common/conventions.h>
#include <dynvo/vis/display.h>
#include <dynvo/vis/label_renderer.h>
#include <dynvo/vis/trajectory_plot.h>

#include <gtest/gtest.h>

#include "support/temp_dir.h"

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <set>
#include <string>

namespace {

using dynvo::LabelRenderer;
using Rgb = std::array<std::uint8_t, 3>;

constexpr double PI = 3.14159265358979323846;

#define DYNVO_SKIP_WITHOUT_DISPLAY()                                                   \
  do {                                                                                 \
    std::string why;                                                                   \
    if (!dynvo::displayAvailable(&why))                                                \
      GTEST_SKIP() << "no display (" << why << "); run under xvfb-run -a";             \
  } while (false)

/// Colour of a PNG pixel (OpenCV reads B, G, R).
Rgb
pixel(const cv::Mat& bgr, int u, int v)
{
  const cv::Vec3b p = bgr.at<cv::Vec3b>(v, u);
  return {p[2], p[1], p[0]};
}

/// Largest per-channel difference.
int
colourDistance(const Rgb& a, const Rgb& b)
{
  int d = 0;
  for (int c = 0; c < 3; ++c)
    d = std::max(d, std::abs(int(a[c]) - int(b[c])));
  return d;
}

/// The driver turns 8-bit colours into floats and back, and the renderer blends in a
/// different order than blendedColor(); each may round by one level.
constexpr int COLOUR_ROUNDING = 1;

/** A 640x480 organized scene seen by an anisotropic, off-centre camera, with every pixel
 * valid (307,200 points): a slanted static wall (label 1), an unlabelled floor strip
 * (label 0), a box (label 2) and a disc (label 5) in front. Colours vary smoothly. */
class LabelledScene : public ::testing::Test {
protected:
  void SetUp() override
  {
    params_.intrinsics.fx = 520.0;
    params_.intrinsics.fy = 535.0;
    params_.intrinsics.cx = 324.0;
    params_.intrinsics.cy = 236.5;
    cloud_.width = params_.width;
    cloud_.height = params_.height;
    cloud_.resize(std::size_t{cloud_.width} * cloud_.height);
    labels_.assign(cloud_.size(), dynvo::LABEL_STATIC);
    for (int v = 0; v < int(cloud_.height); ++v)
      for (int u = 0; u < int(cloud_.width); ++u) {
        const std::size_t i = std::size_t(v) * cloud_.width + u;
        float z = 3.0f + 0.001f * u;
        if (v >= 400)
          labels_[i] = dynvo::LABEL_NONE;
        if (u >= 100 && u < 220 && v >= 100 && v < 200) {
          labels_[i] = 2;
          z = 1.5f;
        }
        if (std::hypot(u - 450.0, v - 320.0) < 60.0) {
          labels_[i] = 5;
          z = 2.0f;
        }
        const Eigen::Vector3f p = params_.intrinsics.backproject(u, v, z);
        pcl::PointXYZRGB& point = cloud_[i];
        point.x = p.x();
        point.y = p.y();
        point.z = p.z();
        point.r = static_cast<std::uint8_t>(128 + 100 * std::sin(u / 40.0));
        point.g = static_cast<std::uint8_t>(128 + 100 * std::cos(v / 30.0));
        point.b = static_cast<std::uint8_t>((u + v) / 8 % 256);
      }
  }

  Rgb expected(std::size_t i) const
  {
    const pcl::PointXYZRGB& p = cloud_[i];
    return LabelRenderer::blendedColor(labels_[i], {p.r, p.g, p.b}, params_.rgb_blend);
  }

  /// Renders, times the call and reads the PNG back.
  cv::Mat renderAndRead(LabelRenderer& renderer,
                        const Eigen::Isometry3d& pose,
                        const dynvo::Trajectory& trajectory,
                        const std::string& name,
                        double* milliseconds = nullptr)
  {
    const std::string path = dir_.file(name);
    const auto start = std::chrono::steady_clock::now();
    EXPECT_TRUE(renderer.render(cloud_, labels_, pose, trajectory, path));
    if (milliseconds)
      *milliseconds = std::chrono::duration<double, std::milli>(
                          std::chrono::steady_clock::now() - start)
                          .count();
    return cv::imread(path, cv::IMREAD_COLOR);
  }

  LabelRenderer::Parameters params_;
  pcl::PointCloud<pcl::PointXYZRGB> cloud_;
  std::vector<std::uint8_t> labels_;
  dynvo::test::TempDir dir_;
};

Eigen::Isometry3d
somePose()
{
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::AngleAxisd(0.6, Eigen::Vector3d(0.3, -1.0, 0.2).normalized())
                      .toRotationMatrix();
  pose.translation() = Eigen::Vector3d(1.5, -0.4, 2.0);
  return pose;
}

TEST(LabelPalette, GreysForNoneAndStaticSaturatedDistinctObjects)
{
  const Rgb none = LabelRenderer::labelColor(dynvo::LABEL_NONE);
  const Rgb stat = LabelRenderer::labelColor(dynvo::LABEL_STATIC);
  EXPECT_TRUE(none[0] == none[1] && none[1] == none[2]);
  EXPECT_TRUE(stat[0] == stat[1] && stat[1] == stat[2]);
  EXPECT_LT(none[0], stat[0]) << "no measurement is the darker grey";
  std::set<Rgb> seen{none, stat};
  for (int label = 2; label < 256; ++label) {
    const Rgb c = LabelRenderer::labelColor(static_cast<std::uint8_t>(label));
    EXPECT_EQ(*std::max_element(c.begin(), c.end()), 255) << label;
    EXPECT_EQ(*std::min_element(c.begin(), c.end()), 0) << label;
    EXPECT_TRUE(seen.insert(c).second) << "label " << label << " repeats a colour";
  }
}

TEST(LabelPalette, BlendMixesOriginalColourAtTheSetRatio)
{
  const Rgb grey = LabelRenderer::labelColor(dynvo::LABEL_STATIC);
  EXPECT_EQ(LabelRenderer::blendedColor(1, {10, 20, 30}, 0.0), grey);
  EXPECT_EQ(LabelRenderer::blendedColor(1, {10, 20, 30}, 1.0), (Rgb{10, 20, 30}));
  const Rgb half = LabelRenderer::blendedColor(1, {0, 0, 0}, 0.5);
  EXPECT_EQ(half[0], std::lround(grey[0] * 0.5));
}

TEST(LabelRendererContract, BadParametersThrow)
{
  LabelRenderer::Parameters p;
  p.rgb_blend = 1.5;
  EXPECT_THROW(LabelRenderer{p}, std::invalid_argument);
  p = {};
  p.point_size = 0.5;
  EXPECT_THROW(LabelRenderer{p}, std::invalid_argument);
  p = {};
  p.width = 0;
  EXPECT_THROW(LabelRenderer{p}, std::invalid_argument);
  p = {};
  p.frustum_depth = 0.0;
  LabelRenderer renderer;
  EXPECT_THROW(renderer.setParameters(p), std::invalid_argument);
  EXPECT_EQ(renderer.getParameters().frustum_depth,
            LabelRenderer::Parameters{}.frustum_depth);
}

TEST(LabelRendererContract, MismatchedOrEmptyInputWritesNothing)
{
  dynvo::test::TempDir dir;
  pcl::PointCloud<pcl::PointXYZRGB> cloud(4, 3);
  LabelRenderer renderer;
  const auto identity = Eigen::Isometry3d::Identity();
  EXPECT_FALSE(renderer.render(cloud, std::vector<std::uint8_t>(11, 1), identity, {},
                               dir.file("a.png")));
  EXPECT_FALSE(renderer.render(pcl::PointCloud<pcl::PointXYZRGB>{}, {}, identity, {},
                               dir.file("b.png")));
  EXPECT_FALSE(std::filesystem::exists(dir.file("a.png")));
  EXPECT_FALSE(std::filesystem::exists(dir.file("b.png")));
}

/// Points DISPLAY at a server that does not exist for the lifetime of the object.
class NoDisplay {
public:
  NoDisplay()
  {
    if (const char* old = std::getenv("DISPLAY"))
      saved_ = old;
    setenv("DISPLAY", ":65000", 1); // far above any display number xvfb-run -a picks
  }
  ~NoDisplay()
  {
    if (saved_.empty())
      unsetenv("DISPLAY");
    else
      setenv("DISPLAY", saved_.c_str(), 1);
  }

private:
  std::string saved_;
};

TEST(LabelRendererContract, WithoutDisplayRenderAndPlotReturnFalse)
{
  const NoDisplay no_display;
  std::string why;
  EXPECT_FALSE(dynvo::displayAvailable(&why));
  EXPECT_NE(why.find(":65000"), std::string::npos) << why;
  dynvo::test::TempDir dir;
  pcl::PointCloud<pcl::PointXYZRGB> cloud(4, 3);
  LabelRenderer renderer;
  for (int attempt = 0; attempt < 2;
       ++attempt) // the second call must not retry X either
    EXPECT_FALSE(renderer.render(cloud, std::vector<std::uint8_t>(12, 1),
                                 Eigen::Isometry3d::Identity(), {}, dir.file("x.png")));
  EXPECT_FALSE(
      dynvo::writeTrajectoryPlot({dynvo::StampedPose{}}, {}, dir.file("t.png")));
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
}

TEST_F(LabelledScene, CameraViewHasEachLabelColourAtItsProjectedPixel)
{
  DYNVO_SKIP_WITHOUT_DISPLAY();
  LabelRenderer renderer(params_);
  const cv::Mat image =
      renderAndRead(renderer, Eigen::Isometry3d::Identity(), {}, "cam.png");
  ASSERT_EQ(image.cols, 640);
  ASSERT_EQ(image.rows, 480);
  // Not blank: every pixel holds a valid point, so nothing may stay background black.
  int black = 0;
  for (int v = 0; v < image.rows; ++v)
    for (int u = 0; u < image.cols; ++u)
      black += pixel(image, u, v) == Rgb{0, 0, 0};
  EXPECT_EQ(black, 0);

  // One sample point per label, away from region borders; look within 2 px of where
  // the point projects (a wrong principal point or focal length would land elsewhere).
  const int samples[][2] = {{30, 30}, {600, 300}, {160, 150}, {450, 320}, {320, 440}};
  for (const auto& s : samples) {
    const std::size_t i = std::size_t(s[1]) * cloud_.width + s[0];
    const Eigen::Vector2f uv = params_.intrinsics.project(cloud_[i].getVector3fMap());
    int best = 255;
    for (int dv = -2; dv <= 2; ++dv)
      for (int du = -2; du <= 2; ++du)
        best = std::min(best, colourDistance(pixel(image, int(std::lround(uv.x())) + du,
                                                   int(std::lround(uv.y())) + dv),
                                             expected(i)));
    EXPECT_LE(best, COLOUR_ROUNDING)
        << "label " << int(labels_[i]) << " at " << s[0] << "," << s[1];
  }
}

TEST_F(LabelledScene, CameraViewLinesUpWithTheInputFromAnyPose)
{
  DYNVO_SKIP_WITHOUT_DISPLAY();
  LabelRenderer renderer(params_);
  double first_ms = 0.0;
  double later_ms = 0.0;
  const cv::Mat at_origin =
      renderAndRead(renderer, Eigen::Isometry3d::Identity(), {}, "a.png", &first_ms);
  // The same cloud seen from a different world pose must give the same picture.
  const cv::Mat posed = renderAndRead(renderer, somePose(), {}, "b.png", &later_ms);
  std::printf("[ timing ] 307200-point VGA camera view: first render %.1f ms, "
              "second %.1f ms (render + PNG)\n",
              first_ms, later_ms);
  RecordProperty("first_render_ms", std::to_string(first_ms));
  RecordProperty("later_render_ms", std::to_string(later_ms));
  ASSERT_FALSE(at_origin.empty());
  ASSERT_FALSE(posed.empty());

  for (const cv::Mat* image : {&at_origin, &posed})
    for (const std::uint8_t label : {std::uint8_t{2}, std::uint8_t{5}}) {
      // Centroid of the input mask versus centroid of the pixels showing that label's colour.
      Eigen::Vector2d mask_sum = Eigen::Vector2d::Zero();
      Eigen::Vector2d drawn_sum = Eigen::Vector2d::Zero();
      double mask_n = 0.0;
      double drawn_n = 0.0;
      for (int v = 0; v < image->rows; ++v)
        for (int u = 0; u < image->cols; ++u) {
          const std::size_t i = std::size_t(v) * cloud_.width + u;
          const Rgb as_label = LabelRenderer::blendedColor(
              label, {cloud_[i].r, cloud_[i].g, cloud_[i].b}, params_.rgb_blend);
          if (labels_[i] == label) {
            mask_sum += Eigen::Vector2d(u, v);
            ++mask_n;
          }
          if (colourDistance(pixel(*image, u, v), as_label) <= COLOUR_ROUNDING) {
            drawn_sum += Eigen::Vector2d(u, v);
            ++drawn_n;
          }
        }
      ASSERT_GT(drawn_n, 0.9 * mask_n) << "label " << int(label);
      // A one-pixel shift of the whole object moves the centroid by 1 px; registration
      // errors below that are rounding inside the driver.
      EXPECT_LT((mask_sum / mask_n - drawn_sum / drawn_n).norm(), 0.5)
          << "label " << int(label);
    }
  cv::Mat difference;
  cv::absdiff(at_origin, posed, difference);
  // Rounding of the world transform may flip a handful of pixels by one colour level.
  EXPECT_LT(cv::countNonZero(difference.reshape(1) > COLOUR_ROUNDING), 10);
}

TEST_F(LabelledScene, NaNPointsLeaveBackground)
{
  DYNVO_SKIP_WITHOUT_DISPLAY();
  for (int v = 0; v < 50; ++v)
    for (int u = 0; u < 50; ++u)
      cloud_[std::size_t(v) * cloud_.width + u].z =
          std::numeric_limits<float>::quiet_NaN();
  LabelRenderer renderer(params_);
  const cv::Mat image =
      renderAndRead(renderer, Eigen::Isometry3d::Identity(), {}, "nan.png");
  ASSERT_FALSE(image.empty());
  EXPECT_EQ(pixel(image, 25, 25), (Rgb{0, 0, 0}));
  EXPECT_LE(colourDistance(pixel(image, 60, 60), expected(60 * cloud_.width + 60)),
            COLOUR_ROUNDING);
}

TEST_F(LabelledScene, SceneViewsShowCloudTrajectoryAndFrustum)
{
  DYNVO_SKIP_WITHOUT_DISPLAY();
  params_.rgb_blend = 0.0; // pure palette colours, so labels can be counted in any view
  dynvo::Trajectory trajectory;
  for (int k = 0; k < 20; ++k) {
    dynvo::StampedPose pose;
    pose.timestamp = k / 30.0;
    pose.T_world_camera.translation() = Eigen::Vector3d(0.05 * k, 0.0, -0.03 * k);
    trajectory.push_back(pose);
  }
  for (const auto view : {dynvo::RenderView::oblique, dynvo::RenderView::top}) {
    params_.view = view;
    LabelRenderer renderer(params_);
    const cv::Mat image = renderAndRead(renderer, trajectory.back().T_world_camera,
                                        trajectory, "view.png");
    ASSERT_FALSE(image.empty());
    int white = 0;
    int box = 0;
    int disc = 0;
    int background = 0;
    for (int v = 0; v < image.rows; ++v)
      for (int u = 0; u < image.cols; ++u) {
        const Rgb c = pixel(image, u, v);
        white += c == Rgb{255, 255, 255};
        box += colourDistance(c, LabelRenderer::labelColor(2)) <= COLOUR_ROUNDING;
        disc += colourDistance(c, LabelRenderer::labelColor(5)) <= COLOUR_ROUNDING;
        background += c == Rgb{0, 0, 0};
      }
    const int view_id = static_cast<int>(view);
    // A 2-px polyline over 19 steps plus 8 frustum edges covers well over 50 pixels.
    EXPECT_GT(white, 50) << "view " << view_id;
    EXPECT_GT(box, 50) << "view " << view_id;
    EXPECT_GT(disc, 50) << "view " << view_id;
    // The whole scene is fitted into the view, so background must remain around it.
    EXPECT_GT(background, image.rows * image.cols / 20) << "view " << view_id;
  }
}

/// Bounding box of the pixels of one colour inside [x0, x1) x [0, rows).
cv::Rect
colourBox(
    const cv::Mat& image, const Rgb& colour, int x0, int x1, int tolerance, int* count)
{
  int left = x1, right = -1, top = image.rows, bottom = -1;
  *count = 0;
  for (int v = 0; v < image.rows; ++v)
    for (int u = x0; u < x1; ++u)
      if (colourDistance(pixel(image, u, v), colour) <= tolerance) {
        left = std::min(left, u);
        right = std::max(right, u);
        top = std::min(top, v);
        bottom = std::max(bottom, v);
        ++*count;
      }
  return *count ? cv::Rect(left, top, right - left + 1, bottom - top + 1) : cv::Rect();
}

TEST(TrajectoryPlot, CurvesAreInsideTheirPlotAreas)
{
  DYNVO_SKIP_WITHOUT_DISPLAY();
  // A 1 m circle in the x-z plane over 10 s; the ground truth is the same circle 5 cm
  // further along +x, so the error curve is flat at 0.05 m.
  dynvo::Trajectory estimate;
  dynvo::Trajectory groundtruth;
  for (int k = 0; k <= 300; ++k) {
    dynvo::StampedPose pose;
    pose.timestamp = 100.0 + k / 30.0;
    const double a = 2.0 * PI * k / 300.0;
    pose.T_world_camera.translation() = Eigen::Vector3d(std::cos(a), 0.0, std::sin(a));
    estimate.push_back(pose);
    pose.T_world_camera.translation().x() += 0.05;
    groundtruth.push_back(pose);
  }
  dynvo::test::TempDir dir;
  const dynvo::TrajectoryPlotOptions options;
  ASSERT_TRUE(
      dynvo::writeTrajectoryPlot(estimate, groundtruth, dir.file("plot.png"), options));
  const cv::Mat image = cv::imread(dir.file("plot.png"), cv::IMREAD_COLOR);
  ASSERT_EQ(image.cols, int(options.width));
  ASSERT_EQ(image.rows, int(options.height));

  // The two charts share the width. Anti-aliased line edges blend with the white
  // background, so a curve pixel is one within 40 levels of the curve colour.
  const int tolerance = 40;
  const int half = image.cols / 2;
  const int margin = 10; // a curve touching the chart edge would be clipped
  struct Curve {
    const char* name;
    Rgb colour;
    int x0, x1;
  };
  for (const Curve& curve :
       {Curve{"estimate path", options.estimate_color, 0, half},
        Curve{"ground-truth path", options.groundtruth_color, 0, half},
        Curve{"error curve", options.estimate_color, half, image.cols}}) {
    int count = 0;
    const cv::Rect box =
        colourBox(image, curve.colour, curve.x0, curve.x1, tolerance, &count);
    // A 2-px circle of at least 40% of a 640x480 chart is several hundred pixels long.
    EXPECT_GT(count, 200) << curve.name;
    EXPECT_GE(box.x, curve.x0 + margin) << curve.name;
    EXPECT_LE(box.x + box.width, curve.x1 - margin) << curve.name;
    EXPECT_GE(box.y, margin) << curve.name;
    EXPECT_LE(box.y + box.height, image.rows - margin) << curve.name;
    if (std::string(curve.name) != "error curve") {
      // Axes fitted to the data: the circle spans most of its chart.
      EXPECT_GT(box.width, 0.4 * half) << curve.name;
      EXPECT_GT(box.height, 0.4 * image.rows) << curve.name;
    }
  }
}

TEST(TrajectoryPlot, ObjectPathsAreDrawnInTheirLabelColours)
{
  DYNVO_SKIP_WITHOUT_DISPLAY();
  // The camera moves 1 m along x; object 2 crosses 1 m along z in front of it, object 3
  // (a second run of another id) moves 0.5 m along x further away.
  dynvo::Trajectory estimate, crossing, far;
  for (int k = 0; k <= 90; ++k) {
    const double t = k / 90.0;
    dynvo::StampedPose pose;
    pose.timestamp = 1.0 + k / 30.0;
    pose.T_world_camera.translation() = Eigen::Vector3d(t, 0.0, 0.0);
    estimate.push_back(pose);
    pose.T_world_camera.translation() = Eigen::Vector3d(0.5, 0.0, 1.0 + t);
    crossing.push_back(pose);
    pose.T_world_camera.translation() = Eigen::Vector3d(0.25 + 0.5 * t, 0.0, 2.5);
    far.push_back(pose);
  }
  dynvo::test::TempDir dir;
  const dynvo::TrajectoryPlotOptions options;
  ASSERT_TRUE(dynvo::writeTrajectoryPlot(estimate, {}, dir.file("plot.png"), options,
                                         {{2, crossing}, {3, far}}));
  const cv::Mat image = cv::imread(dir.file("plot.png"), cv::IMREAD_COLOR);
  ASSERT_EQ(image.cols, int(options.width));
  // Without ground truth the path chart takes the whole width, its legend (with a
  // sample of each colour) in the top-right corner. Each object's path is a line in its
  // label's palette colour: the crossing one vertical (along z), the far one horizontal
  // (along x) and above the crossing one (larger z).
  const int tolerance = 40; // anti-aliased line edges, as above
  const int left_of_legend = image.cols * 4 / 5;
  int count2 = 0, count3 = 0;
  const cv::Rect box2 = colourBox(image, dynvo::LabelRenderer::labelColor(2), 0,
                                  left_of_legend, tolerance, &count2);
  const cv::Rect box3 = colourBox(image, dynvo::LabelRenderer::labelColor(3), 0,
                                  left_of_legend, tolerance, &count3);
  // A 2-px line over a third of the chart is over a hundred pixels.
  EXPECT_GT(count2, 100);
  EXPECT_GT(count3, 100);
  EXPECT_GT(box2.height, 3 * box2.width) << box2;
  EXPECT_GT(box3.width, 3 * box3.height) << box3;
  EXPECT_LT(box3.y + box3.height, box2.y + 5); // image rows grow downwards
}

} // namespace
