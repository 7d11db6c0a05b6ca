// SPDX-License-Identifier: BSD-3-Clause
// dynvo_segment: per-pixel rigid-motion labels of an RGB-D sequence, from the odometry
// pipeline (the registration's ego-motion predicts the next frame's segmentation).
#include <dynvo/app/pipeline_args.h>

#include <cstdio>

namespace {

const char* const USAGE =
    "dynvo_segment (-tum_dir DIR | -pcd_dir DIR | -oni FILE) -out_dir LABELS "
    "[-objects FILE] [-objects_dir DIR] [-clouds_dir DIR] [options]";

const char* const ABOUT =
    "Labels every frame by rigid motion: 0 no measurement, 1 static background, 2.. "
    "moving objects.\nFrame 0 has no flow and is all 0. The labels are those of "
    "dynvo_odometry -labels_dir with the\nsame flags.";

} // namespace

int
main(int argc, char** argv)
{
  return dynvo::app::runApp(USAGE, [&] {
    const dynvo::app::Arguments args(
        argc, argv,
        dynvo::app::appOptions(
            dynvo::app::PipelineStages::all,
            {{"out_dir", "DIR",
              "folder for <rgb timestamp>.png label images (required)"}}));
    if (args.helpRequested()) {
      std::printf("%s", dynvo::app::appHelp(USAGE, ABOUT, args).c_str());
      return 0;
    }
    dynvo::app::setVerbosityFromArguments(args);
    const auto options = dynvo::app::pipelineOptionsFromArguments(args);
    if (dynvo::app::writeConfigIfRequested(args, options))
      return 0;
    if (!args.has("out_dir"))
      throw dynvo::app::UsageError("-out_dir DIR is required");
    const std::size_t max_frames = dynvo::app::maxFramesFromArguments(args);

    const auto paths =
        dynvo::app::runOutputPathsFromArguments(args, "", args.string("out_dir"));
    const auto source = dynvo::app::openFrameSource(args);
    dynvo::app::prepareRunOutputs(args, *source,
                                  {{"-out_dir", args.string("out_dir"), true}});
    dynvo::app::RunOutputs outputs(paths);
    // Whatever stops the run, the labels and objects of the frames done are kept.
    const auto end = dynvo::app::runPipeline(options, max_frames, *source, outputs, {},
                                             args.has("read_ahead"));
    end.report.printSummary();
    return end.loop.error.empty() ? 0 : 1;
  });
}
