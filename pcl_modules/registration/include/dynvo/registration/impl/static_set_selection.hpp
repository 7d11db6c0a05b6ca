// SPDX-License-Identifier: BSD-3-Clause
// Template bodies of StaticSetSelection (compiled in src/ for XYZRGB and XYZRGBA).
#pragma once

#include <dynvo/common/rigid_fit.h>
#include <dynvo/registration/static_set_selection.h>

namespace dynvo {

template <typename PointT>
bool
StaticSetSelection<PointT>::fit(Registration& registration,
                                const Eigen::Matrix4d& T_prev_curr_guess,
                                bool final)
{
  // docs/algorithm.md §7.2: the cells are chosen with the metric fit; only the final fit is
  // refined under the sensor's noise (its iterations are restored however align() ends).
  struct Iterations {
    Registration& registration;
    const int kept = registration.getInformationIterations();
    ~Iterations() { registration.setInformationIterations(kept); }
  } iterations{registration};
  if (!final)
    registration.setInformationIterations(0);
  registration.setStaticCells(static_cells_);
  typename Registration::PointCloud aligned;
  registration.align(aligned, T_prev_curr_guess.cast<float>());
  return registration.hasConverged();
}

template <typename PointT>
void
StaticSetSelection<PointT>::selectConsensus(const FlowCloud& flow,
                                            const Eigen::Matrix4d& T_prev_curr,
                                            bool exclude_objects,
                                            double limit)
{
  for (std::size_t i = 0; i < flow.size(); ++i) {
    const PointFlow& cell = flow[i];
    const bool selected =
        cell.valid_3d && !(exclude_objects && labels_.labels[i] > LABEL_STATIC) &&
        !leftOut(i) &&
        squaredTransferError(T_prev_curr, cell.getVector3fMap().cast<double>(),
                             Eigen::Vector3d(cell.prev_x, cell.prev_y, cell.prev_z)) <=
            limit;
    static_cells_.labels[i] = selected ? LABEL_STATIC : LABEL_NONE;
  }
}

template <typename PointT>
bool
StaticSetSelection<PointT>::align(Registration& registration)
{
  labels_trusted_ = true;
  const auto& flow = registration.getInputFlow();
  const auto& source = registration.getInputSource();
  if (!flow || !source ||
      !FlowGrid::fromFlow(*flow, source->width, source->height, static_cells_)) {
    // The registration reports the broken input.
    static_cells_ = FlowGrid();
    return fit(registration, rigidInverse(T_curr_prev_predicted_), true);
  }
  if (!use_labels_) {
    for (std::size_t i = 0; i < flow->size(); ++i)
      static_cells_.labels[i] =
          (*flow)[i].valid_3d && !leftOut(i) ? LABEL_STATIC : LABEL_NONE;
    return fit(registration, rigidInverse(T_curr_prev_predicted_), true);
  }
  const bool labels_fit = labels_.sameGeometry(static_cells_) &&
                          labels_.labels.size() == static_cells_.size();
  for (std::size_t i = 0; labels_fit && i < static_cells_.size(); ++i)
    static_cells_.labels[i] =
        labels_.labels[i] == LABEL_STATIC && !leftOut(i) ? LABEL_STATIC : LABEL_NONE;

  const Eigen::Matrix4d T_prev_curr_predicted = rigidInverse(T_curr_prev_predicted_);
  const bool background_fit =
      fit(registration, T_prev_curr_predicted, !(params_.static_consensus > 0.0f));
  Eigen::Matrix4d T_prev_curr =
      registration.getFinalTransformation().template cast<double>();
  if (!(params_.static_consensus > 0.0f))
    return background_fit;
  const double departure =
      (T_curr_prev_predicted_ * T_prev_curr).topRightCorner<3, 1>().norm();
  const double tau = guard_tolerance_;
  labels_trusted_ = labels_fit && background_fit && departure <= tau;
  if (!labels_trusted_) {
    selectConsensus(*flow, T_prev_curr_predicted, false, tau * tau);
    T_prev_curr = fit(registration, T_prev_curr_predicted, false)
                      ? registration.getFinalTransformation().template cast<double>()
                      : T_prev_curr_predicted;
  }
  selectConsensus(*flow, T_prev_curr, labels_trusted_,
                  static_cast<double>(params_.static_consensus) * inlier_threshold_);
  return fit(registration, T_prev_curr, true);
}

} // namespace dynvo
