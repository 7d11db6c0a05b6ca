// SPDX-License-Identifier: BSD-3-Clause
// dynvo_evaluate GT EST: RPE and ATE of an estimated TUM trajectory against ground truth.
#include <dynvo/app/cli.h>
#include <dynvo/eval/trajectory_metrics.h>

#include <cstdio>
#include <stdexcept>
#include <string>

namespace {

const char* const USAGE =
    "dynvo_evaluate GROUNDTRUTH ESTIMATE [-delta D] [-delta_unit s|f] [-json]";

} // namespace

int
main(int argc, char** argv)
{
  return dynvo::app::runApp(USAGE, [&] {
    const dynvo::RpeOptions defaults;
    const dynvo::app::Arguments args(
        argc, argv,
        {{"delta", "D", "RPE pair spacing (default 1)"},
         {"delta_unit", "s|f", "unit of -delta: seconds or frames (default s)"},
         {"json", "", "print the result as one JSON object"}},
        2);
    if (args.helpRequested()) {
      std::printf(
          "Usage: %s\n\nRelative pose error as TUM evaluate_rpe.py --fixed_delta "
          "and absolute trajectory error as evaluate_ate.py.\nBoth files are TUM "
          "trajectories (timestamp tx ty tz qx qy qz qw, camera-to-world).\n\n%s",
          USAGE, args.optionsHelp().c_str());
      return 0;
    }
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
