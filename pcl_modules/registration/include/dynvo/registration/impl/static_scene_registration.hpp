// SPDX-License-Identifier: BSD-3-Clause
// Template bodies of StaticSceneRegistration (compiled in src/ for XYZRGB and XYZRGBA).
#pragma once

#include <dynvo/common/rigid_fit.h>
#include <dynvo/registration/static_scene_registration.h>

#include <pcl/common/transforms.h>
#include <pcl/console/print.h>

#include <cmath>
#include <stdexcept>

namespace dynvo {

template <typename PointT> StaticSceneRegistration<PointT>::StaticSceneRegistration()
{
  reg_name_ = "StaticSceneRegistration";
  // The flow gives the correspondences: the target's kd-tree is only built when the base
  // class's getFitnessScore(max_range) asks for it.
  Base::setSearchMethodTarget(pcl::make_shared<detail::LazyKdTree<PointT>>());
  setParameters(Parameters());
}

template <typename PointT>
void
StaticSceneRegistration<PointT>::setParameters(const Parameters& parameters)
{
  parameters.validate();
  assignParameters(parameters);
}

template <typename PointT>
void
StaticSceneRegistration<PointT>::setSensorNoise(const SensorNoiseModel& noise,
                                                float focal)
{
  noise.validate();
  if (!(focal > 0.0f))
    throw std::invalid_argument("[dynvo::StaticSceneRegistration::setSensorNoise] "
                                "focal must be > 0");
  noise_ = noise;
  focal_ = focal;
}

template <typename PointT>
void
StaticSceneRegistration<PointT>::adoptIndices()
{
  user_indices_ = indices_;
  updateIndices();
}

template <typename PointT>
void
StaticSceneRegistration<PointT>::setStaticCells(const FlowGrid& cells)
{
  static_cells_input_ = cells;
  updateIndices();
}

template <typename PointT>
void
StaticSceneRegistration<PointT>::setInputSource(const PointCloudConstPtr& cloud)
{
  Base::setInputSource(cloud);
  updateIndices();
}

template <typename PointT>
void
StaticSceneRegistration<PointT>::updateIndices()
{
  indices_rejected_ = false;
  if (static_cells_input_.size() > 0) {
    // The centres of the static cells: a small output, and in range whenever the cells are
    // on the source's grid (otherwise validateInputs() rejects them).
    auto centres = pcl::make_shared<pcl::Indices>();
    if (input_ && static_cells_input_.image_width == input_->width &&
        static_cells_input_.image_height == input_->height)
      for (std::size_t i = 0; i < static_cells_input_.size(); ++i)
        if (static_cells_input_.labels[i] == LABEL_STATIC)
          centres->push_back(
              static_cast<pcl::index_t>(static_cells_input_.centreIndex(i)));
    indices_ = centres;
    fake_indices_ = false;
    return;
  }
  indices_ = user_indices_;
  fake_indices_ = false;
  if (!user_indices_ || !input_)
    return;
  for (const auto index : *user_indices_) {
    if (index < 0 || static_cast<std::size_t>(index) >= input_->size()) {
      indices_rejected_ = true;
      rejected_index_ = static_cast<int>(index);
      PCL_ERROR(
          "[dynvo::%s::setIndices] index %d is outside the %zu-point source cloud.\n",
          reg_name_.c_str(), rejected_index_, input_->size());
      indices_ = pcl::make_shared<pcl::Indices>();
      return;
    }
  }
}

template <typename PointT>
void
StaticSceneRegistration<PointT>::resetResults(const Matrix4& guess)
{
  converged_ = false;
  final_transformation_ = guess;
  transformation_ = guess;
  flow_transformation_ = guess;
  status_ = Status::invalid_input;
  mean_squared_residual_ = std::numeric_limits<double>::max();
  inlier_count_ = 0;
  source_points_.clear();
  target_points_.clear();
  weights_.clear();
  inliers_.clear();
}

template <typename PointT>
bool
StaticSceneRegistration<PointT>::validateInputs()
{
  const char* name = reg_name_.c_str();
  if (!input_ || !target_ || !flow_) {
    PCL_ERROR("[dynvo::%s::align] %s not set.\n", name,
              !input_    ? "source (current) cloud"
              : !target_ ? "target (previous) cloud"
                         : "flow grid (setInputFlow)");
    return false;
  }
  if (!input_->isOrganized() || !target_->isOrganized() || !flow_->isOrganized()) {
    PCL_ERROR("[dynvo::%s::align] %s is not organized.\n", name,
              !input_->isOrganized()    ? "source (current) cloud"
              : !target_->isOrganized() ? "target (previous) cloud"
                                        : "flow grid");
    return false;
  }
  if (input_->width != target_->width || input_->height != target_->height) {
    PCL_ERROR("[dynvo::%s::align] source cloud is %ux%u but target cloud is %ux%u.\n",
              name, input_->width, input_->height, target_->width, target_->height);
    return false;
  }
  if (!FlowGrid::fromFlow(*flow_, input_->width, input_->height, grid_)) {
    PCL_ERROR("[dynvo::%s::align] a %ux%u flow grid does not tile a %ux%u cloud "
              "(cell size = width / flow width).\n",
              name, flow_->width, flow_->height, input_->width, input_->height);
    return false;
  }
  if (static_cells_input_.size() > 0 &&
      (!static_cells_input_.sameGeometry(grid_) ||
       static_cells_input_.labels.size() != grid_.size())) {
    PCL_ERROR(
        "[dynvo::%s::align] the static cells (%ux%u cells of %u px) are not on the "
        "flow's grid (%ux%u cells of %u px).\n",
        name, static_cells_input_.cols, static_cells_input_.rows,
        static_cells_input_.cell_size, grid_.cols, grid_.rows, grid_.cell_size);
    return false;
  }
  if (indices_rejected_) {
    PCL_ERROR("[dynvo::%s::align] index %d is outside the %zu-point source cloud.\n",
              name, rejected_index_, input_->size());
    return false;
  }
  return true;
}

template <typename PointT>
void
StaticSceneRegistration<PointT>::collectCorrespondences()
{
  static_cells_.assign(grid_.size(), 0);
  if (static_cells_input_.size() > 0) {
    for (std::size_t i = 0; i < grid_.size(); ++i)
      static_cells_[i] = static_cells_input_.labels[i] == LABEL_STATIC;
  }
  else {
    for (const auto index : *indices_) {
      const std::size_t i = grid_.cellOfPixel(static_cast<std::size_t>(index));
      if (i < grid_.size())
        static_cells_[i] = 1;
    }
  }
  for (std::size_t i = 0; i < flow_->size(); ++i) {
    const PointFlow& f = (*flow_)[i];
    const Eigen::Vector3d b(f.x, f.y, f.z);
    const Eigen::Vector3d a(f.prev_x, f.prev_y, f.prev_z);
    if (!static_cells_[i] || !f.valid_3d || !(f.weight > 0.0f) ||
        !std::isfinite(f.weight) || !b.allFinite() || !a.allFinite())
      continue;
    source_points_.push_back(b);
    target_points_.push_back(a);
    weights_.push_back(f.weight);
  }
}

template <typename PointT>
bool
StaticSceneRegistration<PointT>::estimateFromFlow()
{
  const std::size_t count = source_points_.size();
  const auto min_count = static_cast<std::size_t>(params_.min_correspondences);
  if (count < min_count) {
    status_ = Status::too_few_correspondences;
    PCL_DEBUG("[dynvo::%s::align] %zu static cells, fewer than %zu.\n",
              reg_name_.c_str(), count, min_count);
    return false;
  }
  RigidFitAccumulator fit;
  for (std::size_t i = 0; i < count; ++i)
    fit.add(source_points_[i], target_points_[i], weights_[i]);
  Eigen::Matrix4d T_prev_curr;
  if (fit.solve(T_prev_curr) != RigidFitStatus::ok) {
    status_ = Status::degenerate;
    PCL_DEBUG("[dynvo::%s::align] the %zu static cells are collinear.\n",
              reg_name_.c_str(), count);
    return false;
  }
  inliers_.assign(count, 1);
  inlier_count_ = count;
  // docs/algorithm.md §7: keep E_i <= trim_factor * th_inlier and refit, trim_rounds
  // times.
  const double trim_threshold =
      static_cast<double>(params_.trim_factor) * static_cast<double>(params_.th_inlier);
  std::vector<std::uint8_t> kept(count);
  for (int round = 0; round < params_.trim_rounds; ++round) {
    fit.clear();
    for (std::size_t i = 0; i < count; ++i) {
      kept[i] = squaredTransferError(T_prev_curr, source_points_[i],
                                     target_points_[i]) <= trim_threshold;
      if (kept[i])
        fit.add(source_points_[i], target_points_[i], weights_[i]);
    }
    if (fit.size() < min_count || fit.solve(T_prev_curr) != RigidFitStatus::ok)
      break;
    inliers_ = kept;
    inlier_count_ = fit.size();
  }
  // docs/algorithm.md §7.2: the kept cells again, each weighed by its information.
  if (params_.information_iterations > 0) {
    std::vector<InformationPair> pairs;
    pairs.reserve(inlier_count_);
    for (std::size_t i = 0; i < count; ++i)
      if (inliers_[i])
        pairs.push_back(
            {source_points_[i], target_points_[i],
             noise_
                 .transferInformation(target_points_[i].cast<float>(),
                                      source_points_[i].cast<float>(), focal_)
                 .cast<double>(),
             1.0});
    if (refineRigidFit(pairs, params_.information_iterations, params_.huber_threshold,
                       T_prev_curr) != RigidFitStatus::ok)
      PCL_DEBUG("[dynvo::%s::align] the information-weighted fit is singular; "
                "the metric fit stays.\n",
                reg_name_.c_str());
  }
  flow_transformation_ = T_prev_curr.cast<float>();
  return true;
}

template <typename PointT>
void
StaticSceneRegistration<PointT>::computeTransformation(PointCloud& output,
                                                       const Matrix4& guess)
{
  resetResults(guess);
  if (!validateInputs()) {
    output.clear();
    return;
  }
  collectCorrespondences();
  if (!estimateFromFlow()) {
    output.clear();
    return;
  }
  converged_ = true;
  status_ = Status::converged;
  final_transformation_ = flow_transformation_;
  transformation_ = final_transformation_;
  const Eigen::Matrix4d T_final = final_transformation_.template cast<double>();
  double residual_sum = 0.0;
  for (std::size_t i = 0; i < source_points_.size(); ++i)
    if (inliers_[i])
      residual_sum +=
          squaredTransferError(T_final, source_points_[i], target_points_[i]);
  mean_squared_residual_ = residual_sum / static_cast<double>(inlier_count_);
  pcl::transformPointCloud(output, output, final_transformation_);
}

} // namespace dynvo
