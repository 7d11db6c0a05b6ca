// SPDX-License-Identifier: BSD-3-Clause
// dynvo_synthesize: writes a deterministic synthetic dynamic-scene RGB-D sequence (TUM layout).
#include <dynvo/app/cli.h>
#include <dynvo/synth/scene_synthesizer.h>

#include <pcl/console/print.h>
#include <pcl/console/time.h>

#include <cstdio>
#include <stdexcept>
#include <string>
#include <thread>

namespace {

const char* const USAGE =
    "dynvo_synthesize -out DIR [-scenario NAME] [-frames N] [-seed S] [-noise 0|1] "
    "[-threads N] [-width W -height H] | -list";

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
    const dynvo::app::Arguments args(
        argc, argv,
        {{"scenario", "NAME", "scenario to render (default " + defaults.scenario + ")"},
         {"frames", "N", "number of frames (default " + text(defaults.frames) + ")"},
         {"seed", "S",
          "seed of textures and depth noise (default " + text(defaults.seed) + ")"},
         {"out", "DIR", "output folder; must not exist or be empty (required)"},
         {"noise", "0|1",
          "Kinect-like depth model (default " + text(int(defaults.noise)) + ")"},
         {"threads", "N",
          "worker threads (default: hardware count, " + text(hardware_threads) + ")"},
         {"width", "W", "image columns in px (default " + text(defaults.width) + ")"},
         {"height", "H", "image rows in px (default " + text(defaults.height) + ")"},
         {"list", "", "print the scenarios and exit"}},
        0);
    if (args.helpRequested()) {
      std::printf(
          "Usage: %s\n\nRenders textured rooms with rigid moving objects and writes "
          "rgb/, depth/, labels/, rgb.txt,\ndepth.txt, groundtruth.txt and "
          "objects.txt. The same seed gives the same bytes.\n\n%s",
          USAGE, args.optionsHelp().c_str());
      return 0;
    }
    if (args.has("list")) {
      for (const dynvo::ScenarioInfo& info : dynvo::SceneSynthesizer::scenarios())
        std::printf("%-16s  %s\n", info.name.c_str(), info.description.c_str());
      return 0;
    }
    if (!args.has("out"))
      throw dynvo::app::UsageError("-out DIR is required");

    dynvo::SynthOptions options;
    options.scenario = args.string("scenario", defaults.scenario);
    options.frames =
        static_cast<int>(args.integer("frames", defaults.frames, 1, 1000000));
    options.seed =
        static_cast<std::uint32_t>(args.integer("seed", defaults.seed, 0, 4294967295L));
    options.noise = args.integer("noise", defaults.noise ? 1 : 0, 0, 1) == 1;
    options.width = static_cast<int>(args.integer("width", defaults.width, 8, 8192));
    options.height = static_cast<int>(args.integer("height", defaults.height, 8, 8192));
    const int threads =
        static_cast<int>(args.integer("threads", hardware_threads, 1, 256));
    try {
      options.validate();
    }
    catch (const std::invalid_argument& e) {
      throw dynvo::app::UsageError(e.what());
    }

    const std::string out = args.string("out");
    pcl::console::TicToc timer;
    timer.tic();
    dynvo::SceneSynthesizer(options).writeSequence(out, threads);
    pcl::console::print_highlight(
        "Wrote %d frames of '%s' (%dx%d, seed %u, noise %s) to %s in ", options.frames,
        options.scenario.c_str(), options.width, options.height, options.seed,
        options.noise ? "on" : "off", out.c_str());
    pcl::console::print_value("%.2f", timer.toc() / 1000.0);
    pcl::console::print_info(" s with %d thread(s)\n", threads);
    return 0;
  });
}
