// SPDX-License-Identifier: BSD-3-Clause
// The noise-following inlier threshold and the table of its parameters.
#include <dynvo/registration/inlier_noise_tracker.h>

#include <algorithm>
#include <stdexcept>

namespace dynvo {

const ParameterTable<InlierNoiseTrackerParameters>&
InlierNoiseTrackerParameters::table()
{
  using P = InlierNoiseTrackerParameters;
  static_assert(AGGREGATE_FIELD_COUNT<P> == 2, "every field of P needs a row below");
  static const ParameterTable<P> table(std::vector<ParameterTable<P>::Field>{
      makeField("inlier_noise_factor", &P::inlier_noise_factor, FieldRange::atLeast(0),
                "x mean static residual, 0 = off"),
      makeField("min_inlier_threshold", &P::min_inlier_threshold, FieldRange::above(0),
                "m^2, <= segmentation.inlier_threshold"),
  });
  return table;
}

void
InlierNoiseTrackerParameters::validate() const
{
  table().checkAll(*this, "[dynvo::InlierNoiseTracker::Parameters::validate]");
}

void
InlierNoiseTracker::setParameters(const Parameters& parameters)
{
  parameters.validate();
  assignParameters(parameters);
}

void
InlierNoiseTracker::setUpperBound(double threshold)
{
  if (!(threshold > 0.0))
    throw std::invalid_argument("[dynvo::InlierNoiseTracker::setUpperBound] the upper "
                                "bound must be > 0 m^2, got " +
                                formatFieldValue(threshold));
  upper_bound_ = threshold;
}

void
InlierNoiseTracker::addResidual(double mean_squared_residual)
{
  residual_mean_ = residual_mean_ > 0.0 ? (1.0 - RESIDUAL_WEIGHT) * residual_mean_ +
                                              RESIDUAL_WEIGHT * mean_squared_residual
                                        : mean_squared_residual;
}

double
InlierNoiseTracker::getInlierThreshold() const
{
  if (!(params_.inlier_noise_factor > 0.0f && residual_mean_ > 0.0))
    return upper_bound_;
  return std::clamp(params_.inlier_noise_factor * residual_mean_,
                    static_cast<double>(params_.min_inlier_threshold), upper_bound_);
}

} // namespace dynvo
