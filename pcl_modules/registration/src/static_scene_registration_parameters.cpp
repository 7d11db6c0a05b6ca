// SPDX-License-Identifier: BSD-3-Clause
// The field table and the checks of StaticSceneRegistrationParameters.
#include <dynvo/registration/static_scene_registration_parameters.h>

namespace dynvo {

const ParameterTable<StaticSceneRegistrationParameters>&
StaticSceneRegistrationParameters::table()
{
  using P = StaticSceneRegistrationParameters;
  using R = FieldRange;
  static_assert(AGGREGATE_FIELD_COUNT<P> == 6, "every field of P needs a row below");
  static const ParameterTable<P> table(std::vector<ParameterTable<P>::Field>{
      makeField("th_inlier", &P::th_inlier, R::above(0), "th_inlier, m^2"),
      makeField("trim_factor", &P::trim_factor, R::atLeast(1), "trim"),
      makeField("trim_rounds", &P::trim_rounds, R::atLeast(0), "trim rounds"),
      makeField("min_correspondences", &P::min_correspondences, R::atLeast(3), "cells"),
      makeField("information_iterations", &P::information_iterations, R::atLeast(0),
                "Gauss-Newton steps, 0 = off"),
      makeField("huber_threshold", &P::huber_threshold, R::above(0), "Huber, sigma"),
  });
  return table;
}

void
StaticSceneRegistrationParameters::validate() const
{
  table().checkAll(*this, "[dynvo::StaticSceneRegistration::Parameters::validate]");
}

} // namespace dynvo
