// SPDX-License-Identifier: BSD-3-Clause
// dynvo_odometry: camera trajectory, moving-object masks and object motions of a recording.
#include <dynvo/app/pipeline_args.h>
#include <dynvo/app/reference_odometry.h>
#include <dynvo/eval/trajectory_metrics.h>
#include <dynvo/io/label_io.h>
#include <dynvo/io/trajectory_io.h>

#ifdef DYNVO_WITH_VTK
#include <dynvo/vis/display.h>
#include <dynvo/vis/label_renderer.h>
#include <dynvo/vis/trajectory_plot.h>
#endif

#include <cstdio>
#include <filesystem>

namespace {

namespace fs = std::filesystem;
using dynvo::app::UsageError;

const char* const USAGE =
    "dynvo_odometry (-tum_dir DIR | -pcd_dir DIR | -oni FILE) [-out trajectory.txt] "
    "[-labels_dir DIR] [-objects FILE] [-objects_dir DIR] [-clouds_dir DIR] [options]";

const char* const ABOUT =
    "Estimates the camera trajectory of a recording with the static scene only (scene "
    "flow -> rigid\nmotion segmentation -> static-only registration).";

std::vector<dynvo::app::Option>
options()
{
  return dynvo::app::appOptions(
      dynvo::app::PipelineStages::all,
      {
          {"out", "FILE",
           "TUM trajectory to write (camera-to-world; first pose identity)"},
          {"init_gt", "",
           "start from the first ground-truth pose (needs groundtruth.txt)"},
          {"labels_dir", "DIR",
           "write <stamp>.png per frame: 0 none, 1 static, 2.. objects"},
          {"render_dir", "DIR",
           "render label-coloured views and trajectory.png (needs X: xvfb-run -a)"},
          {"render_every", "N", "render every N-th frame (default 10)"},
          dynvo::app::referenceOdometryOption(),
      });
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
      std::printf("%s", dynvo::app::appHelp(USAGE, ABOUT, args).c_str());
      return 0;
    }
    dynvo::app::setVerbosityFromArguments(args);
    const auto options = dynvo::app::pipelineOptionsFromArguments(args);
    if (dynvo::app::writeConfigIfRequested(args, options))
      return 0;
    const std::size_t max_frames = dynvo::app::maxFramesFromArguments(args);
    const auto reference =
        dynvo::app::referenceOdometryFromArguments(args, options.intrinsics);

    const std::string groundtruth_path =
        args.has("tum_dir")
            ? (fs::path(args.string("tum_dir")) / "groundtruth.txt").string()
            : "";
    dynvo::Trajectory groundtruth;
    if (!groundtruth_path.empty() && fs::exists(groundtruth_path))
      groundtruth = dynvo::readTrajectory(groundtruth_path);
    if (args.has("init_gt") && groundtruth.empty())
      throw UsageError("-init_gt needs a -tum_dir folder with groundtruth.txt");

    const auto paths = dynvo::app::runOutputPathsFromArguments(
        args, args.string("out"), args.string("labels_dir"));
    auto source = dynvo::app::openFrameSource(args);
    dynvo::app::prepareRunOutputs(args, *source,
                                  {{"-out", args.string("out")},
                                   {"-labels_dir", args.string("labels_dir"), true},
                                   {"-render_dir", args.string("render_dir"), true}});
    dynvo::app::RunOutputs outputs(paths, args.has("init_gt") ? &groundtruth : nullptr);
    RunRenderer renderer(args, options.intrinsics);
    // Whatever stops the run, what was computed is written.
    const auto end = dynvo::app::runPipeline(
        options, max_frames, *source, outputs,
        [&](const dynvo::Frame& frame, const dynvo::app::FrameResult& result) {
          renderer.add(frame, result, outputs.trajectory());
          if (reference) // timed on its own, after the pipeline's frame
            reference->add(frame);
        },
        args.has("read_ahead"));
    renderer.finish(outputs.trajectory(), groundtruth);
    end.report.printSummary(
        groundtruth.empty()
            ? ""
            : dynvo::app::RunReport::accuracy(groundtruth, outputs.trajectory()));
    if (reference)
      reference->printSummary(end.report.medianMs(), groundtruth);
    return end.loop.error.empty() ? 0 : 1;
  });
}
