// SPDX-License-Identifier: BSD-3-Clause
// dynvo_scene_flow: grid scene flow between frames I-1 and I of a recording, saved as PCD.
#include <dynvo/app/pipeline_args.h>
#include <dynvo/io/partial_file.h>
#include <dynvo/scene_flow/grid_scene_flow_estimation.h>

#include <pcl/console/print.h>
#include <pcl/console/time.h>
#include <pcl/io/pcd_io.h>
#include <pcl/point_types.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cstdio>
#include <string>

namespace {

const char* const USAGE =
    "dynvo_scene_flow (-tum_dir DIR | -pcd_dir DIR | -oni FILE) -frame I -out flow.pcd "
    "[-png flow.png] [options]";

const char* const ABOUT =
    "Computes the grid scene flow (docs/algorithm.md section 1) between two "
    "consecutive "
    "frames, with\nthe scene flow parameters of dynvo_odometry. In the PCD, x y z is "
    "the "
    "current point and prev_x\nprev_y prev_z the previous one (metres).";

/// Draws each cell's 2D track over the current colour image and writes it as PNG.
void
writeTrackImage(const std::string& path,
                const dynvo::ColorImage& color,
                const pcl::PointCloud<dynvo::PointFlow>& flow)
{
  cv::Mat rgb(static_cast<int>(color.height), static_cast<int>(color.width), CV_8UC3,
              const_cast<std::uint8_t*>(color.data.data()));
  cv::Mat image;
  cv::cvtColor(rgb, image, cv::COLOR_RGB2BGR);
  for (const dynvo::PointFlow& f : flow) {
    const cv::Point2f c(f.u, f.v);
    if (!f.valid_2d) {
      cv::circle(image, c, 2, cv::Scalar(0, 0, 255), cv::FILLED, cv::LINE_AA);
      continue;
    }
    // Green: 2D and 3D valid; yellow: tracked but no usable depth.
    const cv::Scalar colour =
        f.valid_3d ? cv::Scalar(0, 255, 0) : cv::Scalar(0, 255, 255);
    cv::line(image, c, cv::Point2f(f.prev_u, f.prev_v), colour, 1, cv::LINE_AA);
    cv::circle(image, c, 2, colour, cv::FILLED, cv::LINE_AA);
  }
  std::vector<std::uint8_t> png;
  if (!cv::imencode(".png", image, png))
    throw std::runtime_error(path + ": cannot encode the track image");
  dynvo::replaceFile(path, std::string(png.begin(), png.end()));
}

} // namespace

int
main(int argc, char** argv)
{
  return dynvo::app::runApp(USAGE, [&] {
    const auto text = [](auto value) {
      return std::to_string(value);
    };
    const dynvo::app::Arguments args(
        argc, argv,
        dynvo::app::appOptions(
            dynvo::app::PipelineStages::scene_flow,
            {{"frame", "I", "flow from frame I-1 to frame I, 0-based (required, >= 1)"},
             {"out", "FILE", "PointFlow grid written as binary PCD (required)"},
             {"png", "FILE", "also draw the 2D tracks over frame I"}}));
    if (args.helpRequested()) {
      std::printf("%s", dynvo::app::appHelp(USAGE, ABOUT, args).c_str());
      return 0;
    }
    dynvo::app::setVerbosityFromArguments(args);
    const auto options = dynvo::app::pipelineOptionsFromArguments(args);
    if (dynvo::app::writeConfigIfRequested(args, options))
      return 0;
    if (!args.has("frame") || !args.has("out"))
      throw dynvo::app::UsageError("-frame I and -out FILE are required");
    const long frame_index = args.integer("frame", 0);
    if (frame_index < 1)
      throw dynvo::app::UsageError("-frame must be >= 1, got " + text(frame_index));

    // Configured as OdometryPipeline configures its scene flow.
    dynvo::GridSceneFlowEstimation<pcl::PointXYZRGB> estimation;
    estimation.setCameraIntrinsics(options.intrinsics);
    estimation.setParameters(options.scene_flow);
    estimation.setNumberOfThreads(options.threads);

    const dynvo::FrameSource::Ptr source = dynvo::app::openFrameSource(args);
    dynvo::app::prepareRunOutputs(
        args, *source, {{"-out", args.string("out")}, {"-png", args.string("png")}});
    dynvo::Frame previous, current;
    for (long k = 0; k <= frame_index; ++k) {
      std::swap(previous, current);
      if (!source->next(current))
        throw std::runtime_error("the recording has only " + text(k) +
                                 " frames, need " + text(frame_index + 1));
    }
    estimation.setPreviousCloud(previous.cloud);
    estimation.setInputCloud(current.cloud);
    pcl::PointCloud<dynvo::PointFlow> flow;
    pcl::console::TicToc timer;
    timer.tic();
    estimation.compute(flow);
    const double milliseconds = timer.toc();
    if (flow.empty())
      throw std::runtime_error("no flow between " + previous.name + " and " +
                               current.name);

    dynvo::PartialFile pcd(args.string("out"));
    if (pcl::io::savePCDFileBinary(pcd.partialPath(), flow) != 0)
      throw std::runtime_error(pcd.path() + ": cannot write the flow PCD");
    pcd.commit();
    if (args.has("png"))
      writeTrackImage(args.string("png"), current.color, flow);
    const auto count = [&](auto member) {
      return std::count_if(flow.begin(), flow.end(), [&](const dynvo::PointFlow& f) {
        return f.*member != 0;
      });
    };
    pcl::console::print_highlight("Flow %s -> %s: %ux%u cells, ", previous.name.c_str(),
                                  current.name.c_str(), flow.width, flow.height);
    pcl::console::print_value("%ld",
                              static_cast<long>(count(&dynvo::PointFlow::valid_2d)));
    pcl::console::print_info(" tracked, ");
    pcl::console::print_value("%ld",
                              static_cast<long>(count(&dynvo::PointFlow::valid_3d)));
    pcl::console::print_info(" with 3D, in ");
    pcl::console::print_value("%.2f", milliseconds);
    pcl::console::print_info(" ms (%u thread(s), both frames prepared)\n",
                             options.threads);
    return 0;
  });
}
