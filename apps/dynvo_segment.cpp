// SPDX-License-Identifier: BSD-3-Clause
// dynvo_segment: per-pixel rigid-motion labels of an RGB-D sequence (scene flow + segmentation).
#include <dynvo/app/cli.h>
#include <dynvo/app/frame_source_args.h>
#include <dynvo/app/output_guard.h>
#include <dynvo/io/label_io.h>
#include <dynvo/io/partial_file.h>
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
#include <limits>
#include <memory>
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
    const long max_frames =
        args.integer("max_frames", 0, 1, std::numeric_limits<long>::max());
    const long threads = args.integer("threads", hardware_threads, 1, 256);
    const long seed = args.integer("seed", defaults.seed, 0, 4294967295L);

    const dynvo::CameraIntrinsics intrinsics =
        dynvo::app::intrinsicsFromArguments(args);
    const dynvo::FrameSource::Ptr source = dynvo::app::openFrameSource(args);
    const std::filesystem::path out_dir = args.string("out_dir");
    dynvo::app::prepareOutputs(
        {{"-out_dir", out_dir.string(), true}, {"-objects", args.string("objects")}},
        source->inputPaths());
    std::unique_ptr<dynvo::PartialFile> objects_file;
    std::ofstream objects;
    if (args.has("objects")) {
      objects_file = std::make_unique<dynvo::PartialFile>(args.string("objects"));
      objects.open(objects_file->partialPath());
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

    pcl::PointCloud<dynvo::PointFlow>::Ptr flow(new pcl::PointCloud<dynvo::PointFlow>);
    std::vector<pcl::PointIndices> segments;
    pcl::console::TicToc timer;
    double segment_ms = 0.0;
    long count = 0;
    // Whatever stops the run, the labels and objects of the frames done are kept.
    const auto end = dynvo::app::processFrames(
        *source, static_cast<std::size_t>(max_frames), [&](const dynvo::Frame& frame) {
          flow_estimation.shiftCurrentToPrevious();
          flow_estimation.setInputCloud(frame.cloud);
          const std::string path =
              (out_dir / dynvo::stampedPngName(frame.timestamp)).string();
          if (count++ == 0) {
            dynvo::writeLabelImage(path,
                                   dynvo::paintLabelImage({}, {}, frame.cloud->width,
                                                          frame.cloud->height));
            return;
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
            return;
          // Constant-velocity prediction for the next frame (identity until a
          // background exists).
          if (!segments[0].indices.empty())
            segmentation.setPredictedMotion(segmentation.getMotions()[0]);
          for (std::size_t s = 1; s < segments.size() && objects; ++s)
            objects << dynvo::formatObjectMotionLine(
                           frame.timestamp, segmentation.getSegmentLabels()[s],
                           segments[s].indices.size(), segmentation.getMotions()[s])
                    << '\n';
        });
    count = static_cast<long>(end.frames);
    if (objects_file && count > 0) {
      objects.close();
      if (!objects)
        throw pcl::IOException(args.string("objects") + ": write failed");
      objects_file->commit();
    }
    pcl::console::print_highlight("Labelled %ld frames into %s; segmentation ", count,
                                  out_dir.string().c_str());
    pcl::console::print_value("%.2f", count > 1 ? segment_ms / (count - 1) : 0.0);
    pcl::console::print_info(" ms per frame\n");
    return end.error.empty() ? 0 : 1;
  });
}
