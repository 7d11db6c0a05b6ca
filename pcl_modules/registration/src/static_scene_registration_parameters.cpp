// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/registration/static_scene_registration_parameters.h>

#include <cmath>
#include <stdexcept>
#include <string>

namespace dynvo {

void
StaticSceneRegistrationParameters::validate() const
{
  const auto fail = [](const std::string& what) {
    throw std::invalid_argument(
        "[dynvo::StaticSceneRegistration::Parameters::validate] " + what);
  };
  if (!(std::isfinite(th_inlier) && th_inlier > 0.0f))
    fail("th_inlier must be finite and > 0 m^2, got " + std::to_string(th_inlier));
  if (!(std::isfinite(trim_factor) && trim_factor >= 1.0f))
    fail("trim_factor must be finite and >= 1, got " + std::to_string(trim_factor));
  if (trim_rounds < 0)
    fail("trim_rounds must be >= 0, got " + std::to_string(trim_rounds));
  if (min_correspondences < 3)
    fail("min_correspondences must be >= 3 (a rigid fit needs 3 points), got " +
         std::to_string(min_correspondences));
  if (refinement != RegistrationRefinement::none &&
      refinement != RegistrationRefinement::icp &&
      refinement != RegistrationRefinement::gicp)
    fail("refinement must be none, icp or gicp, got " +
         std::to_string(static_cast<int>(refinement)));
  if (!(std::isfinite(refinement_max_correspondence_distance) &&
        refinement_max_correspondence_distance > 0.0))
    fail("refinement_max_correspondence_distance must be finite and > 0 m, got " +
         std::to_string(refinement_max_correspondence_distance));
  if (refinement_max_iterations < 1)
    fail("refinement_max_iterations must be >= 1, got " +
         std::to_string(refinement_max_iterations));
  if (!(std::isfinite(refinement_transformation_epsilon) &&
        refinement_transformation_epsilon >= 0.0))
    fail("refinement_transformation_epsilon must be finite and >= 0 m^2, got " +
         std::to_string(refinement_transformation_epsilon));
  if (refinement_stride < 1)
    fail("refinement_stride must be >= 1 px, got " + std::to_string(refinement_stride));
}

} // namespace dynvo
