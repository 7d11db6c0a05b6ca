// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/app/pipeline_config.h>

#include <pcl/exceptions.h>

#include <opencv2/core.hpp>

#include <algorithm>
#include <functional>
#include <set>
#include <stdexcept>

namespace dynvo::app {

namespace {

/// Calls visit(section, name, field&) for every configurable field, in file order.
template <typename Options, typename Visit>
void
visitFields(Options& o, Visit&& visit)
{
  auto& f = o.scene_flow;
  visit("scene_flow", "cell_size", f.cell_size);
  visit("scene_flow.depth", "min_depth", f.depth.min_depth);
  visit("scene_flow.depth", "max_depth", f.depth.max_depth);
  visit("scene_flow.depth", "flying_pixel_tolerance", f.depth.flying_pixel_tolerance);
  visit("scene_flow.depth", "max_hole_width", f.depth.max_hole_width);
  visit("scene_flow.depth", "hole_fill_tolerance", f.depth.hole_fill_tolerance);
  visit("scene_flow", "window_size", f.window_size);
  visit("scene_flow", "max_pyramid_level", f.max_pyramid_level);
  visit("scene_flow", "max_iterations", f.max_iterations);
  visit("scene_flow", "epsilon", f.epsilon);
  visit("scene_flow", "min_eigen_threshold", f.min_eigen_threshold);
  visit("scene_flow", "forward_backward_threshold", f.forward_backward_threshold);
  visit("scene_flow", "depth_edge_tolerance", f.depth_edge_tolerance);
  visit("scene_flow", "max_flow", f.max_flow);
  visit("scene_flow", "depth_window_radius", f.depth_window_radius);
  visit("scene_flow", "weight_reference_depth", f.weight_reference_depth);
  auto& s = o.segmentation;
  visit("segmentation", "cell_size", s.cell_size);
  visit("segmentation", "max_hypotheses", s.max_hypotheses);
  visit("segmentation", "max_trials", s.max_trials);
  visit("segmentation", "sample_size", s.sample_size);
  visit("segmentation", "search_radius", s.search_radius);
  visit("segmentation", "inlier_threshold", s.inlier_threshold);
  visit("segmentation", "entropy_lambda", s.entropy_lambda);
  visit("segmentation", "entropy_delta", s.entropy_delta);
  visit("segmentation", "refine_iterations", s.refine_iterations);
  visit("segmentation", "entropy_done", s.entropy_done);
  visit("segmentation", "entropy_saturation", s.entropy_saturation);
  visit("segmentation", "dbscan_min_points", s.dbscan_min_points);
  visit("segmentation", "dbscan_epsilon", s.dbscan_epsilon);
  visit("segmentation", "min_segment_size", s.min_segment_size);
  visit("segmentation", "tracking", s.tracking);
  visit("segmentation", "max_labels", s.max_labels);
  visit("segmentation", "max_age", s.max_age);
  visit("segmentation", "buffer_length", s.buffer_length);
  visit("segmentation", "min_correlation", s.min_correlation);
  visit("segmentation", "static_guard_tolerance", s.static_guard_tolerance);
  visit("segmentation", "static_min_cells", s.static_min_cells);
  visit("segmentation", "object_separation_ratio", s.object_separation_ratio);
  visit("segmentation", "object_separation_hold", s.object_separation_hold);
  visit("segmentation", "seed", s.seed);
  auto& r = o.registration;
  visit("registration", "th_inlier", r.th_inlier);
  visit("registration", "trim_factor", r.trim_factor);
  visit("registration", "trim_rounds", r.trim_rounds);
  visit("registration", "min_correspondences", r.min_correspondences);
  visit("registration", "refinement", r.refinement);
  visit("registration", "refinement_max_correspondence_distance",
        r.refinement_max_correspondence_distance);
  visit("registration", "refinement_max_iterations", r.refinement_max_iterations);
  visit("registration", "refinement_transformation_epsilon",
        r.refinement_transformation_epsilon);
  visit("registration", "refinement_stride", r.refinement_stride);
  visit("pipeline", "use_segmentation", o.use_segmentation);
  visit("pipeline", "static_consensus", o.static_consensus);
  visit("pipeline", "inlier_noise_factor", o.inlier_noise_factor);
  visit("pipeline", "min_inlier_threshold", o.min_inlier_threshold);
  visit("pipeline", "threads", o.threads);
}

const char* const REFINEMENTS[] = {"none", "icp", "gicp"};

cv::FileNode
sectionNode(const cv::FileStorage& fs, const std::string& section)
{
  const auto dot = section.find('.');
  if (dot == std::string::npos)
    return fs[section];
  return fs[section.substr(0, dot)][section.substr(dot + 1)];
}

} // namespace

void
loadPipelineConfig(const std::string& path, PipelineOptions& options)
{
  cv::FileStorage fs;
  try {
    fs.open(path, cv::FileStorage::READ | cv::FileStorage::FORMAT_YAML);
  }
  catch (const cv::Exception& e) {
    throw pcl::IOException(path + ": not a readable YAML file (" + e.err + ")");
  }
  if (!fs.isOpened())
    throw pcl::IOException(path + ": cannot open configuration file");

  std::set<std::string> known;
  const auto fail = [&](const std::string& key, const std::string& problem) {
    throw pcl::IOException(path + ": " + key + ": " + problem);
  };
  visitFields(options, [&](const std::string& section, const std::string& name,
                           auto& field) {
    using Field = std::decay_t<decltype(field)>;
    const std::string key = section + "." + name;
    known.insert(key);
    known.insert(section);
    if (section.find('.') != std::string::npos)
      known.insert(section.substr(0, section.find('.')));
    const cv::FileNode node = sectionNode(fs, section)[name];
    if (node.empty())
      return;
    if constexpr (std::is_same_v<Field, RegistrationRefinement>) {
      if (!node.isString())
        fail(key, "expected one of none, icp, gicp");
      const std::string value = node.string();
      for (int k = 0; k < 3; ++k)
        if (value == REFINEMENTS[k]) {
          field = static_cast<RegistrationRefinement>(k);
          return;
        }
      fail(key, "expected one of none, icp, gicp, got '" + value + "'");
    }
    else if constexpr (std::is_same_v<Field, bool>) {
      if (!node.isInt() || (static_cast<int>(node) != 0 && static_cast<int>(node) != 1))
        fail(key, "expected 0 or 1");
      field = static_cast<int>(node) == 1;
    }
    else if constexpr (std::is_integral_v<Field>) {
      if (!node.isInt() || (std::is_unsigned_v<Field> && static_cast<int>(node) < 0))
        fail(key, std::is_unsigned_v<Field> ? "expected a non-negative integer"
                                            : "expected an integer");
      field = static_cast<Field>(static_cast<int>(node));
    }
    else {
      if (!node.isReal() && !node.isInt())
        fail(key, "expected a number");
      field = static_cast<Field>(static_cast<double>(node));
    }
  });

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
  try {
    fs.open(path, cv::FileStorage::WRITE | cv::FileStorage::FORMAT_YAML);
  }
  catch (const cv::Exception& e) {
    throw pcl::IOException(path + ": cannot write configuration file (" + e.err + ")");
  }
  if (!fs.isOpened())
    throw pcl::IOException(path + ": cannot write configuration file");
  PipelineOptions copy = options;
  std::string open_section;
  visitFields(copy, [&](const std::string& section, const std::string& name,
                        auto& field) {
    using Field = std::decay_t<decltype(field)>;
    if (section != open_section) {
      // Close the previous map(s) and open the new one(s); "a.b" nests b inside a.
      const auto depth = [](const std::string& s) {
        return s.empty() ? 0
                         : 1 + static_cast<int>(std::count(s.begin(), s.end(), '.'));
      };
      const std::string parent = section.substr(0, section.find('.'));
      const bool stays_in_parent = open_section.rfind(parent, 0) == 0;
      for (int d = depth(open_section); d > (stays_in_parent ? 1 : 0); --d)
        fs << "}";
      if (!stays_in_parent)
        fs << parent << "{";
      if (section.find('.') != std::string::npos)
        fs << section.substr(section.find('.') + 1) << "{";
      open_section = section;
    }
    if constexpr (std::is_same_v<Field, RegistrationRefinement>)
      fs << name << std::string(REFINEMENTS[static_cast<int>(field)]);
    else if constexpr (std::is_same_v<Field, bool> || std::is_integral_v<Field>)
      fs << name << static_cast<int>(field);
    else
      fs << name << static_cast<double>(field);
  });
  for (int d = 1 + static_cast<int>(
                       std::count(open_section.begin(), open_section.end(), '.'));
       d > 0; --d)
    fs << "}";
  fs.release();
}

} // namespace dynvo::app
