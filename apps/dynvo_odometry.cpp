// SPDX-License-Identifier: BSD-3-Clause
// dynvo_odometry: camera trajectory, moving-object masks and object motions of a recording.
#include <dynvo/app/cli.h>
#include <dynvo/app/frame_source_args.h>
#include <dynvo/app/odometry_pipeline.h>
#include <dynvo/app/output_guard.h>
#include <dynvo/app/pipeline_config.h>
#include <dynvo/app/run_report.h>
#include <dynvo/eval/trajectory_metrics.h>
#include <dynvo/io/label_io.h>
#include <dynvo/io/trajectory_io.h>

#ifdef DYNVO_WITH_VTK
#include <dynvo/vis/display.h>
#include <dynvo/vis/label_renderer.h>
#include <dynvo/vis/trajectory_plot.h>
#endif

#include <pcl/console/print.h>

#include <cstdio>
#include <filesystem>
#include <limits>

namespace {

namespace fs = std::filesystem;
using dynvo::app::UsageError;

const char* const USAGE =
    "dynvo_odometry (-tum_dir DIR | -pcd_dir DIR | -oni FILE) [-out trajectory.txt] "
    "[-labels_dir DIR] [-objects FILE] [options]";

/// The default of a configuration key, as written in a -config file.
std::string
defaultOf(const std::string& key)
{
  return dynvo::app::pipelineConfigTable().field(key).text(
      dynvo::app::PipelineOptions());
}

std::vector<dynvo::app::Option>
options()
{
  auto list = dynvo::app::frameSourceOptions();
  list.insert(
      list.end(),
      {
          {"out", "FILE",
           "TUM trajectory to write (camera-to-world; first pose identity)"},
          {"init_gt", "",
           "start from the first ground-truth pose (needs groundtruth.txt)"},
          {"labels_dir", "DIR",
           "write <stamp>.png per frame: 0 none, 1 static, 2.. objects"},
          {"objects", "FILE",
           "write 'timestamp id n_pixels tx ty tz qx qy qz qw' per object"},
          {"max_frames", "N", "stop after N frames (default: all)"},
          {"threads", "N",
           "worker threads (default " + defaultOf("pipeline.threads") +
               "); results do not depend on it"},
          {"seed", "S",
           "hypothesis sampling seed (default " + defaultOf("segmentation.seed") + ")"},
          {"no_segmentation", "", "ablation: every valid flow cell counts as static"},
          {"refine", "none|icp|gicp",
           "refinement of the static registration (default " +
               defaultOf("registration.refinement") + ")"},
          {"render_dir", "DIR",
           "render label-coloured views and trajectory.png (needs X: xvfb-run -a)"},
          {"render_every", "N", "render every N-th frame (default 10)"},
          {"config", "FILE", "YAML with every parameter (see -write_config)"},
          {"write_config", "FILE",
           "write the effective configuration as YAML and exit"},
          {"v", "", "verbose (PCL debug messages)"},
          {"q", "", "quiet (errors only)"},
      });
  return list;
}

dynvo::app::PipelineOptions
pipelineOptions(const dynvo::app::Arguments& args)
{
  dynvo::app::PipelineOptions options;
  if (args.has("config"))
    dynvo::app::loadPipelineConfig(args.string("config"), options);
  options.intrinsics = dynvo::app::intrinsicsFromArguments(args);
  options.threads =
      static_cast<unsigned>(args.integer("threads", options.threads, 1, 256));
  options.segmentation.seed = static_cast<std::uint32_t>(
      args.integer("seed", options.segmentation.seed, 0, 4294967295L));
  if (args.has("no_segmentation"))
    options.use_segmentation = false;
  const auto& refinement =
      dynvo::app::pipelineConfigTable().field("registration.refinement");
  const std::string refine = args.string("refine", refinement.text(options));
  const int method = refinement.choiceIndex(refine);
  if (method < 0)
    throw UsageError("-refine must be none, icp or gicp, got '" + refine + "'");
  refinement.set(options, method);
  options.validate();
  return options;
}

/// Renders every N-th frame during the run and the trajectory plot at its end. Without a
/// display the renderer warns once and the run carries on without images.
class RunRenderer {
public:
  RunRenderer(const dynvo::app::Arguments& args,
              const dynvo::CameraIntrinsics& intrinsics)
      : dir_(args.string("render_dir"))
      , every_(args.integer("render_every", 10))
  {
    if (every_ < 1)
      throw UsageError("-render_every must be >= 1");
#ifdef DYNVO_WITH_VTK
    params_.intrinsics = intrinsics;
#else
    (void)intrinsics;
    if (!dir_.empty())
      throw UsageError("-render_dir: dynvo was built without VTK (DYNVO_WITH_VTK=OFF)");
#endif
  }

