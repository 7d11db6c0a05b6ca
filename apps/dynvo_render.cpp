// SPDX-License-Identifier: BSD-3-Clause
// dynvo_render: label-coloured PNGs of a finished run, and its trajectory plot.
#include <dynvo/app/cli.h>
#include <dynvo/app/frame_source_args.h>
#include <dynvo/app/object_trajectories.h>
#include <dynvo/app/output_guard.h>
#include <dynvo/common/timestamps.h>
#include <dynvo/eval/trajectory_metrics.h>
#include <dynvo/io/label_io.h>
#include <dynvo/io/trajectory_io.h>
#include <dynvo/vis/display.h>
#include <dynvo/vis/label_renderer.h>
#include <dynvo/vis/trajectory_plot.h>

#include <pcl/console/print.h>
#include <pcl/console/time.h>
#include <pcl/exceptions.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <numeric>
#include <set>
#include <sstream>
#include <stdexcept>

namespace {

namespace fs = std::filesystem;
using dynvo::app::UsageError;

const char* const USAGE = "dynvo_render (-tum_dir DIR | -pcd_dir DIR | -oni FILE) "
                          "-trajectory FILE -labels_dir DIR "
                          "-out_dir DIR [-groundtruth FILE] [-objects_dir DIR] "
                          "[-frames a,b,c | -every N] "
                          "[-view camera|oblique|top] "
                          "[-plot_plane xz|xy] [-blend B] [camera flags]";

/// A trajectory pose counts as a frame's pose within this many seconds: far above the
/// 1 us rounding of "%.6f" stamps, far below half a frame period (17 ms at 30 Hz).
constexpr double POSE_STAMP_TOLERANCE = 0.005;

std::set<long>
parseFrameList(const std::string& text)
{
  std::set<long> frames;
  std::stringstream stream(text);
  std::string item;
  while (std::getline(stream, item, ',')) {
    std::size_t used = 0;
    long index = -1;
    try {
      index = std::stol(item, &used);
    }
    catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != item.size() || index < 0)
      throw UsageError("-frames takes non-negative frame indices a,b,c; got '" + text +
                       "'");
    frames.insert(index);
  }
  if (frames.empty())
    throw UsageError("-frames is empty");
  return frames;
}

/// The label PNG of a frame (the cloud's size); empty when the file does not exist.
/// \throws pcl::IOException when it exists but is not such an image
std::vector<std::uint8_t>
readLabels(const std::string& path, const pcl::PointCloud<pcl::PointXYZRGB>& cloud)
{
  if (!fs::exists(path))
    return {};
  dynvo::LabelImage labels = dynvo::readLabelImage(path);
  if (labels.width != cloud.width || labels.height != cloud.height)
    throw pcl::IOException(path + ": expected a label image of " +
                           std::to_string(cloud.width) + "x" +
                           std::to_string(cloud.height));
  return std::move(labels.data);
}

/// "Rendered N frames into DIR: first X ms, later mean Y ms, max Z ms" (render + PNG write).
void
printSummary(const std::vector<double>& render_ms, const std::string& out_dir)
{
  pcl::console::print_highlight("Rendered ");
  pcl::console::print_value("%zu", render_ms.size());
  pcl::console::print_info(" frames into %s", out_dir.c_str());
  if (!render_ms.empty()) {
    pcl::console::print_info(": first ");
    pcl::console::print_value("%.1f ms", render_ms.front());
  }
  if (render_ms.size() > 1) {
    const double later = std::accumulate(render_ms.begin() + 1, render_ms.end(), 0.0);
    pcl::console::print_info(", later mean ");
    pcl::console::print_value("%.1f ms",
                              later / static_cast<double>(render_ms.size() - 1));
    pcl::console::print_info(", max ");
    pcl::console::print_value(
        "%.1f ms", *std::max_element(render_ms.begin() + 1, render_ms.end()));
  }
  pcl::console::print_info("\n");
}

} // namespace

