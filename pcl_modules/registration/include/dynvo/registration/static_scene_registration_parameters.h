// SPDX-License-Identifier: BSD-3-Clause
// Every knob of the static-scene ego-motion stage (docs/algorithm.md §7 and §9).
#pragma once

#include <dynvo/common/export.h>
#include <dynvo/common/parameter_table.h>

namespace dynvo {

/** \brief Parameters of StaticSceneRegistration (the single source of the defaults).
 *
 * The flow estimate follows docs/algorithm.md §7: a weighted least-squares fit on the
 * static cells,
 * then trim_rounds rounds that keep the cells with E_i <= trim_factor * th_inlier and refit,
 * then information_iterations Gauss-Newton steps that weigh each kept cell by the inverse
 * covariance of its transfer error under the sensor noise model (§7.2; 0 = the paper's fit).
 * Other methods on the static mask are StaticMaskRegistration's.
 */
struct DYNVO_EXPORTS StaticSceneRegistrationParameters {
  float th_inlier = 3e-5f; ///< th_inlier (m^2, > 0): E_i of an inlier, 5.5 mm squared
  float trim_factor =
      4.0f; ///< trim (>= 1): a round keeps E_i <= trim_factor * th_inlier (11 mm)
  int trim_rounds =
      2; ///< trim rounds (>= 0): trim-and-refit rounds after the first fit
  int min_correspondences =
      6; ///< (>= 3): fewer usable static cells is "too few"; a trim round leaving fewer keeps the previous fit
  int information_iterations =
      4; ///< (>= 0): Gauss-Newton steps of the information-weighted fit, 0 = off (paper)
  float huber_threshold =
      3.0f; ///< (sigma, > 0): Mahalanobis distance above which a cell's weight falls as 1/d

  /// Names, units and ranges of the fields above, in file order (ParameterTable).
  static const ParameterTable<StaticSceneRegistrationParameters>& table();

  /// \throws std::invalid_argument naming the first field out of the range stated above
  void validate() const;
};

} // namespace dynvo
