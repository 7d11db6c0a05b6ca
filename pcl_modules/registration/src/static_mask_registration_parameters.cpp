// SPDX-License-Identifier: BSD-3-Clause
// The field table and the checks of StaticMaskRegistrationParameters.
#include <dynvo/registration/static_mask_registration_parameters.h>

namespace dynvo {

const ParameterTable<StaticMaskRegistrationParameters>&
StaticMaskRegistrationParameters::table()
{
  using P = StaticMaskRegistrationParameters;
  using R = FieldRange;
  static_assert(AGGREGATE_FIELD_COUNT<P> == 7, "every field of P needs a row below");
  static const ParameterTable<P> table(std::vector<ParameterTable<P>::Field>{
      makeChoiceField("backend", &P::backend,
                      {"flow", "cv_rgbd", "icp", "gicp", "direct"},
                      "ego-motion method on the static mask"),
      makeField("icp_max_correspondence_distance", &P::icp_max_correspondence_distance,
                R::above(0), "metres"),
      makeField("icp_max_iterations", &P::icp_max_iterations, R::atLeast(1),
                "ICP/GICP iterations"),
      makeField("icp_transformation_epsilon", &P::icp_transformation_epsilon,
                R::atLeast(0), "m^2"),
      makeField("icp_stride", &P::icp_stride, R::atLeast(1), "px"),
      makeField("rgbd_max_depth_difference", &P::rgbd_max_depth_difference, R::above(0),
                "metres"),
      makeField("rgbd_max_depth", &P::rgbd_max_depth, R::above(0), "metres"),
  });
  return table;
}

void
StaticMaskRegistrationParameters::validate() const
{
  table().checkAll(*this, "[dynvo::StaticMaskRegistration::Parameters::validate]");
}

} // namespace dynvo
