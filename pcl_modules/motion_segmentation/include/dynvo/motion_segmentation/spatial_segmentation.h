// SPDX-License-Identifier: BSD-3-Clause
// Two-frame rigid motion segmentation: hypotheses, refinement, DBSCAN, labels (docs/algorithm.md §3).
#pragma once

#include <dynvo/common/export.h>
#include <dynvo/motion_segmentation/grid_flow_data.h>
#include <dynvo/motion_segmentation/rigid_motion_segmentation_parameters.h>

#include <Eigen/Core>

#include <cstdint>
#include <functional>
#include <random>
#include <vector>

namespace dynvo {

/// One accepted motion hypothesis (docs/algorithm.md §3.3).
struct MotionHypothesis {
  Eigen::Matrix4d T_curr_prev = Eigen::Matrix4d::Identity(); ///< H mapping a_i to b_i
  std::vector<int> inliers; ///< points with E_i(H) <= th_inlier, ascending indices
};

/// Output of SpatialSegmenter::segment (docs/algorithm.md §3.6).
struct SpatialSegmentationResult {
  std::vector<std::uint8_t>
      labels; ///< G_i per cell: 0 = no valid motion, 1..g by size (1 largest)
  std::vector<Eigen::Matrix4d>
      motions;            ///< H_c (T_curr_prev) of segment c at index c - 1
  std::vector<int> sizes; ///< N_c, cells of segment c at index c - 1
  std::vector<MotionHypothesis>
      hypotheses; ///< accepted hypotheses, inliers as cell indices
  int trials = 0; ///< trials made, failed ones included
  float inlier_threshold = 0.0f; ///< th of this result, in the unit of E_i

  /// Number of segments g.
  int segmentCount() const { return static_cast<int>(sizes.size()); }
};

/** \brief DBSCAN over a neighbour test (Yarpiz MATLAB DBSCAN semantics).
 *
 * The neighbourhood of an item includes the item itself; an item is a core point when its
 * neighbourhood holds at least min_points items. With min_points = 1 every item is a core
 * point, the clusters are the connected components of the neighbour graph and no item is
 * noise: pairs are joined in order, and a pair already in one cluster is not tested.
 * \param[in] count number of items
 * \param[in] min_points core-point size (>= 1)
 * \param[in] neighbours symmetric test of two items i < j (distance <= epsilon), called at
 *            most once per pair
 * \return cluster id per item (0, 1, ... in order of discovery; with min_points = 1, of each
 *         cluster's smallest item), -1 for noise
 */
DYNVO_EXPORTS std::vector<int> dbscan(int count,
                                      int min_points,
                                      const std::function<bool(int, int)>& neighbours);

/** \brief Motion-field distance of two hypotheses (docs/algorithm.md §3.5):
 * sqrt(mean over i in I_x u I_y of d_i^T W_i d_i), d_i = (R_x - R_y) a_i + (t_x - t_y);
 * 0 when both are empty.
 * \param[in] a points the inlier indices refer to (metres, previous camera frame)
 * \param[in] information W_i per point (the sensor model's, in 1 / sigma^2: the distance
 *            is in sigma), or empty for W_i = I (the paper's distance in metres)
 * Both in double: every pair of hypotheses reads them again, so the caller converts once.
 */
DYNVO_EXPORTS double motionFieldDistance(const MotionHypothesis& x,
                                         const MotionHypothesis& y,
                                         const std::vector<Eigen::Vector3d>& a,
                                         const std::vector<Eigen::Matrix3d>& information);

/// The three thresholds of the search in the unit of E_i (docs/algorithm.md §2).
struct DYNVO_EXPORTS ResidualThresholds {
  float inlier = 0.0f;  ///< th: E_i <= th is an inlier
  float lambda = 0.0f;  ///< entropy shape, per unit of E_i
  float epsilon = 0.0f; ///< DBSCAN radius, in the unit of sqrt(E_i)

  /// The paper model's th_inlier, lambda, eps (m^2, m^-2, m) or the sensor model's.
  static ResidualThresholds of(const RigidMotionSegmentationParameters& params);
};

/** \brief The two-frame segmentation of docs/algorithm.md §3 on the valid_3d cells of a grid.
 *
 * Entropy-weighted seeds (std::discrete_distribution on a std::mt19937 seeded with
 * params.seed at every call), m - 1 distinct neighbours within r_search cells, a 7-point fit
 * accepted when every sample point is an inlier, up to refine_iterations inlier/refit rounds,
 * the three stopping rules, DBSCAN with the motion-field distance, and labelling with
 * small-segment removal. The scratch buffers are kept between calls. Deterministic: the
 * result depends on the input and params only. One thread: each loop takes microseconds, and
 * DBSCAN computes only the distances it needs (NOTES.md, decision 11).
 */
class DYNVO_EXPORTS SpatialSegmenter {
public:
  /** \param[in] grid scene flow of the frame pair, with information for the sensor model
   *  \param[in] params validated parameters
   *  \param[out] result labels per cell and one motion per segment (all 0 and no segment
   *              when fewer than 2 m cells are valid_3d)
   */
  void segment(const GridFlowData& grid,
               const RigidMotionSegmentationParameters& params,
               SpatialSegmentationResult& result);

private:
  /// E_k of packed point k under a motion (R, t).
  float error(const Eigen::Matrix3f& R, const Eigen::Vector3f& t, int k) const;

  /// Fills errors_ with E_k(H) for every packed point.
  void evaluate(const Eigen::Matrix4d& H);

  /// Draws one hypothesis; false when the trial fails.
  bool tryHypothesis(const RigidMotionSegmentationParameters& params,
                     MotionHypothesis& hypothesis);

  /// DBSCAN of the accepted hypotheses; returns the cluster of each one.
  std::vector<int>
  clusterHypotheses(const RigidMotionSegmentationParameters& params) const;

  /// Labels the grid from the clusters and fills result (docs/algorithm.md §3.6).
  void label(const std::vector<int>& clusters,
             const RigidMotionSegmentationParameters& params,
             SpatialSegmentationResult& result);

  int cols_ = 0;                    ///< grid columns
  int rows_ = 0;                    ///< grid rows
  std::vector<int> packed_of_cell_; ///< packed index of each cell, -1 when not valid_3d
  std::vector<int> cell_of_packed_; ///< cell index of each packed point
  std::vector<Eigen::Vector3f> a_;  ///< packed a_i
  std::vector<Eigen::Vector3f> b_;  ///< packed b_i
  std::vector<Eigen::Matrix3f> w_;  ///< packed W_i, empty for the paper model
  ResidualThresholds th_;           ///< thresholds of this call
  std::vector<float> errors_;       ///< E_k of the hypothesis being evaluated
  std::vector<float> min_errors_;   ///< min over accepted hypotheses of E_k
  std::vector<double> entropy_;     ///< S_k
  std::vector<int> candidates_;     ///< neighbours of the current seed
  std::vector<int> sample_;         ///< the m sampled points
  std::vector<int> inliers_;        ///< inlier scratch
  std::vector<MotionHypothesis>
      accepted_; ///< hypotheses of this frame (packed indices)
  using Draw = std::discrete_distribution<int>;
  std::mt19937 rng_; ///< sampling RNG
  Draw draw_;        ///< seed distribution S_k / sum S, rebuilt on acceptance
};

} // namespace dynvo
