// SPDX-License-Identifier: BSD-3-Clause
// dynvo_segment: per-pixel rigid-motion labels of an RGB-D sequence (scene flow + segmentation).
#include <dynvo/app/cli.h>
#include <dynvo/app/frame_source_args.h>
#include <dynvo/motion_segmentation/rigid_motion_segmentation.h>
#include <dynvo/scene_flow/grid_scene_flow_estimation.h>

#include <pcl/console/print.h>
#include <pcl/console/time.h>
#include <pcl/point_types.h>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

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

/// Writes the label image: 0 no measurement, 1 static, 2.. objects (uint8 PNG).
void
writeLabels(const std::string& path,
            const pcl::PointCloud<Point>& cloud,
            const std::vector<pcl::PointIndices>& segments,
            const std::vector<std::uint8_t>& labels)
{
  cv::Mat image(static_cast<int>(cloud.height), static_cast<int>(cloud.width), CV_8UC1,
                cv::Scalar(0));
  for (std::size_t s = 0; s < segments.size(); ++s)
    for (const int index : segments[s].indices)
      image.data[index] = labels[s];
  if (!cv::imwrite(path, image))
    throw std::runtime_error("cannot write " + path);
}

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
        throw std::runtime_error("cannot write " + args.string("objects"));
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
      char name[64];
      std::snprintf(name, sizeof(name), "%.6f.png", frame.timestamp);
      if (count == 0) {
        writeLabels((out_dir / name).string(), *frame.cloud, {}, {});
        continue;
      }
      flow_estimation.compute(*flow);
      segmentation.setInputCloud(frame.cloud);
      segmentation.setInputFlow(flow);
      timer.tic();
      segmentation.segment(segments);
      segment_ms += timer.toc();
      writeLabels((out_dir / name).string(), *frame.cloud, segments,
                  segmentation.getSegmentLabels());
      if (segments.empty())
        continue;
      // Constant-velocity prediction for the next frame (identity until a background exists).
      if (!segments[0].indices.empty())
        segmentation.setPredictedMotion(segmentation.getMotions()[0]);
      for (std::size_t s = 1; s < segments.size() && objects; ++s) {
        const Eigen::Matrix4f& T = segmentation.getMotions()[s];
        Eigen::Quaternionf q(T.topLeftCorner<3, 3>());
        q.normalize();
        if (q.w() < 0.0f)
          q.coeffs() = -q.coeffs();
        char line[256];
        std::snprintf(line, sizeof(line),
                      "%.6f %d %zu %.6f %.6f %.6f %.6f %.6f %.6f %.6f\n",
                      frame.timestamp, segmentation.getSegmentLabels()[s],
                      segments[s].indices.size(), T(0, 3), T(1, 3), T(2, 3), q.x(),
                      q.y(), q.z(), q.w());
        objects << line;
      }
    }
    pcl::console::print_highlight("Labelled %ld frames into %s; segmentation ", count,
                                  out_dir.string().c_str());
    pcl::console::print_value("%.2f", count > 1 ? segment_ms / (count - 1) : 0.0);
    pcl::console::print_info(" ms per frame\n");
    return 0;
  });
}
