// SPDX-License-Identifier: BSD-3-Clause
// Range checks of RigidMotionSegmentationParameters.
#include <dynvo/motion_segmentation/rigid_motion_segmentation_parameters.h>

#include <cmath>
#include <stdexcept>
#include <string>

namespace dynvo {

void
RigidMotionSegmentationParameters::validate() const
{
  const auto fail = [](const std::string& what) {
    throw std::invalid_argument(
        "[dynvo::RigidMotionSegmentationParameters::validate] " + what);
  };
  const auto positive = [](float x) {
    return std::isfinite(x) && x > 0.0f;
  };
  if (cell_size < 2)
    fail("cell_size must be >= 2 px, got " + std::to_string(cell_size));
  if (max_hypotheses < 1 || max_hypotheses > 254)
    fail("max_hypotheses must be in [1, 254], got " + std::to_string(max_hypotheses));
  if (max_trials < max_hypotheses)
    fail("max_trials must be >= max_hypotheses, got " + std::to_string(max_trials));
  if (sample_size < 3)
    fail("sample_size must be >= 3 points, got " + std::to_string(sample_size));
  if (search_radius < 1)
    fail("search_radius must be >= 1 cell, got " + std::to_string(search_radius));
  if (!positive(inlier_threshold))
    fail("inlier_threshold must be > 0 m^2, got " + std::to_string(inlier_threshold));
  if (!positive(entropy_lambda))
    fail("entropy_lambda must be > 0 m^-2, got " + std::to_string(entropy_lambda));
  if (!positive(entropy_delta))
    fail("entropy_delta must be > 0, got " + std::to_string(entropy_delta));
  if (refine_iterations < 1)
    fail("refine_iterations must be >= 1, got " + std::to_string(refine_iterations));
  if (!(entropy_done >= 0.0f && entropy_done <= 1.0f))
    fail("entropy_done must be in [0, 1], got " + std::to_string(entropy_done));
  if (!(std::isfinite(entropy_saturation) && entropy_saturation >= 0.0f))
    fail("entropy_saturation must be >= 0, got " + std::to_string(entropy_saturation));
  if (dbscan_min_points < 1)
    fail("dbscan_min_points must be >= 1, got " + std::to_string(dbscan_min_points));
  if (!positive(dbscan_epsilon))
    fail("dbscan_epsilon must be > 0 m, got " + std::to_string(dbscan_epsilon));
  if (min_segment_size < 1)
    fail("min_segment_size must be >= 1 cell, got " + std::to_string(min_segment_size));
  if (max_labels < 2 || max_labels > 254)
    fail("max_labels must be in [2, 254], got " + std::to_string(max_labels));
  if (!(std::isfinite(max_age) && max_age >= 1.0f))
    fail("max_age must be >= 1 frame, got " + std::to_string(max_age));
  if (buffer_length < 1)
    fail("buffer_length must be >= 1 frame, got " + std::to_string(buffer_length));
  if (!(min_correlation > 0.0f && min_correlation <= 1.0f))
    fail("min_correlation must be in (0, 1], got " + std::to_string(min_correlation));
  if (!positive(static_guard_tolerance))
    fail("static_guard_tolerance must be > 0 m, got " +
         std::to_string(static_guard_tolerance));
  if (static_min_cells < 1)
    fail("static_min_cells must be >= 1 cell, got " + std::to_string(static_min_cells));
  if (!(std::isfinite(object_separation_ratio) && object_separation_ratio >= 0.0f))
    fail("object_separation_ratio must be >= 0, got " +
         std::to_string(object_separation_ratio));
  if (!(object_separation_hold >= 1.0f &&
        (object_separation_ratio == 0.0f ||
         object_separation_hold <= object_separation_ratio)))
    fail("object_separation_hold must be in [1, object_separation_ratio], got " +
         std::to_string(object_separation_hold));
}

} // namespace dynvo
