// SPDX-License-Identifier: BSD-3-Clause
// dynvo_segment: per-pixel rigid-motion labels of an RGB-D sequence (scene flow + segmentation).
#include <dynvo/app/cli.h>
#include <dynvo/app/frame_source_args.h>
#include <dynvo/io/label_io.h>
#include <dynvo/motion_segmentation/rigid_motion_segmentation.h>
#include <dynvo/scene_flow/grid_scene_flow_estimation.h>

#include <pcl/console/print.h>
#include <pcl/console/time.h>
#include <pcl/exceptions.h>
#include <pcl/point_types.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <thread>

namespace {

const char* const USAGE =
    "dynvo_segment (-tum_dir DIR | -pcd_dir DIR | -oni FILE) -out_dir LABELS "
    "[-no_tracking] [-max_frames N] [-objects FILE] [-threads N] [-seed S]";

using Point = pcl::PointXYZRGB;

} // namespace

int
main(int argc, char** argv)
{
  return dynvo::app::runApp(USAGE, [&] {
    const dynvo::RigidMotionSegmentationParameters defaults;
    const long hardware_threads = std::max(1U, std::thread::hardware_concurrency());
    std::vector<dynvo::app::Option> options = dynvo::app::frameSourceOptions();
    options.insert(
        options.end(),
        {{"out_dir", "DIR", "folder for <rgb timestamp>.png label images (required)"},
         {"no_tracking", "",
          "write the two-frame segments (ids per frame) instead of tracked ids"},
         {"max_frames", "N", "stop after N frames (default: all)"},
         {"objects", "FILE",
          "write 'timestamp id n_pixels tx ty tz qx qy qz qw' per object"},
         {"threads", "N",
          "worker threads (default: hardware count, " +
              std::to_string(hardware_threads) + ")"},
         {"seed", "S",
          "hypothesis sampling seed (default " + std::to_string(defaults.seed) + ")"},
         {"v", "", "verbose (PCL debug messages)"},
         {"q", "", "quiet (errors only)"}});
    const dynvo::app::Arguments args(argc, argv, options, 0);
    if (args.helpRequested()) {
      std::printf(
          "Usage: %s\n\nLabels every frame by rigid motion: 0 no measurement, 1 static "
          "background, 2.. moving objects.\nFrame 0 has no flow and is all 0.\n\n%s",
          USAGE, args.optionsHelp().c_str());
      return 0;
    }
    if (args.has("v"))
      pcl::console::setVerbosityLevel(pcl::console::L_DEBUG);
    if (args.has("q"))
      pcl::console::setVerbosityLevel(pcl::console::L_ERROR);
    if (!args.has("out_dir"))
      throw dynvo::app::UsageError("-out_dir DIR is required");
    const long max_frames = args.integer("max_frames", -1);
    const long threads = args.integer("threads", hardware_threads);
    const long seed = args.integer("seed", defaults.seed);
    if (threads < 1 || seed < 0 || seed > 4294967295L || max_frames == 0 ||
        max_frames < -1)
      throw dynvo::app::UsageError(
          "-threads must be >= 1, -seed in [0, 2^32), -max_frames >= 1");

    const dynvo::CameraIntrinsics intrinsics =
        dynvo::app::intrinsicsFromArguments(args);
    const dynvo::FrameSource::Ptr source = dynvo::app::openFrameSource(args);
    const std::filesystem::path out_dir = args.string("out_dir");
    std::filesystem::create_directories(out_dir);
    std::ofstream objects;
    if (args.has("objects")) {
      objects.open(args.string("objects"));
      if (!objects)
        throw pcl::IOException(args.string("objects") + ": cannot write objects file");
    }

    dynvo::GridSceneFlowEstimation<Point> flow_estimation;
    flow_estimation.setCameraIntrinsics(intrinsics);
    flow_estimation.setNumberOfThreads(static_cast<unsigned>(threads));
    dynvo::RigidMotionSegmentation<Point> segmentation;
    segmentation.setCameraIntrinsics(intrinsics);
    segmentation.setNumberOfThreads(static_cast<unsigned>(threads));
    segmentation.setSeed(static_cast<std::uint32_t>(seed));
    segmentation.setTracking(!args.has("no_tracking"));
    flow_estimation.setCellSize(segmentation.getCellSize());

    pcl::PointCloud<dynvo::PointFlow>::Ptr flow(new pcl::PointCloud<dynvo::PointFlow>);
    std::vector<pcl::PointIndices> segments;
    dynvo::Frame frame;
    pcl::console::TicToc timer;
    double segment_ms = 0.0;
    long count = 0;
    for (; (max_frames < 0 || count < max_frames) && source->next(frame); ++count) {
      flow_estimation.shiftCurrentToPrevious();
      flow_estimation.setInputCloud(frame.cloud);
      const std::string path =
          (out_dir / dynvo::stampedPngName(frame.timestamp)).string();
      if (count == 0) {
        dynvo::writeLabelImage(path, dynvo::paintLabelImage({}, {}, frame.cloud->width,
                                                            frame.cloud->height));
        continue;
      }
      flow_estimation.compute(*flow);
      segmentation.setInputCloud(frame.cloud);
      segmentation.setInputFlow(flow);
      timer.tic();
      segmentation.segment(segments);
      segment_ms += timer.toc();
      dynvo::writeLabelImage(
          path, dynvo::paintLabelImage(segments, segmentation.getSegmentLabels(),
                                       frame.cloud->width, frame.cloud->height));
      if (segments.empty())
        continue;
      // Constant-velocity prediction for the next frame (identity until a background exists).
      if (!segments[0].indices.empty())
        segmentation.setPredictedMotion(segmentation.getMotions()[0]);
      for (std::size_t s = 1; s < segments.size() && objects; ++s)
        objects << dynvo::formatObjectMotionLine(
                       frame.timestamp, segmentation.getSegmentLabels()[s],
                       segments[s].indices.size(), segmentation.getMotions()[s])
                << '\n';
    }
    pcl::console::print_highlight("Labelled %ld frames into %s; segmentation ", count,
                                  out_dir.string().c_str());
    pcl::console::print_value("%.2f", count > 1 ? segment_ms / (count - 1) : 0.0);
    pcl::console::print_info(" ms per frame\n");
    return 0;
  });
}
