// SPDX-License-Identifier: BSD-3-Clause
// Motion segment tracking (docs/algorithm.md §4-§6).
#include <dynvo/motion_segmentation/segment_tracker.h>

#include <dynvo/common/conventions.h>
#include <dynvo/common/rigid_fit.h>

#include <pcl/console/print.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <numeric>
#include <tuple>
#include <utility>

namespace dynvo {

namespace {

/// Median of a non-empty list (upper median for even sizes).
float
median(std::vector<float>& values)
{
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

/// The segment (1..g) with label 1 in `ids`, 0 when none has.
int
labelOneSegment(const std::vector<int>& ids)
{
  const auto found = std::find(ids.begin() + 1, ids.end(), LABEL_STATIC);
  return found == ids.end() ? 0 : static_cast<int>(found - ids.begin());
}

} // namespace

double
correlateLabelMaps(const std::vector<std::uint8_t>& segments,
                   const std::vector<std::uint8_t>& past,
                   int segment_count,
                   int labels,
                   std::vector<double>& correlation)
{
  const int stride = labels + 1;
  std::vector<int> joint(static_cast<std::size_t>(segment_count + 1) * stride, 0);
  std::vector<int> n_i(segment_count + 1, 0), n_j(stride, 0);
  for (std::size_t c = 0; c < segments.size(); ++c) {
    const int i = segments[c];
    const int j = past[c] <= labels ? past[c] : 0;
    ++n_i[i];
    ++n_j[j];
    ++joint[static_cast<std::size_t>(i) * stride + j];
  }
  correlation.assign(joint.size(), 0.0);
  double weighted = 0.0;
  long total = 0;
  for (int i = 1; i <= segment_count; ++i) {
    double best = 0.0;
    for (int j = 1; j <= labels; ++j) {
      const int both = joint[static_cast<std::size_t>(i) * stride + j];
      if (both == 0)
        continue;
      const double c = both / std::sqrt(static_cast<double>(n_i[i]) * n_j[j]);
      correlation[static_cast<std::size_t>(i) * stride + j] = c;
      best = std::max(best, c);
    }
    weighted += n_i[i] * best;
    total += n_i[i];
  }
  return total == 0 ? 0.0 : weighted / static_cast<double>(total);
}

void
SegmentTracker::reset()
{
  buffer_.clear();
  labels_exhausted_ = false;
  model_ = DualLabelModel();
  source_.clear();
  tracked_.clear();
  fused_.clear();
  previous_fused_.clear();
  separated_.clear();
  ids_.clear();
  motions_.clear();
  ages_.clear();
}

std::vector<std::uint8_t>
SegmentTracker::warpNearest(const std::vector<std::uint8_t>& map,
                            const GridFlowData& grid) const
{
  std::vector<std::uint8_t> warped(grid.size(), 0);
  const float half = static_cast<float>(grid.cellSize() / 2);
  for (std::size_t i = 0; i < grid.size(); ++i) {
    const Eigen::Vector2f& p = source_[i];
    if (!p.allFinite())
      continue;
    const long a = std::lround((p.x() - half) / grid.cellSize());
    const long b = std::lround((p.y() - half) / grid.cellSize());
    if (a >= 0 && a < grid.cols() && b >= 0 && b < grid.rows())
      warped[i] = map[static_cast<std::size_t>(b) * grid.cols() + a];
  }
  return warped;
}

void
SegmentTracker::sourcePixels(const GridFlowData& grid,
                             const Eigen::Matrix4d& T_pred,
                             const CameraIntrinsics& intrinsics)
{
  const Eigen::Matrix3f R_t = T_pred.topLeftCorner<3, 3>().transpose().cast<float>();
  const Eigen::Vector3f t = T_pred.topRightCorner<3, 1>().cast<float>();
  source_.resize(grid.size());
  std::vector<float> dx, dy;
  for (std::size_t i = 0; i < grid.size(); ++i) {
    if (grid.valid_2d[i]) {
      source_[i] = grid.previous_pixel[i];
      continue;
    }
    const Eigen::Vector2f centre = grid.cellCentre(i);
    // (1) The point seen at c_i, moved back into frame k-1 by H_pred^-1, reprojected.
    if (grid.b[i].allFinite()) {
      const Eigen::Vector3f previous = R_t * (grid.b[i] - t);
      if (previous.z() > 0.0f) {
        source_[i] = intrinsics.project(previous);
        continue;
      }
    }
    // (2) Median displacement of the tracked 3x3 neighbours; (3) zero.
    dx.clear();
    dy.clear();
    const int col = static_cast<int>(i % grid.cols()),
              row = static_cast<int>(i / grid.cols());
    for (int r = std::max(0, row - 1); r <= std::min(grid.rows() - 1, row + 1); ++r)
      for (int c = std::max(0, col - 1); c <= std::min(grid.cols() - 1, col + 1); ++c) {
        const std::size_t j = static_cast<std::size_t>(r) * grid.cols() + c;
        if (!grid.valid_2d[j])
          continue;
        const Eigen::Vector2f d = grid.previous_pixel[j] - grid.cellCentre(j);
        dx.push_back(d.x());
        dy.push_back(d.y());
      }
    source_[i] = dx.empty() ? centre : centre + Eigen::Vector2f(median(dx), median(dy));
  }
}

void
SegmentTracker::collectUsedIds(int labels)
{
  used_.assign(labels + 1, 0);
  for (const auto& map : buffer_)
    for (const std::uint8_t l : map)
      used_[std::min<int>(l, labels)] = 1;
  for (std::size_t i = 0; i < model_.readOut().size(); ++i)
    used_[model_.argmax(DualLabelModel::Model::apparent, i)] = 1;
  used_[LABEL_STATIC] = 1;
  // A candidate alone does not keep an id: an object no apparent model and no recent frame
  // holds is gone, and its evidence would reserve the id for ever (a static real scene ran
  // out of labels) and hand a later, unrelated segment a head start.
  model_.forgetCandidates(used_);
}

int
SegmentTracker::freeId(const std::vector<int>& taken) const
{
  const int labels = static_cast<int>(used_.size()) - 1;
  for (int id = 2; id <= labels; ++id)
    if (!used_[id] && std::find(taken.begin(), taken.end(), id) == taken.end())
      return id;
  return 0;
}

std::vector<int>
SegmentTracker::matchSegments(const GridFlowData& grid,
                              const SpatialSegmentationResult& spatial,
                              const RigidMotionSegmentationParameters& params) const
{
  const int g = spatial.segmentCount();
  std::vector<int> ids(g + 1, 0);
  if (!hasHistory()) {
    // First pair: the background is the largest segment (paper model) or the segment whose
    // motion explains the most cells (sensor model: real backgrounds split into several
    // segments under noise, and a textured object can be the largest single one); the
    // others 2, 3, ... by size.
    const int background = grid.information.empty() ? 1 : widestConsensus(grid, spatial);
    int next = LABEL_STATIC + 1;
    for (int i = 1; i <= g; ++i)
      ids[i] = i == background ? LABEL_STATIC : (next <= params.max_labels ? next++ : 0);
    return ids;
  }
  // Correlation with every buffered frame; frames in order of score (ties: most recent).
  const int labels = params.max_labels;
  std::vector<std::vector<double>> correlation(buffer_.size());
  std::vector<std::pair<double, std::size_t>> frames;
  for (std::size_t l = 0; l < buffer_.size(); ++l)
    frames.emplace_back(
        -correlateLabelMaps(spatial.labels, buffer_[l], g, labels, correlation[l]), l);
  std::stable_sort(frames.begin(), frames.end());
  // Greedy one-to-one assignment on the best frame l_m; [D] segments left unmatched there
  // try the other buffered frames in score order, so an object missed in one frame keeps
  // its id.
  std::vector<char> taken(labels + 1, 0);
  for (const auto& frame : frames) {
    const std::vector<double>& C = correlation[frame.second];
    std::vector<std::tuple<double, int, int>> pairs;
    for (int i = 1; i <= g; ++i)
      for (int j = 1; j <= labels; ++j) {
        const double c = C[static_cast<std::size_t>(i) * (labels + 1) + j];
        if (ids[i] == 0 && !taken[j] && c >= params.min_correlation)
          pairs.emplace_back(-c, i, j);
      }
    std::sort(pairs.begin(), pairs.end());
    for (const auto& [c, i, j] : pairs)
      if (ids[i] == 0 && !taken[j]) {
        ids[i] = j;
        taken[j] = 1;
      }
  }
  // New ids for unmatched segments, largest first.
  for (int i = 1; i <= g; ++i)
    if (ids[i] == 0)
      ids[i] = freeId(ids);
  return ids;
}

bool
SegmentTracker::hasHistory() const
{
  return std::any_of(buffer_.begin(), buffer_.end(), [](const auto& map) {
    return std::any_of(map.begin(), map.end(), [](std::uint8_t l) {
      return l != 0;
    });
  });
}

int
SegmentTracker::widestConsensus(const GridFlowData& grid,
                                const SpatialSegmentationResult& spatial) const
{
  // Threshold of the segmentation's own inliers: every cell a segment's motion explains.
  const float limit = spatial.inlier_threshold;
  int best = 0;
  std::size_t best_count = 0;
  for (int c = 1; c <= spatial.segmentCount(); ++c) {
    const Eigen::Matrix4d& H = spatial.motions[c - 1];
    const Eigen::Matrix3f R = H.topLeftCorner<3, 3>().cast<float>();
    const Eigen::Vector3f t = H.topRightCorner<3, 1>().cast<float>();
    std::size_t count = 0;
    for (std::size_t i = 0; i < grid.size(); ++i)
      count += grid.valid_3d[i] && grid.error(i, R, t) <= limit ? 1 : 0;
    if (count > best_count) {
      best = c;
      best_count = count;
    }
  }
  return best;
}

void
SegmentTracker::guardBackground(const GridFlowData& grid,
                                const SpatialSegmentationResult& spatial,
                                const Eigen::Matrix4d& T_pred,
                                const RigidMotionSegmentationParameters& params,
                                std::vector<int>& ids) const
{
  const int g = spatial.segmentCount();
  if (g == 0)
    return;
  // r_pred(c): RMS residual of segment c under the constant-velocity prediction (metres).
  // [D] Sensor model: RMS distance between where the segment's motion and the prediction
  // move the points of every valid cell of the frame, so that depth noise (3 cm at 4 m)
  // does not count as a departure, and so that motions are compared over one scene: over
  // its own few cells a small segment's fit can agree with any motion (a sliver of the
  // background trades rotation for translation), over the whole scene it cannot.
  const bool sensor = !grid.information.empty();
  std::vector<double> sum(g + 1, 0.0);
  std::size_t valid = 0;
  for (std::size_t i = 0; i < grid.size(); ++i) {
    const Eigen::Vector3d a = grid.a[i].cast<double>();
    if (sensor) {
      if (!grid.valid_3d[i])
        continue;
      ++valid;
      for (int c = 1; c <= g; ++c)
        sum[c] += squaredTransferError(
            T_pred, a,
            Eigen::Vector3d((spatial.motions[c - 1] * a.homogeneous()).head<3>()));
    }
    else if (spatial.labels[i] != 0) {
      sum[spatial.labels[i]] +=
          squaredTransferError(T_pred, a, grid.b[i].cast<double>());
    }
  }
  // [D] Label 1 moves from a tracked background only to a segment of at least half its
  // cells (and n_static_min): a background does not lose half of itself in one frame. When
  // the former background fails the guard and only a smaller segment agrees with H_pred,
  // that is a sliver whose motion happens to pass (a blurred frame after a dropped one,
  // H_pred 5 cm off); the frame then has no background, and the pipeline segments it again
  // against its measured step. The first pair's label 1 is a guess, not a tracked
  // background (the paper model's largest segment may be a box covering most of the image).
  int min_cells = params.static_min_cells;
  for (int c = 1; c <= g; ++c)
    if (ids[c] == LABEL_STATIC && hasHistory())
      min_cells = std::max(min_cells, (spatial.sizes[c - 1] + 1) / 2);
  int c1 = 0, best = 0;
  std::vector<double> r(g + 1, 0.0);
  for (int c = 1; c <= g; ++c) {
    r[c] =
        std::sqrt(sum[c] / static_cast<double>(sensor ? std::max<std::size_t>(valid, 1)
                                                      : spatial.sizes[c - 1]));
    if (ids[c] == LABEL_STATIC)
      c1 = c;
    if (spatial.sizes[c - 1] >= min_cells && (best == 0 || r[c] < r[best]))
      best = c;
  }
  const double tau = params.static_guard_tolerance;
  const bool c1_fails = c1 != 0 && r[c1] > tau;
  if (best != 0 && r[best] <= tau && best != c1 && (c1 == 0 || c1_fails)) {
    const int previous = ids[best];
    ids[best] = LABEL_STATIC;
    if (c1 != 0)
      ids[c1] = previous != 0 ? previous : freeId(ids);
    PCL_DEBUG("[dynvo::SegmentTracker::update] label 1 moved to a segment of %d cells "
              "(r_pred %.3f m).\n",
              spatial.sizes[best - 1], r[best]);
  }
  else if (c1_fails) {
    // [D] No segment agrees with H_pred: no cell is static, and the former background is
    // left unmeasured this frame rather than turned into an object.
    ids[c1] = 0;
    PCL_DEBUG(
        "[dynvo::SegmentTracker::update] no segment agrees with H_pred; no label 1.\n");
  }
}

void
SegmentTracker::mergeNoiseSplits(const GridFlowData& grid,
                                 const SpatialSegmentationResult& spatial,
                                 const RigidMotionSegmentationParameters& params,
                                 std::vector<int>& ids) const
{
  const int g = spatial.segmentCount();
  const int background = labelOneSegment(ids);
  if (grid.information.empty() || background == 0)
    return;
  const Eigen::Matrix4d& H = spatial.motions[background - 1];
  const Eigen::Matrix3f R = H.topLeftCorner<3, 3>().cast<float>();
  const Eigen::Vector3f t = H.topRightCorner<3, 1>().cast<float>();
  std::vector<std::vector<float>> errors(g + 1);
  for (std::size_t i = 0; i < grid.size(); ++i) {
    const int c = spatial.labels[i];
    if (c != 0 && ids[c] != LABEL_STATIC)
      errors[c].push_back(grid.error(i, R, t));
  }
  for (int c = 1; c <= g; ++c)
    if (!errors[c].empty() && median(errors[c]) <= 0.5f * params.inlier_chi2)
      ids[c] = LABEL_STATIC;
}

void
SegmentTracker::findAmbiguousObjects(const GridFlowData& grid,
                                     const SpatialSegmentationResult& spatial,
                                     const std::vector<int>& ids,
                                     int background,
                                     const CameraIntrinsics& intrinsics,
                                     const FramePairColours& colours,
                                     const RigidMotionSegmentationParameters& params)
{
  ambiguous_.assign(256, 0);
  const int radius = params.ambiguity_search_radius;
  if (radius <= 0 || background == 0 || colours.empty() ||
      colours.width != static_cast<int>(grid.geometry.image_width) ||
      colours.height != static_cast<int>(grid.geometry.image_height))
    return;
  const Eigen::Matrix4f H_inverse =
      rigidInverse(spatial.motions[background - 1]).cast<float>();
  const int g = spatial.segmentCount();
  // Per segment: its cells, and each far cell with its background position.
  std::vector<int> cells(g + 1, 0);
  std::vector<std::vector<std::pair<std::size_t, Eigen::Vector2f>>> far(g + 1);
  const auto far_limit = static_cast<float>(2 * radius);
  for (std::size_t i = 0; i < grid.size(); ++i) {
    const int c = spatial.labels[i];
    if (c == 0 || ids[c] <= LABEL_STATIC || !grid.valid_2d[i] || !grid.valid_3d[i])
      continue;
    const Eigen::Vector3f a_background =
        (H_inverse * grid.b[i].homogeneous()).head<3>();
    if (!(a_background.z() > 0.0f))
      continue;
    ++cells[c];
    const Eigen::Vector2f& p = grid.previous_pixel[i];
    const Eigen::Vector2f q =
        p + intrinsics.project(a_background) - intrinsics.project(grid.a[i]);
    if ((q - p).norm() > far_limit)
      far[c].emplace_back(i, q);
  }
  // The image is compared (the costly part) only while the segment's outcome is open: at
  // least half of its cells far, then until half of those are ambiguous or can no longer be.
  for (int c = 1; c <= g; ++c) {
    const auto n_far = static_cast<int>(far[c].size());
    if (n_far == 0 || 2 * n_far < cells[c])
      continue;
    int ambiguous = 0;
    int left = n_far;
    for (const auto& [i, q] : far[c]) {
      if (2 * ambiguous >= n_far || 2 * (ambiguous + left) < n_far)
        break;
      --left;
      if (trackIsAmbiguous(colours, grid.cellCentre(i), grid.previous_pixel[i], q,
                           radius))
        ++ambiguous;
    }
    if (2 * ambiguous >= n_far)
      ambiguous_[static_cast<std::size_t>(ids[c])] = 1;
  }
}

void
SegmentTracker::keepObjectsApart(const GridFlowData& grid,
                                 const SpatialSegmentationResult& spatial,
                                 const std::vector<int>& ids,
                                 const RigidMotionSegmentationParameters& params)
{
  const double ratio = params.object_separation_ratio;
  if (ratio <= 0.0 || previous_fused_.size() != grid.size()) {
    separated_.clear();
    return;
  }
  const std::vector<std::uint8_t> previous = warpNearest(previous_fused_, grid);
  const int g = spatial.segmentCount();
  const int labels = params.max_labels;
  std::vector<int> segment_of(labels + 1, 0); // segment matched to each object id
  for (int c = 1; c <= g; ++c)
    if (ids[c] > LABEL_STATIC && ids[c] <= labels)
      segment_of[ids[c]] = c;
  const auto n_min = static_cast<std::size_t>(params.static_min_cells);
  separated_.resize(labels + 1, 0);
  // Objects kept apart this frame; one kept apart before and still present as its own
  // segment stays separated, so it is held with the lower ratio when it merges again.
  std::vector<char> held(labels + 1, 0);
  for (int m = LABEL_STATIC + 1; m <= labels; ++m)
    held[m] = separated_[m] && segment_of[m] != 0;
  const auto pair = [&grid](std::size_t i) {
    return std::make_pair(grid.a[i].cast<double>(), grid.b[i].cast<double>());
  };
  // The former background cells of every label-1 segment: the reference of a segment with
  // too few of its own, an object merged whole into the background (its own segment, handed
  // to label 1 by the noise-split merge). Gathered only when such a segment comes.
  std::optional<RigidFitAccumulator> former_background;
  for (int c = 1; c <= g; ++c) {
    if (ids[c] != LABEL_STATIC)
      continue;
    const auto in_segment = [&](std::size_t i) {
      return spatial.labels[i] == c && grid.valid_3d[i];
    };
    // One fit per previous label of the segment's cells.
    std::vector<RigidFitAccumulator> fits(labels + 1);
    for (std::size_t i = 0; i < grid.size(); ++i)
      if (in_segment(i) && previous[i] != 0 && previous[i] <= labels) {
        const auto [a, b] = pair(i);
        fits[previous[i]].add(a, b);
      }
    // The background's motion where the segment is: a fit on its own former background
    // cells (one fit over all of them for every segment was worse on tum_fr1_desk_fast).
    if (fits[LABEL_STATIC].size() < n_min && !former_background) {
      former_background.emplace();
      for (std::size_t i = 0; i < grid.size(); ++i)
        if (spatial.labels[i] != 0 && ids[spatial.labels[i]] == LABEL_STATIC &&
            grid.valid_3d[i] && previous[i] == LABEL_STATIC) {
          const auto [a, b] = pair(i);
          former_background->add(a, b);
        }
    }
    const RigidFitAccumulator& reference =
        fits[LABEL_STATIC].size() >= n_min ? fits[LABEL_STATIC] : *former_background;
    Eigen::Matrix4d H_background;
    if (reference.size() < n_min || reference.solve(H_background) != RigidFitStatus::ok)
      continue;
    // Each object with former cells here: its motion (its own segment's, else a fit on those
    // cells) and the cells' residual sums under it and under the background's.
    std::vector<Eigen::Matrix4d> H(labels + 1);
    std::vector<char> tested(labels + 1, 0);
    for (int m = LABEL_STATIC + 1; m <= labels; ++m) {
      if (fits[m].size() == 0)
        continue;
      if (segment_of[m] != 0)
        H[m] = spatial.motions[segment_of[m] - 1];
      else if (fits[m].size() < std::max<std::size_t>(n_min, 7) ||
               fits[m].solve(H[m]) !=
                   RigidFitStatus::ok) // 7: see the n / (n - 6) below
        continue;
      tested[m] = 1;
    }
    std::vector<double> e_background(labels + 1, 0.0), e_object(labels + 1, 0.0);
    for (std::size_t i = 0; i < grid.size(); ++i) {
      const int m = previous[i];
      if (m > LABEL_STATIC && m <= labels && tested[m] && in_segment(i)) {
        const auto [a, b] = pair(i);
        e_background[m] += squaredTransferError(H_background, a, b);
        e_object[m] += squaredTransferError(H[m], a, b);
      }
    }
    // Objects whose former cells fit the background's motion `ratio` times worse (RMS)
    // than their own keep those cells; an object already kept apart needs only
    // object_separation_hold times worse.
    std::vector<char> kept(labels + 1, 0);
    std::vector<int> apart;
    for (int m = LABEL_STATIC + 1; m <= labels; ++m) {
      if (!tested[m])
        continue;
      // A motion fitted on these very cells used up 6 degrees of freedom of their residual.
      if (segment_of[m] == 0)
        e_object[m] *= static_cast<double>(fits[m].size()) /
                       static_cast<double>(fits[m].size() - 6);
      const double k = separated_[m] ? params.object_separation_hold : ratio;
      if (e_background[m] > k * k * e_object[m]) {
        kept[m] = held[m] = 1;
        apart.push_back(m);
      }
    }
    if (apart.empty())
      continue;
    // Their cells keep their label; cells without a previous label go to the motion they fit
    // best, so the object's newly seen cells do not leak into the background frame after frame.
    for (std::size_t i = 0; i < grid.size(); ++i) {
      if (spatial.labels[i] != c)
        continue;
      const int m = previous[i];
      if (m > LABEL_STATIC && m <= labels && kept[m]) {
        tracked_[i] = static_cast<std::uint8_t>(m);
        continue;
      }
      if (m != 0 || !grid.valid_3d[i])
        continue;
      const auto [a, b] = pair(i);
      double best = squaredTransferError(H_background, a, b);
      for (const int object : apart) {
        const double e = squaredTransferError(H[object], a, b);
        if (e < best) {
          best = e;
          tracked_[i] = static_cast<std::uint8_t>(object);
        }
      }
    }
  }
  separated_ = held;
}

void
SegmentTracker::collectOutputs(const GridFlowData& grid,
                               const SpatialSegmentationResult& spatial,
                               const std::vector<int>& segment_ids,
                               const Eigen::Matrix4d& T_pred)
{
  const std::vector<std::uint8_t>& model = model_.readOut();
  fused_.resize(grid.size());
  std::vector<char> present(256, 0);
  for (std::size_t i = 0; i < grid.size(); ++i) {
    const std::uint8_t t = tracked_[i], l = model[i];
    fused_[i] = t > LABEL_STATIC ? t : (l > LABEL_STATIC ? l : t);
    present[fused_[i]] = 1;
  }
  ids_.assign(1, LABEL_STATIC);
  for (int id = LABEL_STATIC + 1; id < 256; ++id)
    if (present[id])
      ids_.push_back(static_cast<std::uint8_t>(id));
  motions_.clear();
  for (const std::uint8_t id : ids_) {
    const auto matched = std::find(segment_ids.begin() + 1, segment_ids.end(), id);
    if (matched != segment_ids.end()) {
      motions_.push_back(spatial.motions[matched - segment_ids.begin() - 1]);
      continue;
    }
    RigidFitAccumulator fit;
    for (std::size_t i = 0; i < grid.size(); ++i)
      if (fused_[i] == id && grid.valid_3d[i])
        fit.add(grid.a[i].cast<double>(), grid.b[i].cast<double>());
    Eigen::Matrix4d H = id == LABEL_STATIC ? T_pred : Eigen::Matrix4d::Identity();
    fit.solve(H); // keeps the fallback when the cells do not determine a motion
    motions_.push_back(H);
  }
}

bool
SegmentTracker::clearlyApart(const GridFlowData& grid, std::uint8_t id, double ratio) const
{
  const auto at = std::find(ids_.begin(), ids_.end(), id);
  const Eigen::Matrix4d& H_object = motions_[at - ids_.begin()];
  const Eigen::Matrix4d& H_background = motions_.front();
  double e_background = 0.0, e_object = 0.0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < grid.size(); ++i)
    if (fused_[i] == id && grid.valid_3d[i]) {
      const Eigen::Vector3d a = grid.a[i].cast<double>(), b = grid.b[i].cast<double>();
      e_background += squaredTransferError(H_background, a, b);
      e_object += squaredTransferError(H_object, a, b);
      ++n;
    }
  // The object's motion was fitted on these cells: 6 degrees of freedom of their residual.
  return n > 6 && e_background > ratio * ratio * e_object * static_cast<double>(n) /
                                     static_cast<double>(n - 6);
}

void
SegmentTracker::updateAges(const GridFlowData& grid,
                           const RigidMotionSegmentationParameters& params)
{
  constexpr int OLD = std::numeric_limits<int>::max();
  ages_.resize(256, 0);
  std::vector<char> measured(256, 0);
  for (const std::uint8_t id : tracked_)
    measured[id] = 1;
  const std::vector<std::uint8_t> previous =
      previous_fused_.size() == grid.size() ? warpNearest(previous_fused_, grid)
                                            : std::vector<std::uint8_t>(grid.size(), 0);
  std::vector<int> next(256, 0);
  for (const std::uint8_t id : ids_) {
    if (id == LABEL_STATIC)
      continue;
    int age = ages_[id];
    if (age == 0) {
      // A new id over cells that mostly held one object: that object under a new id.
      std::array<int, 256> held{};
      int cells = 0;
      for (std::size_t i = 0; i < grid.size(); ++i)
        if (fused_[i] == id) {
          ++cells;
          ++held[previous[i]];
        }
      const auto most = std::max_element(held.begin() + LABEL_STATIC + 1, held.end());
      if (2 * *most >= cells)
        age = ages_[most - held.begin()];
    }
    if (age != OLD && measured[id] && params.object_birth_ratio > 0.0f &&
        clearlyApart(grid, id, params.object_birth_ratio))
      age = OLD;
    if (age == OLD)
      next[id] = OLD;
    else if (measured[id])
      next[id] = age + 1;
    else // a young object counts consecutive frames: a break starts its count again
      next[id] = age >= params.object_birth_frames ? age : 0;
  }
  ages_ = std::move(next);
}

void
SegmentTracker::update(const GridFlowData& grid,
                       const SpatialSegmentationResult& spatial,
                       const Eigen::Matrix4d& T_pred,
                       const CameraIntrinsics& intrinsics,
                       const RigidMotionSegmentationParameters& params,
                       const FramePairColours& colours)
{
  if (model_.cols() != grid.cols() || model_.rows() != grid.rows() ||
      model_.labels() != params.max_labels) {
    if (model_.cols() != 0)
      PCL_DEBUG(
          "[dynvo::SegmentTracker::update] grid or label count changed; restarting.\n");
    reset();
    model_.reset(grid.cols(), grid.rows(), params.max_labels);
  }
  collectUsedIds(params.max_labels);
  // §6's source of every cell, also the one every map of the past is warped through.
  sourcePixels(grid, T_pred, intrinsics);
  for (auto& map : buffer_)
    map = warpNearest(map, grid);

  // §4: persistent ids for this frame's segments.
  std::vector<int> ids = matchSegments(grid, spatial, params);
  // Busy real scenes run out of labels over and over: said once per sequence.
  if (!labels_exhausted_ && std::find(ids.begin() + 1, ids.end(), 0) != ids.end()) {
    PCL_WARN("[dynvo::SegmentTracker::update] all %d labels in use: segments without a "
             "free label are left unlabelled (said once per sequence).\n",
             params.max_labels);
    labels_exhausted_ = true;
  }
  // [D] The guard needs a prediction: none exists for the first pair of a sequence (the
  // pipeline's identity would hand label 1 to whatever moves least in the image).
  if (grid.information.empty() || hasHistory())
    guardBackground(grid, spatial, T_pred, params, ids);
  const int background = labelOneSegment(ids);
  mergeNoiseSplits(grid, spatial, params, ids);
  tracked_.resize(grid.size());
  for (std::size_t i = 0; i < grid.size(); ++i)
    tracked_[i] = static_cast<std::uint8_t>(ids[spatial.labels[i]]);
  findAmbiguousObjects(grid, spatial, ids, background, intrinsics, colours, params);
  keepObjectsApart(grid, spatial, ids, params);

  // §6 then §5: carry the models into the current grid, fold in Ghat, read out L.
  model_.compensate(source_, grid.valid_2d, grid.cellSize());
  model_.update(tracked_, params.max_age);

  collectOutputs(grid, spatial, ids, T_pred);
  updateAges(grid, params);
  previous_fused_ = fused_;
  buffer_.push_front(tracked_);
  while (static_cast<int>(buffer_.size()) > params.buffer_length)
    buffer_.pop_back();
}

} // namespace dynvo
