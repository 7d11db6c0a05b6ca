// SPDX-License-Identifier: BSD-3-Clause
// dynvo_synthesize: writes a deterministic synthetic dynamic-scene RGB-D sequence (TUM layout).
#include <dynvo/app/cli.h>
#include <dynvo/app/frame_source_args.h>
#include <dynvo/app/output_guard.h>
#include <dynvo/app/synthesize.h>
#include <dynvo/synth/scene_synthesizer.h>

#include <pcl/console/print.h>
#include <pcl/console/time.h>

#include <cstdio>
#include <stdexcept>
#include <string>
#include <thread>

namespace {

const char* const USAGE =
    "dynvo_synthesize -out DIR [-scenario NAME] [-frames N] [-seed S] [-clean] "
    "[-plain_objects] [-threads N] [-width W -height H] | -composite TUM_DIR -scenario "
    "NAME -out DIR [-frames N] [-seed S] [-plain_objects] [-camera C] "
    "[-fx -fy -cx -cy] [-distortion K] [-depth_scale S] | -list";

/// \throws dynvo::app::UsageError when the options are out of range
void
validate(const dynvo::SynthOptions& options)
{
  try {
    options.validate();
  }
  catch (const std::invalid_argument& e) {
    throw dynvo::app::UsageError(e.what());
  }
}

/// -composite: the scenario's objects rendered into a real recording.
int
composite(const dynvo::app::Arguments& args)
{
  for (const char* name : {"clean", "threads", "width", "height"})
    if (args.has(name))
      throw dynvo::app::UsageError(std::string("-") + name +
                                   " does not apply to -composite");
  dynvo::SynthOptions options;
  options.scenario = args.string("scenario", options.scenario);
  options.seed =
      static_cast<std::uint32_t>(args.integer("seed", options.seed, 0, 4294967295L));
  options.plain_objects = args.has("plain_objects");
  dynvo::app::CompositeOptions composite;
  composite.recording = args.string("composite");
  composite.intrinsics = dynvo::app::intrinsicsFromArguments(args);
  composite.depth_scale = args.number("depth_scale", 0.0);
  if (args.has("depth_scale") && !(composite.depth_scale > 0.0))
    throw dynvo::app::UsageError("-depth_scale must be positive");
  if (args.has("frames"))
    composite.frames = static_cast<int>(args.integer("frames", 0, 1, 1000000));
  options.intrinsics = composite.intrinsics;
  validate(options);
  const std::string out = args.string("out");
  dynvo::app::prepareOutputs({{"-out", out, true}}, {composite.recording});
  pcl::console::TicToc timer;
  timer.tic();
  std::size_t skipped = 0;
  try {
    skipped = dynvo::app::writeCompositeSequence(options, composite, out);
  }
  catch (const std::invalid_argument& e) { // a scenario without objects
    throw dynvo::app::UsageError(e.what());
  }
  pcl::console::print_highlight("Composited '%s' (seed %u) into %s, wrote %s in ",
                                options.scenario.c_str(), options.seed,
                                composite.recording.c_str(), out.c_str());
  pcl::console::print_value("%.2f", timer.toc() / 1000.0);
  pcl::console::print_info(" s\n");
  if (skipped > 0)
    std::printf("skipped %zu frames of %s without ground truth\n", skipped,
                composite.recording.c_str());
  return 0;
}

} // namespace

