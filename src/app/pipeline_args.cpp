// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/app/pipeline_args.h>
#include <dynvo/app/pipeline_config.h>

#include <pcl/console/print.h>

#include <algorithm>
#include <cstdio>
#include <limits>
#include <stdexcept>

namespace dynvo::app {

namespace {

/// A flag that sets a configuration key (pipelineConfigTable()) to the value given.
struct ParameterFlag {
  std::string name; ///< without the dash
  /// the key; it gives kind, range and default (a boolean key makes the flag a switch that
  /// sets the key to 0)
  std::string key;
  std::string value_name; ///< e.g. "PX"; "" for a choice (its names) or a switch
  std::string help;       ///< what it sets; the default and the keys are added
  PipelineStages stages;  ///< the widest part of the pipeline that has it
};

/// The parameter flags, in help order.
const std::vector<ParameterFlag>&
parameterFlags()
{
  using S = PipelineStages;
  static const std::vector<ParameterFlag> flags{
      {"threads", "pipeline.threads", "N",
       "worker threads; results do not depend on it", S::scene_flow},
      {"cell_size", "scene_flow.cell_size", "PX", "grid cell size", S::scene_flow},
      {"window_size", "scene_flow.window_size", "PX", "LK window side", S::scene_flow},
      {"max_pyramid_level", "scene_flow.max_pyramid_level", "L",
       "LK pyramid levels above the image", S::scene_flow},
      {"fb_check", "scene_flow.forward_backward_check", "", "forward-backward scheme",
       S::scene_flow},
      {"seed", "segmentation.seed", "S", "hypothesis sampling seed", S::all},
      {"no_tracking", "segmentation.tracking", "",
       "two-frame segments (ids per frame) instead of tracked ids", S::all},
      {"no_segmentation", "pipeline.use_segmentation", "",
       "ablation: every valid flow cell counts as static, no object labels", S::all},
      {"no_keyframes", "pipeline.keyframes", "",
       "frame-to-frame registration only, no keyframe", S::all},
      {"backend", "registration.backend", "",
       "ego-motion method on the static mask, from the flow estimate", S::all},
  };
  return flags;
}

bool
takes(PipelineStages app, PipelineStages flag)
{
  return app == PipelineStages::all || flag == PipelineStages::scene_flow;
}

const FieldInfo<PipelineOptions>&
fieldOf(const ParameterFlag& flag)
{
  return pipelineConfigTable().field(flag.key);
}

/// "flow|cv_rgbd|icp|gicp" for a choice, else the flag's own value name.
std::string
valueName(const ParameterFlag& flag)
{
  const auto& field = fieldOf(flag);
  if (field.kind != FieldKind::choice)
    return flag.value_name;
  std::string names;
  for (const auto& choice : field.choices)
    names += (names.empty() ? "" : "|") + choice;
  return names;
}

Option
optionOf(const ParameterFlag& flag)
{
  const std::string& keys = flag.key;
  const bool is_switch = fieldOf(flag).kind == FieldKind::boolean;
  return {flag.name, is_switch ? "" : valueName(flag),
          flag.help + (is_switch
                           ? " (sets " + keys + " to 0)"
                           : " (default " + fieldOf(flag).text(PipelineOptions()) +
                                 "; " + keys + ")")};
}

/// The value of a given flag, checked against its key's range.
double
flagValue(const Arguments& args, const ParameterFlag& flag)
{
  const auto& field = fieldOf(flag);
  const std::string dash = "-" + flag.name;
  switch (field.kind) {
  case FieldKind::boolean:
    return 0.0;
  case FieldKind::choice: {
    const int index = field.choiceIndex(args.string(flag.name));
    if (index < 0)
      throw UsageError(dash + " must be " + valueName(flag) + ", got '" +
                       args.string(flag.name) + "'");
    return index;
  }
  case FieldKind::integer:
  case FieldKind::real:
    break;
  }
  const double value = field.kind == FieldKind::integer
                           ? static_cast<double>(args.integer(flag.name, 0))
                           : args.number(flag.name, 0.0);
  if (!field.range.contains(value))
    throw UsageError(dash + " must be " + field.range.describe() + ", got " +
                     args.string(flag.name));
  const std::string problem = field.problem(value);
  if (!problem.empty())
    throw UsageError(dash + " " + problem);
  return value;
}

} // namespace

std::vector<Option>
appOptions(PipelineStages stages, std::vector<Option> own)
{
  std::vector<Option> options = frameSourceOptions();
  options.insert(options.end(), own.begin(), own.end());
  options.push_back(
      {"config", "FILE", "YAML with every parameter (see -write_config)"});
  options.push_back(
      {"write_config", "FILE", "write the effective configuration as YAML and exit"});
  for (const ParameterFlag& flag : parameterFlags())
    if (takes(stages, flag.stages))
      options.push_back(optionOf(flag));
  if (stages == PipelineStages::all) {
    options.push_back({"max_frames", "N", "stop after N frames (default 0 = all)"});
    options.push_back({"read_ahead", "",
                       "read the next frame on a thread of its own: a shorter run, "
                       "longer frames on two cores"});
    options.push_back(
        {"objects", "FILE",
         "write 'timestamp id n_pixels tx ty tz qx qy qz qw' per object"});
    options.push_back({"objects_dir", "DIR",
                       "write object_<id>.txt (object-to-world), camera.txt and "
                       "objects_summary.txt"});
    options.push_back(
        {"clouds_dir", "DIR",
         "write <stamp>.pcd per frame: PointXYZRGBL, label as in the PNGs"});
    options.push_back(
        {"clouds_every", "N", "write the cloud of every N-th frame (default 1)"});
    options.push_back(
        {"frames_report", "FILE",
         "write one TSV line per frame: stamp, lost and why, static cells, "
         "residual, keyframe, moving share, ms per stage"});
  }
  options.push_back({"v", "", "verbose (PCL debug messages)"});
  options.push_back({"q", "", "quiet (errors only)"});
  return options;
}

std::string
appHelp(const std::string& usage, const std::string& about, const Arguments& args)
{
  return "Usage: " + usage + "\n\n" + about + "\n\n" + args.optionsHelp() +
         "\nConfiguration keys (-config FILE) and defaults:\n" +
         pipelineConfigHelp(PipelineOptions());
}

void
setVerbosityFromArguments(const Arguments& args)
{
  if (args.has("v"))
    pcl::console::setVerbosityLevel(pcl::console::L_DEBUG);
  if (args.has("q"))
    pcl::console::setVerbosityLevel(pcl::console::L_ERROR);
}

PipelineOptions
pipelineOptionsFromArguments(const Arguments& args)
{
  PipelineOptions options;
  if (args.has("config"))
    loadPipelineConfig(args.string("config"), options);
  options.intrinsics = intrinsicsFromArguments(args);
  for (const ParameterFlag& flag : parameterFlags()) {
    if (!args.has(flag.name))
      continue;
    const double value = flagValue(args, flag);
    pipelineConfigTable().field(flag.key).set(options, value);
  }
  try {
    options.validate();
  }
  catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  return options;
}

bool
writeConfigIfRequested(const Arguments& args, const PipelineOptions& options)
{
  if (!args.has("write_config"))
    return false;
  const std::string path = args.string("write_config");
  prepareOutputs({{"-write_config", path}}, {args.string("config")});
  writePipelineConfig(path, options);
  std::printf("wrote %s\n", path.c_str());
  return true;
}

void
prepareRunOutputs(const Arguments& args,
                  const FrameSource& source,
                  std::vector<OutputPath> outputs)
{
  auto inputs = source.inputPaths();
  inputs.push_back(args.string("config"));
  outputs.insert(outputs.end(), {{"-objects", args.string("objects")},
                                 {"-objects_dir", args.string("objects_dir"), true},
                                 {"-clouds_dir", args.string("clouds_dir"), true},
                                 {"-frames_report", args.string("frames_report")}});
  prepareOutputs(outputs, inputs);
}

RunOutputPaths
runOutputPathsFromArguments(const Arguments& args,
                            const std::string& trajectory,
                            const std::string& labels_dir)
{
  if (args.has("clouds_every") && !args.has("clouds_dir"))
    throw UsageError("-clouds_every needs -clouds_dir DIR");
  RunOutputPaths paths;
  paths.trajectory = trajectory;
  paths.labels_dir = labels_dir;
  paths.objects = args.string("objects");
  paths.clouds_dir = args.string("clouds_dir");
  paths.clouds_every = static_cast<std::size_t>(
      args.integer("clouds_every", 1, 1, std::numeric_limits<long>::max()));
  paths.objects_dir = args.string("objects_dir");
  paths.frames_report = args.string("frames_report");
  return paths;
}

std::size_t
maxFramesFromArguments(const Arguments& args)
{
  return static_cast<std::size_t>(
      args.integer("max_frames", 0, 0, std::numeric_limits<long>::max()));
}

PipelineRunEnd
runPipeline(const PipelineOptions& options,
            std::size_t max_frames,
            FrameSource& source,
            RunOutputs& outputs,
            const std::function<void(const Frame&, const FrameResult&)>& on_result,
            bool read_ahead)
{
  OdometryPipeline pipeline(options);
  PipelineRunEnd end{
      {},
      RunReport(max_frames > 0 ? std::min(max_frames, source.size()) : source.size())};
  end.loop = processFrames(
      source, max_frames,
      [&](const Frame& frame) {
        const auto& result =
            pipeline.process(frame.cloud, frame.timestamp, frame.depth_timestamp);
        outputs.add(frame, result);
        if (on_result)
          on_result(frame, result);
        end.report.add(result);
      },
      read_ahead);
  outputs.finish();
  return end;
}

} // namespace dynvo::app
