// SPDX-License-Identifier: BSD-3-Clause
// The field table and the checks of RigidMotionSegmentationParameters.
#include <dynvo/motion_segmentation/rigid_motion_segmentation_parameters.h>

#include <stdexcept>
#include <string>

namespace dynvo {

const ParameterTable<RigidMotionSegmentationParameters>&
RigidMotionSegmentationParameters::table()
{
  using P = RigidMotionSegmentationParameters;
  using R = FieldRange;
  static_assert(AGGREGATE_FIELD_COUNT<P> == 33, "every field of P needs a row below");
  using Fields = std::vector<ParameterTable<P>::Field>;
  static const ParameterTable<P> table{Fields{
      makeField("max_hypotheses", &P::max_hypotheses, R::closed(1, 254), "h_max"),
      makeField("max_trials", &P::max_trials, R::atLeast(1),
                "T_max, >= max_hypotheses"),
      makeField("sample_size", &P::sample_size, R::atLeast(3), "m, points"),
      makeField("search_radius", &P::search_radius, R::atLeast(1), "r_search, cells"),
      makeChoiceField("residual_model", &P::residual_model, {"paper", "sensor"},
                      "unit of E_i"),
      makeField("inlier_threshold", &P::inlier_threshold, R::above(0),
                "th_inlier, m^2, paper model"),
      makeField("inlier_chi2", &P::inlier_chi2, R::above(0),
                "th_chi2, sigma^2, sensor model"),
      makeField("sensor_entropy_lambda", &P::sensor_entropy_lambda, R::above(0),
                "lambda_chi2, sigma^-2"),
      makeField("sensor_dbscan_epsilon", &P::sensor_dbscan_epsilon, R::above(0),
                "eps_chi2, sigma")},
      nestFields("noise", &P::noise, SensorNoiseModel::table().fields()),
      Fields{
      makeField("noise_scale_min", &P::noise_scale_min, R::above(0), "s_min"),
      makeField("noise_scale_max", &P::noise_scale_max, R::above(0),
                "s_max, >= s_min"),
      makeField("entropy_lambda", &P::entropy_lambda, R::above(0), "lambda, m^-2"),
      makeField("entropy_delta", &P::entropy_delta, R::above(0), "delta"),
      makeField("refine_iterations", &P::refine_iterations, R::atLeast(1),
                "refine_iters"),
      makeField("entropy_done", &P::entropy_done, R::closed(0, 1), "s_done"),
      makeField("entropy_saturation", &P::entropy_saturation, R::atLeast(0), "s_sat"),
      makeField("dbscan_min_points", &P::dbscan_min_points, R::atLeast(1), "p_min"),
      makeField("dbscan_epsilon", &P::dbscan_epsilon, R::above(0), "eps, metres"),
      makeField("min_segment_size", &P::min_segment_size, R::atLeast(1),
                "n_seg_min, cells"),
      makeField("tracking", &P::tracking, R::any(), "0 = two-frame segments"),
      makeField("max_labels", &P::max_labels, R::closed(2, 254), "n_obj"),
      makeField("max_age", &P::max_age, R::atLeast(1), "alpha_max, frames"),
      makeField("buffer_length", &P::buffer_length, R::atLeast(1), "L_buf, frames"),
      makeField("min_correlation", &P::min_correlation, R{0, 1, true, false}, "c_min"),
      makeField("static_guard_tolerance", &P::static_guard_tolerance, R::above(0),
                "tau_cv, metres"),
      makeField("static_min_cells", &P::static_min_cells, R::atLeast(1),
                "n_static_min, cells"),
      makeField("object_separation_ratio", &P::object_separation_ratio, R::atLeast(0),
                "k_sep, 0 = off"),
      makeField("object_separation_hold", &P::object_separation_hold, R::atLeast(1),
                "k_hold, <= k_sep"),
      makeField("object_birth_frames", &P::object_birth_frames, R::atLeast(1),
                "n_birth, frames, 1 = off"),
      makeField("object_birth_ratio", &P::object_birth_ratio, R::atLeast(0),
                "k_birth, 0 = off"),
      makeField("ambiguity_search_radius", &P::ambiguity_search_radius, R::atLeast(0),
                "r_amb, px, 0 = off"),
      makeField("seed", &P::seed, R::closed(0, 4294967295.0), "sampling seed")}};
  return table;
}

void
RigidMotionSegmentationParameters::validate() const
{
  const std::string prefix = "[dynvo::RigidMotionSegmentationParameters::validate]";
  table().checkAll(*this, prefix);
  if (max_trials < max_hypotheses)
    throw std::invalid_argument(prefix + " max_trials must be >= max_hypotheses (" +
                                std::to_string(max_hypotheses) + "), got " +
                                std::to_string(max_trials));
  if (noise_scale_max < noise_scale_min)
    throw std::invalid_argument(prefix + " noise_scale_max must be >= noise_scale_min (" +
                                formatFieldValue(noise_scale_min, true) + "), got " +
                                formatFieldValue(noise_scale_max, true));
  if (object_separation_ratio != 0.0f &&
      object_separation_hold > object_separation_ratio)
    throw std::invalid_argument(
        prefix + " object_separation_hold must be <= object_separation_ratio (" +
        formatFieldValue(object_separation_ratio, true) + "), got " +
        formatFieldValue(object_separation_hold, true));
}

} // namespace dynvo