int
main(int argc, char** argv)
{
  return dynvo::app::runApp(USAGE, [&] {
    const dynvo::SynthOptions defaults;
    const long hardware_threads = std::max(1U, std::thread::hardware_concurrency());
    const auto text = [](auto value) {
      return std::to_string(value);
    };
    std::vector<dynvo::app::Option> options_list = {
        {"scenario", "NAME", "scenario to render (default " + defaults.scenario + ")"},
        {"frames", "N", "number of frames (default " + text(defaults.frames) + ")"},
        {"seed", "S",
         "seed of textures and depth noise (default " + text(defaults.seed) + ")"},
        {"out", "DIR", "output folder; must not exist or be empty (required)"},
        {"clean", "", "exact depth (default: the Kinect v1 depth model)"},
        {"plain_objects", "",
         "the scenario's objects in one flat colour per face, without texture"},
        {"threads", "N",
         "worker threads (default: hardware count, " + text(hardware_threads) + ")"},
        {"width", "W", "image columns in px (default " + text(defaults.width) + ")"},
        {"height", "H", "image rows in px (default " + text(defaults.height) + ")"},
        {"list", "",
         "print the scenarios with their largest moving-pixel share and exit"},
        {"composite", "TUM_DIR",
         "render the scenario's objects into this real recording (its ground truth "
         "gives the camera; -frames N takes the first N frames, default all)"}};
    for (const dynvo::app::Option& option : dynvo::app::frameSourceOptions())
      for (const char* name :
           {"camera", "fx", "fy", "cx", "cy", "distortion", "depth_scale"})
        if (option.name == name)
          options_list.push_back(option);
    const dynvo::app::Arguments args(argc, argv, options_list, 0);
    if (args.helpRequested()) {
      std::printf(
          "Usage: %s\n\nRenders textured rooms with rigid moving objects and writes "
          "rgb/, depth/, labels/, rgb.txt,\ndepth.txt, groundtruth.txt and "
          "objects.txt. The same seed gives the same bytes.\n\n%s",
          USAGE, args.optionsHelp().c_str());
      return 0;
    }
    if (args.has("list")) {
      // The moving share is counted on an 80x60 label render of the default length.
      dynvo::SynthOptions probe;
      probe.width = 80;
      probe.height = 60;
      probe.noise = false;
      std::printf("%-18s %-8s %s\n", "# scenario", "moving", "description");
      for (const dynvo::ScenarioInfo& info : dynvo::SceneSynthesizer::scenarios()) {
        probe.scenario = info.name;
        const double share = dynvo::SceneSynthesizer(probe).largestMovingShare();
        std::printf("%-18s %5.1f %%  %s\n", info.name.c_str(), 100.0 * share,
                    info.description.c_str());
      }
      return 0;
    }
    if (!args.has("out"))
      throw dynvo::app::UsageError("-out DIR is required");
    if (args.has("composite"))
      return composite(args);
    for (const char* name :
         {"camera", "fx", "fy", "cx", "cy", "distortion", "depth_scale"})
      if (args.has(name))
        throw dynvo::app::UsageError(std::string("-") + name + " needs -composite");

    dynvo::SynthOptions options;
    options.scenario = args.string("scenario", defaults.scenario);
    options.frames =
        static_cast<int>(args.integer("frames", defaults.frames, 1, 1000000));
    options.seed =
        static_cast<std::uint32_t>(args.integer("seed", defaults.seed, 0, 4294967295L));
    options.noise = !args.has("clean");
    options.plain_objects = args.has("plain_objects");
    options.width = static_cast<int>(args.integer("width", defaults.width, 8, 8192));
    options.height = static_cast<int>(args.integer("height", defaults.height, 8, 8192));
    const int threads =
        static_cast<int>(args.integer("threads", hardware_threads, 1, 256));
    validate(options);

    const std::string out = args.string("out");
    pcl::console::TicToc timer;
    timer.tic();
    dynvo::app::writeSyntheticSequence(options, out, threads);
    pcl::console::print_highlight(
        "Wrote %d frames of '%s' (%dx%d, seed %u, %s depth) to %s in ", options.frames,
        options.scenario.c_str(), options.width, options.height, options.seed,
        options.noise ? "Kinect" : "clean", out.c_str());
    pcl::console::print_value("%.2f", timer.toc() / 1000.0);
    pcl::console::print_info(" s with %d thread(s)\n", threads);
    return 0;
  });
}
