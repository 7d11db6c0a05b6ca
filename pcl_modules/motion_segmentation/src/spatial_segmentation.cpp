// SPDX-License-Identifier: BSD-3-Clause
// Two-frame rigid motion segmentation (docs/algorithm.md §3).
#include <dynvo/motion_segmentation/spatial_segmentation.h>

#include <dynvo/common/rigid_fit.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <functional>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <utility>

namespace dynvo {

namespace {

/// Rotation and translation of H in float, for the per-point error loops.
struct RigidF {
  Eigen::Matrix3f R;
  Eigen::Vector3f t;
  explicit RigidF(const Eigen::Matrix4d& H)
      : R(H.topLeftCorner<3, 3>().cast<float>())
      , t(H.topRightCorner<3, 1>().cast<float>())
  {
  }
};

/// Least-squares fit (docs/algorithm.md §2) of b = H a on the listed points; false when degenerate.
bool
fitRigidMotion(const std::vector<Eigen::Vector3f>& a,
               const std::vector<Eigen::Vector3f>& b,
               const std::vector<int>& indices,
               Eigen::Matrix4d& T_b_a)
{
  RigidFitAccumulator fit;
  for (const int k : indices)
    fit.add(a[k].cast<double>(), b[k].cast<double>());
  return fit.solve(T_b_a) == RigidFitStatus::ok;
}

/// Points whose error is within the threshold, ascending.
void
collectInliers(const std::vector<float>& errors,
               float threshold,
               std::vector<int>& inliers)
{
  inliers.clear();
  for (std::size_t k = 0; k < errors.size(); ++k)
    if (errors[k] <= threshold)
      inliers.push_back(static_cast<int>(k));
}

} // namespace

std::vector<int>
dbscan(int count, int min_points, const std::function<bool(int, int)>& neighbours)
{
  constexpr int UNASSIGNED = -1;
  std::vector<int> cluster(static_cast<std::size_t>(count), UNASSIGNED);
  if (min_points <= 1) {
    // Connected components: each pair joins two trees of a union-find forest unless one
    // tree already holds both, whose test is then not needed (on a real frame most pairs
    // of the 20 hypotheses describe the background and fall into one tree early).
    std::vector<int> parent(static_cast<std::size_t>(count));
    std::iota(parent.begin(), parent.end(), 0);
    const auto root = [&](int i) {
      while (parent[i] != i)
        i = parent[i] = parent[parent[i]];
      return i;
    };
    for (int i = 0; i < count; ++i)
      for (int j = i + 1; j < count; ++j) {
        const int ri = root(i), rj = root(j);
        // Each root stays its tree's smallest item.
        if (ri != rj && neighbours(i, j))
          parent[std::max(ri, rj)] = std::min(ri, rj);
      }
    int next_cluster = 0;
    for (int i = 0; i < count; ++i) {
      const int r = root(i);
      cluster[i] = r == i ? next_cluster++ : cluster[r];
    }
    return cluster;
  }
  // Each pair tested once, kept for the other item's neighbourhood.
  enum : char { UNKNOWN, NEAR, FAR };
  std::vector<char> tested(static_cast<std::size_t>(count) * count, UNKNOWN);
  const auto near = [&](int i, int j) {
    if (i == j)
      return true;
    const int a = std::min(i, j), b = std::max(i, j);
    char& t = tested[static_cast<std::size_t>(a) * count + b];
    if (t == UNKNOWN)
      t = neighbours(a, b) ? NEAR : FAR;
    return t == NEAR;
  };
  std::vector<char> visited(static_cast<std::size_t>(count), 0);
  const auto neighbourhood = [&](int i) {
    std::vector<int> result;
    for (int j = 0; j < count; ++j)
      if (near(i, j))
        result.push_back(j);
    return result;
  };
  int next_cluster = 0;
  for (int i = 0; i < count; ++i) {
    if (visited[i])
      continue;
    visited[i] = 1;
    std::vector<int> queue = neighbourhood(i);
    if (static_cast<int>(queue.size()) < min_points)
      continue; // noise unless a later core point reaches it
    const int id = next_cluster++;
    cluster[i] = id;
    for (std::size_t q = 0; q < queue.size(); ++q) {
      const int j = queue[q];
      if (!visited[j]) {
        visited[j] = 1;
        const std::vector<int> more = neighbourhood(j);
        if (static_cast<int>(more.size()) >= min_points)
          queue.insert(queue.end(), more.begin(), more.end());
      }
      if (cluster[j] == UNASSIGNED)
        cluster[j] = id;
    }
  }
  return cluster;
}

ResidualThresholds
ResidualThresholds::of(const RigidMotionSegmentationParameters& params)
{
  if (params.residual_model == ResidualModel::paper)
    return {params.inlier_threshold, params.entropy_lambda, params.dbscan_epsilon};
  return {params.inlier_chi2, params.sensor_entropy_lambda,
          params.sensor_dbscan_epsilon};
}

double
motionFieldDistance(const MotionHypothesis& x,
                    const MotionHypothesis& y,
                    const std::vector<Eigen::Vector3d>& a,
                    const std::vector<Eigen::Matrix3d>& information)
{
  const Eigen::Matrix3d dR =
      x.T_curr_prev.topLeftCorner<3, 3>() - y.T_curr_prev.topLeftCorner<3, 3>();
  const Eigen::Vector3d dt =
      x.T_curr_prev.topRightCorner<3, 1>() - y.T_curr_prev.topRightCorner<3, 1>();
  double sum = 0.0;
  std::size_t n = 0;
  const auto add = [&](int i) {
    const Eigen::Vector3d d = dR * a[i] + dt;
    sum += information.empty() ? d.squaredNorm() : d.dot(information[i] * d);
    ++n;
  };
  // Merge of the two ascending inlier lists: every index of the union once.
  auto p = x.inliers.begin();
  auto q = y.inliers.begin();
  while (p != x.inliers.end() || q != y.inliers.end()) {
    if (q == y.inliers.end() || (p != x.inliers.end() && *p < *q))
      add(*p++);
    else if (p == x.inliers.end() || *q < *p)
      add(*q++);
    else {
      add(*p++);
      ++q;
    }
  }
  return n == 0 ? 0.0 : std::sqrt(sum / static_cast<double>(n));
}

float
SpatialSegmenter::error(const Eigen::Matrix3f& R, const Eigen::Vector3f& t, int k) const
{
  // Paper eq. 1, E_k = ||R a + t - b||^2, or its Mahalanobis form e^T W_k e.
  const Eigen::Vector3f e = R * a_[k] + t - b_[k];
  return w_.empty() ? e.squaredNorm() : e.dot(w_[k] * e);
}

void
SpatialSegmenter::evaluate(const Eigen::Matrix4d& H)
{
  const RigidF m(H);
  const int n = static_cast<int>(a_.size());
  errors_.resize(a_.size());
  for (int k = 0; k < n; ++k)
    errors_[k] = error(m.R, m.t, k);
}

bool
SpatialSegmenter::tryHypothesis(const RigidMotionSegmentationParameters& params,
                                MotionHypothesis& hypothesis)
{
  // 1. Seed drawn with probability S_k / sum S.
  const int seed = draw_(rng_);
  // 2. m - 1 distinct valid neighbours within the Chebyshev window.
  const int cell = cell_of_packed_[seed];
  const int col = cell % cols_;
  const int row = cell / cols_;
  const int r = params.search_radius;
  candidates_.clear();
  for (int y = std::max(0, row - r); y <= std::min(rows_ - 1, row + r); ++y)
    for (int x = std::max(0, col - r); x <= std::min(cols_ - 1, col + r); ++x) {
      const int k = packed_of_cell_[static_cast<std::size_t>(y) * cols_ + x];
      if (k >= 0 && k != seed)
        candidates_.push_back(k);
    }
  const int needed = params.sample_size - 1;
  if (static_cast<int>(candidates_.size()) < needed)
    return false;
  sample_.assign(1, seed);
  for (int s = 0; s < needed; ++s) {
    std::uniform_int_distribution<int> pick(s,
                                            static_cast<int>(candidates_.size()) - 1);
    std::swap(candidates_[s], candidates_[pick(rng_)]);
    sample_.push_back(candidates_[s]);
  }
  // 3. Fit on the sample; every sample point must be an inlier.
  Eigen::Matrix4d H;
  if (!fitRigidMotion(a_, b_, sample_, H))
    return false;
  const RigidF m(H);
  for (const int k : sample_)
    if (error(m.R, m.t, k) > th_.inlier)
      return false;
  // §3.3 refinement: inliers of all points, refit, until the set stops changing.
  std::vector<int>& inliers = hypothesis.inliers;
  for (int round = 0; round < params.refine_iterations; ++round) {
    evaluate(H);
    collectInliers(errors_, th_.inlier, inliers_);
    if (round > 0 && inliers_ == inliers)
      break;
    if (static_cast<int>(inliers_.size()) < params.sample_size)
      return false;
    if (!fitRigidMotion(a_, b_, inliers_, H))
      return false;
    inliers.swap(inliers_);
  }
  evaluate(H);
  collectInliers(errors_, th_.inlier, inliers);
  if (static_cast<int>(inliers.size()) < params.sample_size)
    return false;
  // [D] A refit that drifted off its own sample describes other points, not the sample's motion.
  for (const int k : sample_)
    if (errors_[k] > th_.inlier)
      return false;
  hypothesis.T_curr_prev = H;
  return true;
}

std::vector<int>
SpatialSegmenter::clusterHypotheses(
    const RigidMotionSegmentationParameters& params) const
{
  const int h = static_cast<int>(accepted_.size());
  // Converted once for all pairs (exact: every float is a double).
  std::vector<Eigen::Vector3d> a(a_.size());
  std::transform(a_.begin(), a_.end(), a.begin(), [](const Eigen::Vector3f& p) {
    return p.cast<double>();
  });
  std::vector<Eigen::Matrix3d> w(w_.size());
  std::transform(w_.begin(), w_.end(), w.begin(), [](const Eigen::Matrix3f& m) {
    return m.cast<double>();
  });
  // Each pair is a pass over two inlier lists (about 2 us on a real frame): DBSCAN asks
  // only for the pairs it needs.
  return dbscan(h, params.dbscan_min_points, [&](int i, int j) {
    return motionFieldDistance(accepted_[i], accepted_[j], a, w) <= th_.epsilon;
  });
}

void
SpatialSegmenter::label(const std::vector<int>& clusters,
                        const RigidMotionSegmentationParameters& params,
                        SpatialSegmentationResult& result)
{
  // 1. One motion per cluster, fitted on the union of its members' inliers.
  const int cluster_count =
      clusters.empty() ? 0 : *std::max_element(clusters.begin(), clusters.end()) + 1;
  const std::size_t n = a_.size();
  std::vector<Eigen::Matrix4d> motions;
  std::vector<char> member(n);
  for (int c = 0; c < cluster_count; ++c) {
    std::fill(member.begin(), member.end(), 0);
    for (std::size_t h = 0; h < accepted_.size(); ++h)
      if (clusters[h] == c)
        for (const int k : accepted_[h].inliers)
          member[k] = 1;
    inliers_.clear();
    for (std::size_t k = 0; k < n; ++k)
      if (member[k])
        inliers_.push_back(static_cast<int>(k));
    Eigen::Matrix4d H;
    if (fitRigidMotion(a_, b_, inliers_, H))
      motions.push_back(H);
  }
  // 2. Each point takes the motion explaining it best, if within th_inlier.
  std::vector<RigidF> rigid;
  for (const Eigen::Matrix4d& H : motions)
    rigid.emplace_back(H);
  std::vector<int> assigned(n, -1);
  const int count = static_cast<int>(n);
  for (int k = 0; k < count; ++k) {
    float best = std::numeric_limits<float>::infinity();
    for (std::size_t c = 0; c < rigid.size(); ++c) {
      const float e = error(rigid[c].R, rigid[c].t, k);
      if (e < best) {
        best = e;
        assigned[k] = static_cast<int>(c);
      }
    }
    if (!(best <= th_.inlier))
      assigned[k] = -1;
  }
  std::vector<int> sizes(motions.size(), 0);
  for (const int c : assigned)
    if (c >= 0)
      ++sizes[c];
  // 3. Dissolve small segments, renumber by size (largest first), refit on final points.
  std::vector<int> order;
  for (std::size_t c = 0; c < motions.size(); ++c)
    if (sizes[c] >= params.min_segment_size)
      order.push_back(static_cast<int>(c));
  std::stable_sort(order.begin(), order.end(), [&](int x, int y) {
    return sizes[x] > sizes[y];
  });
  std::vector<int> new_label(motions.size(), 0);
  for (std::size_t r = 0; r < order.size(); ++r)
    new_label[order[r]] = static_cast<int>(r) + 1;
  for (std::size_t k = 0; k < n; ++k) {
    const int g = assigned[k] >= 0 ? new_label[assigned[k]] : 0;
    result.labels[cell_of_packed_[k]] = static_cast<std::uint8_t>(g);
  }
  for (std::size_t r = 0; r < order.size(); ++r) {
    inliers_.clear();
    for (std::size_t k = 0; k < n; ++k)
      if (assigned[k] == order[r])
        inliers_.push_back(static_cast<int>(k));
    Eigen::Matrix4d H = motions[order[r]];
    fitRigidMotion(a_, b_, inliers_, H); // keeps the cluster fit if this one fails
    result.motions.push_back(H);
    result.sizes.push_back(sizes[order[r]]);
  }
}

void
SpatialSegmenter::segment(const GridFlowData& grid,
                          const RigidMotionSegmentationParameters& params,
                          SpatialSegmentationResult& result)
{
  th_ = ResidualThresholds::of(params);
  result.inlier_threshold = th_.inlier;
  if ((params.residual_model == ResidualModel::sensor) !=
      (grid.information.size() == grid.size()))
    throw std::invalid_argument(
        "[dynvo::SpatialSegmenter::segment] the sensor model needs the grid's "
        "information matrices (GridFlowData::setSensorNoise), the paper model none");
  result.labels.assign(grid.size(), 0);
  result.motions.clear();
  result.sizes.clear();
  result.hypotheses.clear();
  result.trials = 0;
  cols_ = grid.cols();
  rows_ = grid.rows();
  packed_of_cell_.assign(grid.size(), -1);
  cell_of_packed_.clear();
  a_.clear();
  b_.clear();
  w_.clear();
  for (std::size_t i = 0; i < grid.size(); ++i)
    if (grid.valid_3d[i]) {
      packed_of_cell_[i] = static_cast<int>(cell_of_packed_.size());
      cell_of_packed_.push_back(static_cast<int>(i));
      a_.push_back(grid.a[i]);
      b_.push_back(grid.b[i]);
      if (!grid.information.empty())
        w_.push_back(grid.information[i]);
    }
  const std::size_t n = a_.size();
  if (static_cast<int>(n) < 2 * params.sample_size)
    return;

  // §3.1-3.4: entropy-weighted hypothesis search.
  rng_.seed(params.seed);
  accepted_.clear();
  entropy_.assign(n, 1.0);
  min_errors_.assign(n, std::numeric_limits<float>::infinity());
  draw_.param(Draw::param_type(entropy_.begin(), entropy_.end()));
  double previous_mean = 1.0;
  MotionHypothesis hypothesis;
  while (static_cast<int>(accepted_.size()) < params.max_hypotheses &&
         result.trials < params.max_trials) {
    ++result.trials;
    if (!tryHypothesis(params, hypothesis))
      continue;
    // errors_ holds E_k of the accepted hypothesis: fold it into the entropy.
    double sum = 0.0;
    for (std::size_t k = 0; k < n; ++k) {
      min_errors_[k] = std::min(min_errors_[k], errors_[k]);
      entropy_[k] = 1.0 - std::exp(-static_cast<double>(params.entropy_delta) -
                                   static_cast<double>(th_.lambda) * min_errors_[k]);
      sum += entropy_[k];
    }
    accepted_.push_back(hypothesis);
    draw_.param(Draw::param_type(entropy_.begin(), entropy_.end()));
    const double mean = sum / static_cast<double>(n);
    if (accepted_.size() >= 2 && mean <= params.entropy_done &&
        previous_mean - mean <= params.entropy_saturation)
      break;
    previous_mean = mean;
  }

  // §3.5-3.6: cluster the hypotheses, label the grid.
  const std::vector<int> clusters = clusterHypotheses(params);
  label(clusters, params, result);
  for (const MotionHypothesis& h : accepted_) {
    MotionHypothesis& out = result.hypotheses.emplace_back();
    out.T_curr_prev = h.T_curr_prev;
    for (const int k : h.inliers)
      out.inliers.push_back(cell_of_packed_[k]);
  }
}

} // namespace dynvo
