// SPDX-License-Identifier: BSD-3-Clause
// A kd-tree that is built on its first query, for pcl::Registration's target search.
#pragma once

#include <pcl/common/point_tests.h>
#include <pcl/search/kdtree.h>

#include <limits>
#include <vector>

namespace dynvo::detail {

/** \brief pcl::search::KdTree that stores its cloud in setInputCloud() and builds the index
 * on the first query. StaticSceneRegistration takes its correspondences from the flow, so
 * pcl::Registration::initCompute() must not build a tree on every new target (tens of
 * milliseconds at VGA); the base class's getFitnessScore(max_range) still gets a working
 * tree when it is called. A query point with a non-finite coordinate (a pixel without depth)
 * has no neighbour: the result holds one entry at infinite squared distance, which
 * getFitnessScore() skips (infinity exceeds every max_range).
 */
template <typename PointT> class LazyKdTree : public pcl::search::KdTree<PointT> {
public:
  using Base = pcl::search::KdTree<PointT>;
  using PointCloudConstPtr = typename Base::PointCloudConstPtr;

  void
  setInputCloud(const PointCloudConstPtr& cloud,
                const pcl::IndicesConstPtr& indices = pcl::IndicesConstPtr()) override
  {
    pending_cloud_ = cloud;
    pending_indices_ = indices;
    this->input_ = cloud;
    this->indices_ = indices;
  }

  int nearestKSearch(const PointT& point,
                     int k,
                     pcl::Indices& k_indices,
                     std::vector<float>& k_sqr_distances) const override
  {
    if (!pcl::isXYZFinite(point)) {
      k_indices.assign(1, 0);
      k_sqr_distances.assign(1, std::numeric_limits<float>::infinity());
      return 0;
    }
    build();
    return Base::nearestKSearch(point, k, k_indices, k_sqr_distances);
  }

  int radiusSearch(const PointT& point,
                   double radius,
                   pcl::Indices& k_indices,
                   std::vector<float>& k_sqr_distances,
                   unsigned int max_nn = 0) const override
  {
    k_indices.clear();
    k_sqr_distances.clear();
    if (!pcl::isXYZFinite(point))
      return 0;
    build();
    return Base::radiusSearch(point, radius, k_indices, k_sqr_distances, max_nn);
  }

private:
  /// Builds the index of the pending cloud (the tree itself is not const, only the query).
  void build() const
  {
    if (!pending_cloud_)
      return;
    auto& self = const_cast<LazyKdTree&>(*this);
    self.Base::setInputCloud(pending_cloud_, pending_indices_);
    self.pending_cloud_.reset();
    self.pending_indices_.reset();
  }

  PointCloudConstPtr pending_cloud_;     ///< cloud whose index is not built yet
  pcl::IndicesConstPtr pending_indices_; ///< its indices (null: every point)
};

} // namespace dynvo::detail