  void add(const dynvo::Frame& frame,
           const dynvo::app::FrameResult& result,
           const dynvo::Trajectory& trajectory)
  {
#ifdef DYNVO_WITH_VTK
    if (dir_.empty() || (trajectory.size() - 1) % every_ != 0)
      return;
    params_.width = frame.cloud->width;
    params_.height = frame.cloud->height;
    renderer_.setParameters(params_);
    const std::string name = dynvo::formatStamp(frame.timestamp);
    renderer_.render(*frame.cloud, result.labels, trajectory.back().T_world_camera,
                     trajectory, (fs::path(dir_) / (name + "_camera.png")).string());
#else
    (void)frame, (void)result, (void)trajectory;
#endif
  }

  void finish(const dynvo::Trajectory& estimate, const dynvo::Trajectory& groundtruth)
  {
#ifdef DYNVO_WITH_VTK
    // Without a display the renderer has already said so once.
    if (dir_.empty() || estimate.size() < 2 || !dynvo::displayAvailable())
      return;
    const std::string plot = (fs::path(dir_) / "trajectory.png").string();
    const auto aligned = groundtruth.empty()
                             ? estimate
                             : dynvo::alignToGroundTruth(groundtruth, estimate);
    if (dynvo::writeTrajectoryPlot(aligned, groundtruth, plot, {}))
      std::printf("rendered frames and %s\n", plot.c_str());
#else
    (void)estimate, (void)groundtruth;
#endif
  }

private:
  std::string dir_;
  long every_;
#ifdef DYNVO_WITH_VTK
  dynvo::LabelRenderer::Parameters params_;
  dynvo::LabelRenderer renderer_;
#endif
};

} // namespace

int
main(int argc, char** argv)
{
  return dynvo::app::runApp(USAGE, [&] {
    const dynvo::app::Arguments args(argc, argv, options());
    if (args.helpRequested()) {
      std::printf(
          "Usage: %s\n\n%s\nConfiguration keys (-config FILE) and defaults:\n%s", USAGE,
          args.optionsHelp().c_str(),
          dynvo::app::pipelineConfigHelp(dynvo::app::PipelineOptions()).c_str());
      return 0;
    }
    if (args.has("v"))
      pcl::console::setVerbosityLevel(pcl::console::L_DEBUG);
    if (args.has("q"))
      pcl::console::setVerbosityLevel(pcl::console::L_ERROR);
    const auto options = pipelineOptions(args);
    if (args.has("write_config")) {
      const std::string path = args.string("write_config");
      dynvo::app::prepareOutputs({{"-write_config", path}}, {args.string("config")});
      dynvo::app::writePipelineConfig(path, options);
      std::printf("wrote %s\n", path.c_str());
      return 0;
    }
    const long max_frames =
        args.integer("max_frames", 0, 0, std::numeric_limits<long>::max());

    const std::string groundtruth_path =
        args.has("tum_dir")
            ? (fs::path(args.string("tum_dir")) / "groundtruth.txt").string()
            : "";
    dynvo::Trajectory groundtruth;
    if (!groundtruth_path.empty() && fs::exists(groundtruth_path))
      groundtruth = dynvo::readTrajectory(groundtruth_path);
    if (args.has("init_gt") && groundtruth.empty())
      throw UsageError("-init_gt needs a -tum_dir folder with groundtruth.txt");

    auto source = dynvo::app::openFrameSource(args);
    auto inputs = source->inputPaths();
    inputs.push_back(args.string("config"));
    dynvo::app::prepareOutputs({{"-out", args.string("out")},
                                {"-labels_dir", args.string("labels_dir"), true},
                                {"-objects", args.string("objects")},
                                {"-render_dir", args.string("render_dir"), true}},
                               inputs);
    dynvo::app::RunOutputs outputs(args.string("out"), args.string("labels_dir"),
                                   args.string("objects"),
                                   args.has("init_gt") ? &groundtruth : nullptr);
    dynvo::app::OdometryPipeline pipeline(options);
    RunRenderer renderer(args, options.intrinsics);
    dynvo::app::RunReport report(max_frames > 0
                                     ? std::min<std::size_t>(max_frames, source->size())
                                     : source->size());
    // Whatever stops the run, what was computed is written below.
    const auto end = dynvo::app::processFrames(
        *source, static_cast<std::size_t>(max_frames), [&](const dynvo::Frame& frame) {
          const auto& result = pipeline.process(frame.cloud, frame.timestamp);
          outputs.add(result);
          renderer.add(frame, result, outputs.trajectory());
          report.add(result);
        });
    outputs.finish();
    renderer.finish(outputs.trajectory(), groundtruth);
    report.printSummary(groundtruth.empty() ? ""
                                            : dynvo::app::RunReport::accuracy(
                                                  groundtruth, outputs.trajectory()));
    return end.error.empty() ? 0 : 1;
  });
}