int
main(int argc, char** argv)
{
  return dynvo::app::runApp(USAGE, [&] {
    const dynvo::LabelRenderer::Parameters defaults;
    auto options = dynvo::app::frameSourceOptions();
    options.insert(
        options.end(),
        {{"trajectory", "FILE", "estimated TUM trajectory of the run (required)"},
         {"labels_dir", "DIR", "label PNGs <stamp>.png of the run (required)"},
         {"out_dir", "DIR",
          "where <stamp>_<view>.png and trajectory.png go (required)"},
         {"groundtruth", "FILE",
          "TUM ground truth: adds it and the error curve to the plot"},
         {"objects_dir", "DIR",
          "object trajectories of the run (dynvo_odometry -objects_dir): adds their "
          "paths to the plot"},
         {"frames", "a,b,c", "frame indices to render (default: see -every)"},
         {"every", "N", "render every N-th frame (default 1)"},
         {"view", "camera|oblique|top", "viewpoint (default camera)"},
         {"plot_plane", "xz|xy",
          "top-down plane of the plot (default xz; xy for z-up ground truth)"},
         {"blend", "B",
          "share of the original RGB in each colour (default " +
              std::to_string(defaults.rgb_blend) + ")"}});
    const dynvo::app::Arguments args(argc, argv, options, 0);
    if (args.helpRequested()) {
      std::printf(
          "Usage: %s\n\nRenders the labelled clouds of a finished run off screen "
          "(needs an X display: use `xvfb-run -a` on a headless machine).\n\n%s",
          USAGE, args.optionsHelp().c_str());
      return 0;
    }
    for (const char* required : {"trajectory", "labels_dir", "out_dir"})
      if (!args.has(required))
        throw UsageError(std::string("-") + required + " is required");
    if (args.has("frames") && args.has("every"))
      throw UsageError("give -frames or -every, not both");
    const std::set<long> frames =
        args.has("frames") ? parseFrameList(args.string("frames")) : std::set<long>{};
    const long every = args.integer("every", 1);
    if (every < 1)
      throw UsageError("-every must be >= 1");
    dynvo::LabelRenderer::Parameters params;
    params.intrinsics = dynvo::app::intrinsicsFromArguments(args);
    params.rgb_blend = args.number("blend", defaults.rgb_blend);
    const std::string view = args.string("view", "camera");
    if (view == "oblique")
      params.view = dynvo::RenderView::oblique;
    else if (view == "top")
      params.view = dynvo::RenderView::top;
    else if (view != "camera")
      throw UsageError("-view must be camera, oblique or top, got '" + view + "'");
    dynvo::TrajectoryPlotOptions plot;
    const std::string plane = args.string("plot_plane", "xz");
    if (plane == "xy")
      plot.plane = dynvo::PlotPlane::xy;
    else if (plane != "xz")
      throw UsageError("-plot_plane must be xz or xy, got '" + plane + "'");
    try {
      params.validate();
    }
    catch (const std::invalid_argument& e) {
      throw UsageError(e.what());
    }

    dynvo::Trajectory estimate = dynvo::readTrajectory(args.string("trajectory"));
    const dynvo::Trajectory groundtruth =
        args.has("groundtruth") ? dynvo::readTrajectory(args.string("groundtruth"))
                                : dynvo::Trajectory{};
    std::vector<std::pair<int, dynvo::Trajectory>> objects;
    if (args.has("objects_dir"))
      for (auto& track :
           dynvo::app::readObjectsFolder(args.string("objects_dir")).objects)
        objects.emplace_back(track.id, std::move(track.poses));
    const auto source = dynvo::app::openFrameSource(args);
    const fs::path out_dir = args.string("out_dir");
    const fs::path labels_dir = args.string("labels_dir");
    auto inputs = source->inputPaths();
    inputs.insert(inputs.end(), {args.string("trajectory"), args.string("groundtruth"),
                                 labels_dir.string(), args.string("objects_dir")});
    dynvo::app::prepareOutputs({{"-out_dir", out_dir.string(), true}}, inputs);
    std::string reason;
    if (!dynvo::displayAvailable(&reason)) {
      pcl::console::print_warn(
          "No display (%s): no images written. Run under `xvfb-run -a` "
          "on a headless machine.\n",
          reason.c_str());
      return 0;
    }

    std::vector<double> stamps;
    for (const auto& pose : estimate)
      stamps.push_back(pose.timestamp);
    dynvo::LabelRenderer renderer;
    std::vector<double> render_ms;
    long index = -1;
    // Whatever stops the run, the frames rendered stay and the plot is still drawn.
    const auto end =
        dynvo::app::processFrames(*source, 0, [&](const dynvo::Frame& frame) {
          ++index;
          if (frames.empty() ? index % every != 0 : frames.count(index) == 0)
            return;
          const std::string stamp = dynvo::formatStamp(frame.timestamp);
          const std::size_t k =
              estimate.empty() ? 0 : dynvo::findClosestIndex(stamps, frame.timestamp);
          const auto labels =
              readLabels((labels_dir / (stamp + ".png")).string(), *frame.cloud);
          if (estimate.empty() ||
              std::abs(stamps[k] - frame.timestamp) > POSE_STAMP_TOLERANCE ||
              labels.empty()) {
            pcl::console::print_warn(
                "Frame %ld (%s): no %s; skipped.\n", index, stamp.c_str(),
                labels.empty() ? "label PNG" : "pose in the trajectory");
            return;
          }
          if (frame.cloud->isOrganized()) {
            params.width = frame.cloud->width;
            params.height = frame.cloud->height;
          }
          renderer.setParameters(params);
          const dynvo::Trajectory so_far(estimate.begin(), estimate.begin() + k + 1);
          const std::string image = (out_dir / (stamp + "_" + view + ".png")).string();
          pcl::console::TicToc timer;
          timer.tic();
          if (!renderer.render(*frame.cloud, labels, estimate[k].T_world_camera, so_far,
                               image))
            throw std::runtime_error(image + ": rendering failed");
          render_ms.push_back(timer.toc());
        });
    if (!groundtruth.empty() && !estimate.empty()) {
      // The objects are in the estimate's world: they move with it (a rigid map).
      const dynvo::Trajectory aligned =
          dynvo::alignToGroundTruth(groundtruth, estimate);
      const Eigen::Isometry3d T_aligned_estimate =
          aligned.front().T_world_camera * estimate.front().T_world_camera.inverse();
      for (auto& [id, object] : objects)
        for (auto& pose : object)
          pose.T_world_camera = T_aligned_estimate * pose.T_world_camera;
      estimate = aligned;
    }
    if (!estimate.empty() && !dynvo::writeTrajectoryPlot(
                                 estimate, groundtruth,
                                 (out_dir / "trajectory.png").string(), plot, objects))
      return 1;

    printSummary(render_ms, out_dir.string());
    return end.error.empty() ? 0 : 1;
  });
}
