// SPDX-License-Identifier: BSD-3-Clause
// Template bodies of StaticSetSelection (compiled in src/ for XYZRGB and XYZRGBA).
#pragma once

#include <dynvo/common/rigid_fit.h>
#include <dynvo/registration/static_set_selection.h>

#include <pcl/console/print.h>

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
        eligible(flow, i, exclude_objects) &&
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
      static_cells_.labels[i] = eligible(*flow, i, false) ? LABEL_STATIC : LABEL_NONE;
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
  const double limit =
      static_cast<double>(params_.static_consensus) * inlier_threshold_;
  selectConsensus(*flow, T_prev_curr, labels_trusted_, limit);
  contestBackground(registration, *flow, limit, T_prev_curr);
  return fit(registration, T_prev_curr, true);
}

template <typename PointT>
void
StaticSetSelection<PointT>::contestBackground(Registration& registration,
                                              const FlowCloud& flow,
                                              double limit,
                                              Eigen::Matrix4d& T_prev_curr)
{
  // docs/algorithm.md §7.8. Fewer cells than MIN_BODY_CELLS are not a body. The rival must
  // show more than SURFACE_RATIO times the consensus' surface: a large mover's visible
  // surface can match the room's (synthetic large_box_slow, 1.0 x 1.6 m at 2.7 m).
  constexpr std::size_t MIN_BODY_CELLS = 30;
  constexpr double SURFACE_RATIO = 2.0;
  const FlowGrid consensus = static_cells_;
  std::size_t rest = 0;
  for (std::size_t i = 0; i < flow.size(); ++i) {
    const bool candidate =
        eligible(flow, i, labels_trusted_) && consensus.labels[i] != LABEL_STATIC;
    static_cells_.labels[i] = candidate ? LABEL_STATIC : LABEL_NONE;
    rest += candidate ? 1 : 0;
  }
  // A cell of side s px at depth z covers (s z / f)^2 m^2: sum z^2 is the body's surface up
  // to a constant factor.
  const auto surface = [&flow](const FlowGrid& cells, std::size_t& count) {
    double sum = 0.0;
    count = 0;
    for (std::size_t i = 0; i < flow.size(); ++i)
      if (cells.labels[i] == LABEL_STATIC) {
        sum += static_cast<double>(flow[i].z) * flow[i].z;
        ++count;
      }
    return sum;
  };
  if (rest >= MIN_BODY_CELLS && fit(registration, T_prev_curr, false)) {
    const Eigen::Matrix4d T_rival =
        registration.getFinalTransformation().template cast<double>();
    selectConsensus(flow, T_rival, labels_trusted_, limit);
    std::size_t held = 0, rival = 0;
    const double held_surface = surface(consensus, held);
    const double rival_surface = surface(static_cells_, rival);
    if (held >= MIN_BODY_CELLS && rival >= MIN_BODY_CELLS &&
        rival_surface > SURFACE_RATIO * held_surface) {
      PCL_DEBUG("[dynvo::%s::align] the cells left out move as a body of %zu cells, "
                "%.1f times the surface of the consensus' %zu: it is the background.\n",
                getClassName().c_str(), rival, rival_surface / held_surface, held);
      T_prev_curr = T_rival;
      return;
    }
  }
  static_cells_ = consensus;
}

} // namespace dynvo
