// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/app/pipeline_config.h>

#include <pcl/exceptions.h>

#include <opencv2/core.hpp>

#include <functional>
#include <limits>
#include <set>
#include <sstream>
#include <stdexcept>

namespace dynvo::app {

namespace {

/// The fields of one struct renamed "prefix.name" (same struct, unlike nestFields()).
std::vector<FieldInfo<PipelineOptions>>
prefixFields(const std::string& prefix, std::vector<FieldInfo<PipelineOptions>> fields)
{
  for (auto& field : fields)
    field.name = prefix + "." + field.name;
  return fields;
}

/// The path of a key: "scene_flow.depth.min_depth" -> {"scene_flow", "depth", "min_depth"}.
std::vector<std::string>
splitKey(const std::string& key)
{
  std::vector<std::string> parts;
  std::istringstream in(key);
  for (std::string part; std::getline(in, part, '.');)
    parts.push_back(part);
  return parts;
}

/// Opens a YAML file; \throws pcl::IOException "path: failure" or "path: error (OpenCV's)"
void
openStorage(cv::FileStorage& fs,
            const std::string& path,
            int mode,
            const std::string& failure,
            const std::string& error)
{
  try {
    fs.open(path, mode | cv::FileStorage::FORMAT_YAML);
  }
  catch (const cv::Exception& e) {
    throw pcl::IOException(path + ": " + error + " (" + e.err + ")");
  }
  if (!fs.isOpened())
    throw pcl::IOException(path + ": " + failure);
}

} // namespace

const ParameterTable<PipelineOptions>&
PipelineOptions::table()
{
  using P = PipelineOptions;
  using R = FieldRange;
  static const ParameterTable<P> table(std::vector<ParameterTable<P>::Field>{
      makeField("use_segmentation", &P::use_segmentation, R::any(),
                "0 = ablation: every valid flow cell is static"),
      makeField("threads", &P::threads, R::atLeast(1), "worker threads"),
      makeField("keyframes", &P::keyframes, R::any(),
                "0 = frame-to-frame registration only"),
      makeField("keyframe_min_overlap", &P::keyframe_min_overlap, R{0, 1, true, false},
                "new keyframe below this share of its first fit's inliers"),
      makeField("keyframe_max_distance", &P::keyframe_max_distance, R::above(0),
                "new keyframe beyond this distance from it (m)"),
      makeField("keyframe_max_angle", &P::keyframe_max_angle, R::above(0),
                "new keyframe beyond this rotation from it (rad)"),
      makeField("max_speed", &P::max_speed, R::above(0),
                "fits moving the camera faster are rejected (m/s)"),
      makeField("max_rotation_rate", &P::max_rotation_rate, R::above(0),
                "fits turning the camera faster are rejected (rad/s)"),
      makeField("velocity_memory", &P::velocity_memory, R::above(0),
                "time constant of the velocity's fading over lost frames (s)"),
      makeField("guard_motion_factor", &P::guard_motion_factor, R::atLeast(0),
                "motion guard tolerance grows by this share of the predicted motion"),
  });
  return table;
}

const ParameterTable<PipelineOptions>&
pipelineConfigTable()
{
  using P = PipelineOptions;
  const auto& own = P::table();
  // The keys of the pipeline map keep the order of the files written so far.
  static const ParameterTable<P> table{
      nestFields("scene_flow", &P::scene_flow,
                 GridSceneFlowParameters::table().fields()),
      nestFields("segmentation", &P::segmentation,
                 RigidMotionSegmentationParameters::table().fields()),
      nestFields("registration", &P::registration,
                 StaticSceneRegistrationParameters::table().fields()),
      nestFields("registration", &P::backend,
                 StaticMaskRegistrationParameters::table().fields()),
      prefixFields("pipeline", {own.field("use_segmentation")}),
      nestFields("pipeline", &P::static_set,
                 StaticSetSelectionParameters::table().fields()),
      nestFields("pipeline", &P::inlier_noise,
                 InlierNoiseTrackerParameters::table().fields()),
      nestFields("pipeline", &P::motion_evidence,
                 MotionEvidenceParameters::table().fields()),
      prefixFields("pipeline",
                   {own.field("threads"), own.field("keyframes"),
                    own.field("keyframe_min_overlap"),
                    own.field("keyframe_max_distance"), own.field("keyframe_max_angle"),
                    own.field("max_speed"), own.field("max_rotation_rate"),
                    own.field("velocity_memory"), own.field("guard_motion_factor")})};
  return table;
}

std::string
pipelineConfigHelp(const PipelineOptions& options)
{
  std::ostringstream out;
  for (const auto& field : pipelineConfigTable().fields()) {
    const std::string head = "  " + field.name + " " + field.text(options);
    out << head << std::string(head.size() < 52 ? 52 - head.size() : 1, ' ') << "("
        << field.doc << "; ";
    if (field.kind == FieldKind::choice) {
      for (std::size_t k = 0; k < field.choices.size(); ++k)
        out << (k ? "|" : "") << field.choices[k];
    }
    else
      out << (field.kind == FieldKind::boolean ? "0 or 1" : field.range.describe());
    out << ")\n";
  }
  return out.str();
}

void
loadPipelineConfig(const std::string& path, PipelineOptions& options)
{
  cv::FileStorage fs;
  openStorage(fs, path, cv::FileStorage::READ, "cannot open configuration file",
              "not a readable YAML file");

  const auto fail = [&](const std::string& key, const std::string& problem) {
    throw pcl::IOException(path + ": " + key + ": " + problem);
  };
  std::set<std::string> known; // every key and every map on the way to one
  for (const auto& field : pipelineConfigTable().fields()) {
    const std::vector<std::string> parts = splitKey(field.name);
    cv::FileNode node = fs[parts[0]];
    std::string prefix = parts[0];
    known.insert(prefix);
    for (std::size_t k = 1; k < parts.size(); ++k) {
      node = node.empty() ? node : node[parts[k]];
      prefix += "." + parts[k];
      known.insert(prefix);
    }
    if (node.empty())
      continue;
    double value = 0.0;
    switch (field.kind) {
    case FieldKind::choice: {
      std::string expected = "expected one of ";
      for (std::size_t k = 0; k < field.choices.size(); ++k)
        expected += (k ? ", " : "") + field.choices[k];
      if (!node.isString())
        fail(field.name, expected);
      const std::string text = node.string();
      value = field.choiceIndex(text);
      if (value < 0)
        fail(field.name, expected + ", got '" + text + "'");
      break;
    }
    case FieldKind::boolean:
      if (!node.isInt() || (static_cast<int>(node) != 0 && static_cast<int>(node) != 1))
        fail(field.name, "expected 0 or 1");
      value = static_cast<int>(node);
      break;
    case FieldKind::integer:
      // A whole number beyond int (a seed from 2^31) is written as a real.
      if (!node.isInt() && !node.isReal())
        fail(field.name, "expected an integer");
      value = node.isInt() ? static_cast<int>(node) : static_cast<double>(node);
      break;
    case FieldKind::real:
      if (!node.isReal() && !node.isInt())
        fail(field.name, "expected a number");
      value = static_cast<double>(node);
      break;
    }
    const std::string problem = field.problem(value);
    if (!problem.empty())
      fail(field.name, problem);
    field.set(options, value);
  }

  // Every key of the file must be known: a typo must not be ignored silently.
  const std::function<void(const cv::FileNode&, const std::string&)> check =
      [&](const cv::FileNode& node, const std::string& prefix) {
        for (const auto& child : node) {
          const std::string key =
              prefix.empty() ? child.name() : prefix + "." + child.name();
          if (!known.count(key))
            fail(key, "unknown key");
          if (child.isMap())
            check(child, key);
        }
      };
  check(fs.root(), "");

  try {
    options.validate();
  }
  catch (const std::invalid_argument& e) {
    throw pcl::IOException(path + ": " + e.what());
  }
}

void
writePipelineConfig(const std::string& path, const PipelineOptions& options)
{
  cv::FileStorage fs;
  openStorage(fs, path, cv::FileStorage::WRITE, "cannot write configuration file",
              "cannot write configuration file");
  std::vector<std::string> open_maps; // the maps around the last key, outermost first
  for (const auto& field : pipelineConfigTable().fields()) {
    std::vector<std::string> parts = splitKey(field.name);
    const std::string name = parts.back();
    parts.pop_back();
    // Close the maps this key is not in, then open the ones it is in.
    std::size_t shared = 0;
    while (shared < open_maps.size() && shared < parts.size() &&
           open_maps[shared] == parts[shared])
      ++shared;
    for (std::size_t k = open_maps.size(); k > shared; --k)
      fs << "}";
    for (std::size_t k = shared; k < parts.size(); ++k)
      fs << parts[k] << "{";
    open_maps = parts;
    const double value = field.get(options);
    switch (field.kind) {
    case FieldKind::choice:
      fs << name << field.text(options);
      break;
    case FieldKind::boolean:
    case FieldKind::integer:
      if (value >= std::numeric_limits<int>::min() &&
          value <= std::numeric_limits<int>::max()) {
        fs << name << static_cast<int>(value);
        break;
      }
      [[fallthrough]];
    case FieldKind::real:
      fs << name << value;
      break;
    }
  }
  for (std::size_t k = open_maps.size(); k > 0; --k)
    fs << "}";
  fs.release();
}

} // namespace dynvo::app
