// SPDX-License-Identifier: BSD-3-Clause
// The configuration file: every key of every parameter table is written and read back.
#include <dynvo/app/pipeline_config.h>

#include <pcl/exceptions.h>

#include <gtest/gtest.h>

#include "support/temp_dir.h"

#include <cmath>
#include <set>
#include <string>

namespace {

using dynvo::FieldKind;
using dynvo::app::PipelineOptions;
using Field = dynvo::ParameterTable<PipelineOptions>::Field;
using dynvo::test::TempDir;

/// A valid value other than `value`: the next choice, the other boolean, one more (or less)
/// or half as much again (or a quarter less), whichever the field's own range accepts.
double
otherValue(const Field& field, double value)
{
  if (field.kind == FieldKind::choice)
    return std::fmod(value + 1.0, static_cast<double>(field.choices.size()));
  if (field.kind == FieldKind::boolean)
    return 1.0 - value;
  const bool integer = field.kind == FieldKind::integer;
  const double up = integer ? value + 1.0 : (value == 0.0 ? 0.5 : value * 1.5);
  const double down = integer ? value - 1.0 : value * 0.75;
  return field.problem(up).empty() ? up : down;
}

/// The options with every field of every table moved off its default. The changes keep the
/// cross-field rules: max_trials stays far above max_hypotheses,
/// min_depth below max_depth, min_inlier_threshold below the segmentation's threshold, and
/// object_separation_hold below object_separation_ratio.
PipelineOptions
everyFieldChanged()
{
  PipelineOptions options;
  for (const Field& field : dynvo::app::pipelineConfigTable().fields())
    field.set(options, otherValue(field, field.get(options)));
  return options;
}

/// The message of loading a YAML text, or "" when it loads.
std::string
loadError(const TempDir& dir, const std::string& yaml)
{
  dynvo::test::writeText(dir.file("load.yaml"), "%YAML:1.0\n" + yaml);
  PipelineOptions options;
  try {
    dynvo::app::loadPipelineConfig(dir.file("load.yaml"), options);
  }
  catch (const pcl::IOException& e) {
    return e.what();
  }
  return "";
}

TEST(PipelineConfig, EveryKeyOfEveryTableRoundTripsThroughTheFile)
{
  // The table is the concatenation of the module tables and the pipeline's own, so a field
  // added to any of them (and its table, which a static_assert enforces) is covered here.
  const auto& fields = dynvo::app::pipelineConfigTable().fields();
  ASSERT_EQ(fields.size(), 17u + 37u + 6u + 7u + 2u + 1u + 3u + 10u);
  const PipelineOptions defaults;
  const PipelineOptions changed = everyFieldChanged();
  ASSERT_NO_THROW(changed.validate());
  std::set<std::string> keys;
  for (const Field& field : fields) {
    EXPECT_TRUE(keys.insert(field.name).second) << "duplicate key " << field.name;
    EXPECT_NE(field.get(changed), field.get(defaults)) << field.name;
  }

  TempDir dir;
  dynvo::app::writePipelineConfig(dir.file("a.yaml"), changed);
  PipelineOptions reread; // starts from the defaults: every key must come from the file
  dynvo::app::loadPipelineConfig(dir.file("a.yaml"), reread);
  for (const Field& field : fields)
    EXPECT_EQ(field.get(reread), field.get(changed)) << field.name;
  dynvo::app::writePipelineConfig(dir.file("b.yaml"), reread);
  EXPECT_EQ(dynvo::test::readText(dir.file("b.yaml")),
            dynvo::test::readText(dir.file("a.yaml")));
}

TEST(PipelineConfig, SeedsBeyondTheIntRangeRoundTrip)
{
  // YAML integers are 32-bit signed; a larger seed is written as a real and read back whole.
  TempDir dir;
  PipelineOptions options;
  options.segmentation.seed = 4000000000u;
  dynvo::app::writePipelineConfig(dir.file("seed.yaml"), options);
  PipelineOptions reread;
  dynvo::app::loadPipelineConfig(dir.file("seed.yaml"), reread);
  EXPECT_EQ(reread.segmentation.seed, 4000000000u);
  EXPECT_NE(
      loadError(dir, "segmentation:\n  seed: 1.5\n").find("must be a whole number"),
      std::string::npos);
}

TEST(PipelineConfig, ForwardBackwardCheckIsAKey)
{
  // It was missing from the file: "-config" rejected it and "-write_config" dropped it.
  TempDir dir;
  dynvo::app::writePipelineConfig(dir.file("c.yaml"), PipelineOptions());
  EXPECT_NE(
      dynvo::test::readText(dir.file("c.yaml")).find("forward_backward_check: local"),
      std::string::npos);
  dynvo::test::writeText(dir.file("full.yaml"),
                         "%YAML:1.0\nscene_flow:\n  forward_backward_check: full\n");
  PipelineOptions options;
  dynvo::app::loadPipelineConfig(dir.file("full.yaml"), options);
  EXPECT_EQ(options.scene_flow.forward_backward_check,
            dynvo::ForwardBackwardCheck::full);
  EXPECT_NE(loadError(dir, "scene_flow:\n  forward_backward_check: fast\n")
                .find("scene_flow.forward_backward_check: expected one of full, local, "
                      "got 'fast'"),
            std::string::npos);
}

TEST(PipelineConfig, OutOfRangeValuesAndBrokenCrossFieldRulesNameTheKey)
{
  TempDir dir;
  const std::string range = loadError(dir, "segmentation:\n  max_hypotheses: 0\n");
  EXPECT_NE(range.find("segmentation.max_hypotheses: must be in [1, 254], got 0"),
            std::string::npos)
      << range;
  // Each value is in its own range, but together they break max_trials >= max_hypotheses.
  const std::string cross =
      loadError(dir, "segmentation:\n  max_hypotheses: 250\n  max_trials: 100\n");
  EXPECT_NE(cross.find("max_trials must be >= max_hypotheses"), std::string::npos)
      << cross;
}

TEST(PipelineConfig, HelpListsEveryKeyWithItsDefault)
{
  const std::string help = dynvo::app::pipelineConfigHelp(PipelineOptions());
  for (const Field& field : dynvo::app::pipelineConfigTable().fields())
    EXPECT_NE(help.find("  " + field.name + " " + field.text(PipelineOptions()) + " "),
              std::string::npos)
        << field.name;
  // Defaults are spelled as they would be written by hand, floats included.
  EXPECT_NE(help.find("  scene_flow.epsilon 0.03 "), std::string::npos) << help;
  EXPECT_NE(help.find("  segmentation.inlier_threshold 6e-05 "), std::string::npos)
      << help;
  EXPECT_NE(help.find("  registration.backend direct "), std::string::npos) << help;
}

} // namespace
