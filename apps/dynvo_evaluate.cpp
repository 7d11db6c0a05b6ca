// SPDX-License-Identifier: BSD-3-Clause
// dynvo_evaluate GT EST: RPE and ATE of an estimated TUM trajectory against ground truth.
// dynvo_evaluate -labels PRED_DIR -truth SEQ_DIR: segmentation scores of label PNGs.
// dynvo_evaluate -objects_dir DIR -truth SEQ_DIR: RPE of object trajectories.
#include <dynvo/app/cli.h>
#include <dynvo/app/object_trajectories.h>
#include <dynvo/app/segmentation_evaluation.h>
#include <dynvo/eval/label_metrics.h>
#include <dynvo/eval/trajectory_metrics.h>
#include <dynvo/io/trajectory_io.h>

#include <pcl/console/print.h>

#include <algorithm>
#include <cstdio>
#include <stdexcept>
#include <string>

namespace {

const char* const USAGE =
    "dynvo_evaluate GROUNDTRUTH ESTIMATE [-delta D] [-delta_unit s|f] [-json]\n"
    "       dynvo_evaluate -labels PRED_DIR -truth SEQ_DIR [-json]\n"
    "       dynvo_evaluate -objects_dir DIR -truth SEQ_DIR [-json]";

const char* const SEGMENTATION_HELP =
    "predicted labels (0 none, 1 static, 2.. objects) against SEQ_DIR/labels\n"
    "(0 static, k moving object k), on pixels with valid depth, frames paired by\n"
    "stamp within 0.005 s. Prints moving_iou static_precision static_recall\n"
    "labelled bg_ok id_switch_rate frames; without SEQ_DIR/labels (a static\n"
    "recording) moving_share labelled frames. Definitions: README.md, dynvo_evaluate.";

const char* const OBJECTS_HELP =
    "object_<id>.txt of a dynvo_odometry -objects_dir folder against the\n"
    "true objects of a synthetic SEQ_DIR (objects.txt, groundtruth.txt). Each object "
    "is\n"
    "moved into the true world by the camera at its first frame, matched to the true\n"
    "object whose origin is nearest on average (within 0.5 m), and scored by the\n"
    "translational RPE (1 s pairs, m/s) of the path of its frame's origin, a fixed "
    "point\n"
    "of the object. Definitions: README.md, dynvo_evaluate.";

/// -labels and -objects_dir select the modes that take no positional arguments.
bool
hasFlag(int argc, char** argv, const std::string& flag)
{
  return std::any_of(argv + 1, argv + argc, [&](const char* token) {
    return token == flag;
  });
}

/// Refuses -delta and -delta_unit (trajectory mode only) and a missing -truth.
void
checkFolderMode(const dynvo::app::Arguments& args, const std::string& mode)
{
  if (!args.has("truth"))
    throw dynvo::app::UsageError("-" + mode + " needs -truth SEQ_DIR");
  for (const char* trajectory_only : {"delta", "delta_unit"})
    if (args.has(trajectory_only))
      throw dynvo::app::UsageError(std::string("-") + trajectory_only +
                                   " applies to trajectories, not to -" + mode);
}

/// The segmentation mode: scores of -labels against -truth.
int
evaluateLabels(const dynvo::app::Arguments& args)
{
  checkFolderMode(args, "labels");
  const dynvo::SegmentationEvaluation result =
      dynvo::app::evaluateSegmentation(args.string("labels"), args.string("truth"));
  if (result.scores.frames < result.sequence_frames)
    pcl::console::print_warn(
        "Warning: %zu of %zu frames of %s have no label PNG within %.3f s in %s; "
        "they are not scored\n",
        result.sequence_frames - result.scores.frames, result.sequence_frames,
        args.string("truth").c_str(),
        dynvo::SegmentationEvaluationOptions{}.max_difference,
        args.string("labels").c_str());
  std::printf("%s\n",
              dynvo::formatSegmentationScores(result, args.has("json")).c_str());
  return 0;
}

/// The object mode: object trajectories of -objects_dir against -truth.
int
evaluateObjects(const dynvo::app::Arguments& args)
{
  checkFolderMode(args, "objects_dir");
  if (args.has("labels"))
    throw dynvo::app::UsageError("give -labels or -objects_dir, not both");
  const auto scores =
      dynvo::app::evaluateObjects(args.string("objects_dir"), args.string("truth"));
  std::printf("%s\n", dynvo::app::formatObjectScores(scores, args.has("json")).c_str());
  return 0;
}

} // namespace

int
main(int argc, char** argv)
{
  return dynvo::app::runApp(USAGE, [&] {
    const dynvo::RpeOptions defaults;
    const bool labels = hasFlag(argc, argv, "-labels");
    const bool objects = hasFlag(argc, argv, "-objects_dir");
    const dynvo::app::Arguments args(
        argc, argv,
        {{"delta", "D", "RPE pair spacing (default 1)"},
         {"delta_unit", "s|f", "unit of -delta: seconds or frames (default s)"},
         {"json", "", "print the result as one JSON object"},
         {"labels", "DIR",
          "predicted label PNGs <stamp>.png (dynvo_odometry -labels_dir)"},
         {"objects_dir", "DIR", "object trajectories (dynvo_odometry -objects_dir)"},
         {"truth", "DIR",
          "sequence folder scored against (labels/, depth.txt, rgb.txt; objects.txt, "
          "groundtruth.txt)"}},
        labels || objects ? 0 : 2);
    if (args.helpRequested()) {
      std::printf(
          "Usage: %s\n\nRelative pose error as TUM evaluate_rpe.py --fixed_delta "
          "and absolute trajectory error as evaluate_ate.py.\nBoth files are TUM "
          "trajectories (timestamp tx ty tz qx qy qz qw, camera-to-world).\n\n%s",
          USAGE, args.optionsHelp().c_str());
      std::printf("\nWith -labels: %s\n", SEGMENTATION_HELP);
      std::printf("\nWith -objects_dir: %s\n", OBJECTS_HELP);
      return 0;
    }
    if (objects)
      return evaluateObjects(args);
    if (labels)
      return evaluateLabels(args);
    if (args.has("truth"))
      throw dynvo::app::UsageError("-truth needs -labels PRED_DIR or -objects_dir DIR");
    dynvo::RpeOptions options;
    options.delta = args.number("delta", defaults.delta);
    if (!(options.delta > 0.0))
      throw dynvo::app::UsageError("-delta must be positive");
    const std::string unit = args.string("delta_unit", "s");
    if (unit == "f")
      options.unit = dynvo::DeltaUnit::frames;
    else if (unit != "s")
      throw dynvo::app::UsageError("-delta_unit must be s or f, got '" + unit + "'");

    const auto read = [](const std::string& path) {
      auto trajectory = dynvo::readTrajectory(path);
      if (trajectory.size() < 2)
        throw std::runtime_error(path + ": holds " + std::to_string(trajectory.size()) +
                                 " pose(s); at least 2 are needed");
      return trajectory;
    };
    const auto groundtruth = read(args.positional()[0]);
    const auto estimate = read(args.positional()[1]);
    const dynvo::RpeResult rpe = dynvo::computeRpe(groundtruth, estimate, options);
    const dynvo::AteResult ate = dynvo::computeAte(groundtruth, estimate);
    std::printf("%s\n", dynvo::formatMetrics(rpe, ate, args.has("json")).c_str());
    return 0;
  });
}
