// SPDX-License-Identifier: BSD-3-Clause
// The noise-following inlier threshold: the static fit's residual fed back into the next
// frame's segmentation (docs/algorithm.md §7).
#pragma once

#include <dynvo/common/export.h>
#include <dynvo/common/parameter_table.h>

#include <string>

namespace dynvo {

/// Parameters of InlierNoiseTracker (the single source of the defaults).
struct DYNVO_EXPORTS InlierNoiseTrackerParameters {
  /// Factor (>= 0, 0 = off: the upper bound throughout) on the running mean of the static
  /// fit's mean squared residual. Residuals of a Gaussian static scene are sigma^2 chi^2_3
  /// with mean 3 sigma^2, so 3 times the mean keeps about 97 % of the static cells.
  float inlier_noise_factor = 3.0f;
  /// Lower bound of the threshold (m^2, > 0; <= the upper bound, checked by the user of the
  /// tracker that sets it).
  float min_inlier_threshold = 3e-5f;

  /// Names, units and ranges of the fields above, in file order (ParameterTable).
  static const ParameterTable<InlierNoiseTrackerParameters>& table();

  /// \throws std::invalid_argument naming the first field out of the range stated above
  void validate() const;
};

/** \brief The segmentation inlier threshold that follows the measured noise
 * (docs/algorithm.md §7).
 *
 * After every converged static fit, addResidual() takes its mean squared residual E
 * (StaticSceneRegistration::getMeanSquaredResidual()) into a running mean, weight RESIDUAL_WEIGHT per
 * frame (the first residual starts it). getInlierThreshold() is inlier_noise_factor times that
 * mean, clamped to [min_inlier_threshold, upper bound]; before the first residual, or with
 * inlier_noise_factor 0, it is the upper bound (setUpperBound(), the segmentation's configured
 * threshold).
 * \code
 * dynvo::InlierNoiseTracker tracker;
 * tracker.setUpperBound(6e-5);                                  // m^2
 * segmentation.setInlierThreshold(static_cast<float>(tracker.getInlierThreshold()));
 * ...                                                           // segment, register
 * if (registration.hasConverged()) tracker.addResidual(registration.getMeanSquaredResidual());
 * \endcode
 */
class DYNVO_EXPORTS InlierNoiseTracker {
public:
  using Parameters = InlierNoiseTrackerParameters;

  /// Weight of a new residual in the running mean.
  static constexpr double RESIDUAL_WEIGHT = 0.1;

  /// Name used in log prefixes: "InlierNoiseTracker".
  const std::string& getClassName() const { return class_name_; }

  /// All knobs at once. \throws std::invalid_argument when parameters.validate() fails
  void setParameters(const Parameters& parameters);

  const Parameters& getParameters() const { return params_; }

  // A setter throws std::invalid_argument when the value is outside the field's own range
  // (InlierNoiseTrackerParameters::table()) and keeps the old value.
  DYNVO_PARAMETER_ACCESSORS(InlierNoiseFactor, inlier_noise_factor)
  DYNVO_PARAMETER_ACCESSORS(MinInlierThreshold, min_inlier_threshold)

  /// Upper bound and starting value of the threshold (m^2, > 0; default 3e-5).
  /// \throws std::invalid_argument when not > 0
  void setUpperBound(double threshold);

  double getUpperBound() const { return upper_bound_; }

  /// Takes the mean squared residual (m^2, >= 0) of a converged static fit.
  void addResidual(double mean_squared_residual);

  /// Running mean of the residuals (m^2); 0 before the first.
  double getResidualMean() const { return residual_mean_; }

  /// The inlier threshold (m^2) for the next frame's segmentation (see the class doc).
  double getInlierThreshold() const;

  /// Forgets the residuals.
  void reset() { residual_mean_ = 0.0; }

private:
  /// Stores checked parameters.
  void assignParameters(const Parameters& parameters) { params_ = parameters; }

  std::string class_name_ = "InlierNoiseTracker"; ///< log prefix
  Parameters params_;                             ///< validated knobs
  double upper_bound_ = 3e-5;                     ///< m^2
  double residual_mean_ = 0.0;                    ///< m^2, 0 = no residual yet
};

} // namespace dynvo
