// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/scene_flow/grid_flow_engine.h>

#include <dynvo/common/parallel.h>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "lucas_kanade.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <deque>
#include <limits>
#include <stdexcept>
#include <string>

namespace dynvo {

namespace detail {

namespace {

constexpr float NaN = std::numeric_limits<float>::quiet_NaN();
/// docs/algorithm.md §1.2: the 3x3 median replacing a missing centre depth needs 3 valid neighbours.
constexpr int MIN_CENTRE_NEIGHBOURS = 3;

/// Depth b_i at the integer cell centre, or NaN (docs/algorithm.md §1.2).
float
centreDepth(const std::vector<float>& depth, int width, int height, int u, int v)
{
  const float z = depth[static_cast<std::size_t>(v) * width + u];
  if (!std::isnan(z))
    return z;
  std::array<float, 8> values;
  int n = 0;
  for (int y = std::max(v - 1, 0); y <= std::min(v + 1, height - 1); ++y)
    for (int x = std::max(u - 1, 0); x <= std::min(u + 1, width - 1); ++x) {
      const float q = depth[static_cast<std::size_t>(y) * width + x];
      if (!std::isnan(q))
        values[n++] = q;
    }
  if (n < MIN_CENTRE_NEIGHBOURS)
    return NaN;
  // Upper middle element, the median definition DepthPreprocessing uses as well.
  std::nth_element(values.begin(), values.begin() + n / 2, values.begin() + n);
  return values[n / 2];
}

/// Depth a_i at a sub-pixel position inside [0, width-2] x [0, height-2] (docs/algorithm.md §1.2).
float
trackedDepth(const std::vector<float>& depth, int width, cv::Point2f p, float tau_edge)
{
  const int x0 = static_cast<int>(std::floor(p.x));
  const int y0 = static_cast<int>(std::floor(p.y));
  const float fx = p.x - static_cast<float>(x0);
  const float fy = p.y - static_cast<float>(y0);
  const float* row0 = depth.data() + static_cast<std::size_t>(y0) * width + x0;
  const float* row1 = row0 + width;
  const float z00 = row0[0], z10 = row0[1], z01 = row1[0], z11 = row1[1];
  const bool all_valid =
      !(std::isnan(z00) || std::isnan(z10) || std::isnan(z01) || std::isnan(z11));
  if (all_valid) {
    const float lo = std::min(std::min(z00, z10), std::min(z01, z11));
    const float hi = std::max(std::max(z00, z10), std::max(z01, z11));
    if (hi - lo <= tau_edge * lo)
      return (1.0f - fy) * ((1.0f - fx) * z00 + fx * z10) +
             fy * ((1.0f - fx) * z01 + fx * z11);
  }
  // Nearest of the four pixels: it may be valid even when the window straddles an edge.
  const float* row = fy < 0.5f ? row0 : row1;
  return row[fx < 0.5f ? 0 : 1];
}

/// Sampling step of the depth window (px): every other row and column, so the window spans
/// twice the pixels for the same cost.
constexpr int WINDOW_STEP = 2;

/** Depth at the sub-pixel point p from the plane 1/z = c0 + c1 dx + c2 dy (dx, dy: offsets
 * from p) fitted to the pixels of the (2r + 1)^2 window around p whose depth is within
 * tau_edge of z_point, the single-pixel depth; z_point stands when fewer than half the
 * window agrees. The normal equations are accumulated in double and solved by Cramer's rule.
 */
float
windowDepth(const std::vector<float>& depth,
            int width,
            int height,
            cv::Point2f p,
            float z_point,
            int radius,
            float tau_edge)
{
  const int u0 = static_cast<int>(std::lround(p.x));
  const int v0 = static_cast<int>(std::lround(p.y));
  const float tolerance = tau_edge * z_point;
  // The window's rows are requested from memory together before the first is read: the
  // depth maps are read a frame after they were made, and a row at a time the loop would
  // wait for each.
  for (int v = std::max(v0 - radius, 0); v <= std::min(v0 + radius, height - 1);
       v += WINDOW_STEP) {
    const float* row = depth.data() + static_cast<std::size_t>(v) * width;
    __builtin_prefetch(row + std::max(u0 - radius, 0));
    __builtin_prefetch(row + std::min(u0 + radius, width - 1));
  }
  double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0, syy = 0, sw = 0, swx = 0, swy = 0;
  for (int v = v0 - radius; v <= v0 + radius; v += WINDOW_STEP) {
    if (v < 0 || v >= height)
      continue;
    const float* row = depth.data() + static_cast<std::size_t>(v) * width;
    const double dy = v - p.y;
    for (int u = u0 - radius; u <= u0 + radius; u += WINDOW_STEP) {
      if (u < 0 || u >= width)
        continue;
      const float z = row[u];
      if (!(std::abs(z - z_point) <= tolerance))
        continue;
      const double dx = u - p.x;
      const double w = 1.0 / z;
      n += 1.0;
      sx += dx;
      sy += dy;
      sxx += dx * dx;
      sxy += dx * dy;
      syy += dy * dy;
      sw += w;
      swx += w * dx;
      swy += w * dy;
    }
  }
  const int side = 2 * (radius / WINDOW_STEP) + 1;
  if (2.0 * n < side * side)
    return z_point;
  // c0 of [n sx sy; sx sxx sxy; sy sxy syy] c = [sw swx swy].
  const double det = n * (sxx * syy - sxy * sxy) - sx * (sx * syy - sxy * sy) +
                     sy * (sx * sxy - sxx * sy);
  const double det0 = sw * (sxx * syy - sxy * sxy) - sx * (swx * syy - sxy * swy) +
                      sy * (swx * sxy - sxx * swy);
  const double inverse_depth = det0 / det;
  return det > 0.0 && inverse_depth > 0.0 ? static_cast<float>(1.0 / inverse_depth)
                                          : z_point;
}

/// Depth at the sub-pixel q (inside [1, width-2] x [1, height-2]): trackedDepth(), then the
/// window's plane when depth_window_radius r > 0; NaN without depth.
float
depthAt(const std::vector<float>& depth,
        int width,
        int height,
        cv::Point2f q,
        int r,
        const GridSceneFlowParameters& params)
{
  const float z = trackedDepth(depth, width, q, params.depth_edge_tolerance);
  if (std::isnan(z) || r == 0)
    return z;
  return windowDepth(depth, width, height, q, z, r, params.depth_edge_tolerance);
}

/// The depth image's stamp minus the colour image's (seconds), 0 when either is unknown.
float
depthOffset(const GridFlowEngine::FrameStamps& stamps)
{
  const double offset = stamps.depth - stamps.colour;
  return std::isfinite(offset) ? static_cast<float>(offset) : 0.0f;
}

/** Gives every cell of a cols x rows grid that is not `known` the value of its nearest known
 * cell (breadth-first over 4-neighbours, so ties go to the first in grid order); nothing
 * changes without a known cell.
 */
void
fillFromNearest(std::vector<Eigen::Vector2f>& values,
                std::vector<std::uint8_t> known,
                int cols,
                int rows)
{
  std::deque<std::size_t> queue;
  for (std::size_t i = 0; i < known.size(); ++i)
    if (known[i])
      queue.push_back(i);
  for (; !queue.empty(); queue.pop_front()) {
    const std::size_t i = queue.front();
    const int row = static_cast<int>(i) / cols, c = static_cast<int>(i) % cols;
    const std::array<std::array<int, 2>, 4> neighbours{
        {{row - 1, c}, {row + 1, c}, {row, c - 1}, {row, c + 1}}};
    for (const auto& [nr, nc] : neighbours) {
      if (nr < 0 || nr >= rows || nc < 0 || nc >= cols)
        continue;
      const std::size_t j = static_cast<std::size_t>(nr) * cols + nc;
      if (known[j])
        continue;
      known[j] = 1;
      values[j] = values[i];
      queue.push_back(j);
    }
  }
}

/** The rotation that takes the prediction's image shift to the image's own (docs/algorithm.md
 * §1.2, seeded search): the global shift of `current` into `reference` (grey images of one
 * pyramid level, `scale` full-resolution pixels per pixel) by phase correlation, against
 * `predicted`, the prediction's median shift of the cells (px). A rotation about the camera's
 * y and x axes moves the image centre by the difference. Identity when the difference is
 * within `reach` px, or when the correlation's peak holds less than MIN_RESPONSE of its
 * energy (a blurred or featureless image has no shift to measure), or the images are tiny.
 */
Eigen::Matrix3f
imageShiftRotation(const cv::Mat& current,
                   const cv::Mat& reference,
                   float scale,
                   const Eigen::Vector2f& predicted,
                   float reach,
                   const CameraIntrinsics& intrinsics)
{
  constexpr double MIN_RESPONSE = 0.1;
  constexpr int MIN_SIDE = 8; // a smaller top level has no shift worth measuring
  if (current.cols < MIN_SIDE || current.rows < MIN_SIDE ||
      current.size() != reference.size())
    return Eigen::Matrix3f::Identity();
  cv::Mat a, b, window;
  current.convertTo(a, CV_32F);
  reference.convertTo(b, CV_32F);
  cv::createHanningWindow(window, a.size(), CV_32F);
  double response = 0.0;
  const cv::Point2d shift = cv::phaseCorrelate(a, b, window, &response);
  const Eigen::Vector2f d =
      Eigen::Vector2f(static_cast<float>(shift.x), static_cast<float>(shift.y)) *
          scale -
      predicted;
  if (!(response >= MIN_RESPONSE) || !(d.norm() > reach))
    return Eigen::Matrix3f::Identity();
  // About y, a point near the optical axis moves by fx * angle in u; about x, by -fy * angle
  // in v.
  return (Eigen::AngleAxisf(std::atan(d.x() / intrinsics.fx),
                            Eigen::Vector3f::UnitY()) *
          Eigen::AngleAxisf(-std::atan(d.y() / intrinsics.fy),
                            Eigen::Vector3f::UnitX()))
      .toRotationMatrix();
}

} // namespace

struct GridFlowEngine::Frame {
  std::uint32_t width = 0;
  std::uint32_t height = 0;
  std::vector<cv::Mat>
      pyramid;              ///< cv::buildOpticalFlowPyramid output, with derivatives
  std::vector<float> depth; ///< preprocessed (metres, NaN = invalid)
  DepthPreprocessing preprocessing;
  FrameStamps stamps;
  /// per cell, the depth b_i is read at c_i (NaN: none), for every track of this frame
  std::vector<float> centre_depth;
  /// per cell, its image velocity (px/s) from this frame's frame-to-frame track; empty: none
  std::vector<Eigen::Vector2f> velocity;
};

GridFlowEngine::GridFlowEngine()
    : current_(std::make_shared<Frame>())
    , previous_(std::make_shared<Frame>())
{
}

GridFlowEngine::~GridFlowEngine() = default;

void
GridFlowEngine::prepare(Slot slot,
                        const std::vector<std::uint8_t>& grey,
                        const std::vector<float>& depth,
                        std::uint32_t width,
                        std::uint32_t height,
                        const GridSceneFlowParameters& params,
                        unsigned threads,
                        const FrameStamps& stamps)
{
  std::shared_ptr<Frame>& stored = slot == Slot::current ? current_ : previous_;
  if (stored == keyframe_)
    stored = std::make_shared<Frame>();
  Frame& frame = *stored;
  frame.width = width;
  frame.height = height;
  frame.stamps = stamps;
  frame.velocity.clear();
  frame.preprocessing.setParameters(params.depth);
  frame.preprocessing.setNumberOfThreads(threads);
  // b_i's depth at each cell centre c_i: the same for the frame-to-frame and keyframe tracks.
  const auto build_centre_depths = [&] {
    const int cell = params.cell_size;
    const int cols = static_cast<int>(width) / cell,
              rows = static_cast<int>(height) / cell;
    const int r = params.depth_window_radius;
    frame.centre_depth.resize(static_cast<std::size_t>(cols) * rows);
    for (int row = 0; row < rows; ++row)
      for (int c = 0; c < cols; ++c) {
        const int u = c * cell + cell / 2, v = row * cell + cell / 2;
        float z = centreDepth(frame.depth, static_cast<int>(width),
                              static_cast<int>(height), u, v);
        if (r > 0 && !std::isnan(z))
          z = windowDepth(frame.depth, static_cast<int>(width),
                          static_cast<int>(height),
                          cv::Point2f(static_cast<float>(u), static_cast<float>(v)), z,
                          r, params.depth_edge_tolerance);
        frame.centre_depth[static_cast<std::size_t>(row) * cols + c] = z;
      }
  };
  // The grey buffer is only read: buildOpticalFlowPyramid copies level 0 into a padded image.
  const cv::Mat image(static_cast<int>(height), static_cast<int>(width), CV_8UC1,
                      const_cast<std::uint8_t*>(grey.data()));
  const auto build_pyramid = [&] {
    cv::buildOpticalFlowPyramid(image, frame.pyramid,
                                cv::Size(params.window_size, params.window_size),
                                params.max_pyramid_level, true);
  };
  // The depth map's rows first, in stripes on every thread; then the pyramid beside the
  // depth map's column pass and the centres' depths, which need the whole map: with two
  // threads, one each (VGA, one thread: the rows 0.5 ms, the pyramid 0.28 ms, the columns
  // 0.1 ms, the centres' depths 0.15 ms). The column pass, nested in a stripe, stays on
  // its thread (forEachStripe()).
  frame.preprocessing.applyRows(depth, width, height, frame.depth);
  const unsigned tasks = std::min(threads, 2u);
  forEachStripe(tasks, tasks, [&](std::size_t s, std::size_t) {
    if (s == 0)
      build_pyramid();
    if (s + 1 == tasks) {
      frame.preprocessing.applyColumns(width, height, frame.depth);
      build_centre_depths();
    }
  });
}

void
GridFlowEngine::shiftCurrentToPrevious()
{
  std::swap(current_, previous_);
}

void
GridFlowEngine::keepCurrentAsKeyframe()
{
  keyframe_ = current_;
}

void
GridFlowEngine::clearKeyframe()
{
  keyframe_.reset();
}

const std::vector<float>&
GridFlowEngine::depth(Slot slot) const
{
  return slot == Slot::current ? current_->depth : previous_->depth;
}

Eigen::Matrix3f
GridFlowEngine::compute(const GridSceneFlowParameters& params,
                        const CameraIntrinsics& intrinsics,
                        unsigned threads,
                        const Eigen::Matrix4f& T_previous_current,
                        pcl::PointCloud<PointFlow>& flow)
{
  std::vector<Eigen::Vector2f> velocity;
  Eigen::Matrix3f shift_rotation;
  track(*previous_, params, intrinsics, threads, T_previous_current, {},
        params.max_pyramid_level, true, flow, velocity, &shift_rotation);
  current_->velocity = std::move(velocity);
  return shift_rotation;
}

void
GridFlowEngine::computeToKeyframe(const GridSceneFlowParameters& params,
                                  const CameraIntrinsics& intrinsics,
                                  unsigned threads,
                                  const Eigen::Matrix4f& T_keyframe_current,
                                  const std::vector<std::uint8_t>& selected,
                                  int max_level,
                                  pcl::PointCloud<PointFlow>& flow) const
{
  if (!keyframe_)
    throw std::logic_error(
        "[dynvo::detail::GridFlowEngine::computeToKeyframe] no keyframe kept");
  std::vector<Eigen::Vector2f> velocity;
  track(*keyframe_, params, intrinsics, threads, T_keyframe_current, selected,
        std::clamp(max_level, 0, params.max_pyramid_level), false, flow, velocity,
        nullptr);
}

void
GridFlowEngine::track(const Frame& reference,
                      const GridSceneFlowParameters& params,
                      const CameraIntrinsics& intrinsics,
                      unsigned threads,
                      const Eigen::Matrix4f& T_reference_current,
                      const std::vector<std::uint8_t>& selected,
                      int max_level,
                      bool frame_to_frame,
                      pcl::PointCloud<PointFlow>& flow,
                      std::vector<Eigen::Vector2f>& velocity,
                      Eigen::Matrix3f* shift_rotation) const
{
  const Frame& curr = *current_;
  const Frame& prev = reference;
  const int width = static_cast<int>(curr.width);
  const int height = static_cast<int>(curr.height);
  const int cell = params.cell_size;
  const int cols = width / cell;
  const int rows = height / cell;
  const std::size_t n = static_cast<std::size_t>(cols) * rows;
  const int r = params.depth_window_radius;

  // c_i, and the depth b_i is read at (NaN: none; prepare()).
  std::vector<cv::Point2f> centres(n);
  for (int row = 0; row < rows; ++row)
    for (int c = 0; c < cols; ++c)
      centres[static_cast<std::size_t>(row) * cols + c] =
          cv::Point2f(static_cast<float>(c * cell + cell / 2),
                      static_cast<float>(row * cell + cell / 2));
  const std::vector<float>& centre_depth = curr.centre_depth;
  // Inside [1, W-2] x [1, H-2]: the 2x2 bilinear depth footprint stays in the image.
  const auto inside = [width, height](cv::Point2f q) {
    return q.x >= 1.0f && q.y >= 1.0f && q.x <= width - 2.0f && q.y <= height - 2.0f;
  };

  // Cells to track: the selected ones with a depth b_i (a cell without one gives no 3D flow;
  // about a fifth of a TUM fr1 frame has no depth). Each starts in the reference frame at the
  // projection of T_reference_current * b_i; a start outside the image leaves the cell out.
  const auto trackable = [&](std::size_t i) {
    return (selected.empty() || selected[i]) && !std::isnan(centre_depth[i]);
  };
  std::vector<std::size_t> tracked_cells;
  std::vector<cv::Point2f> seeds;
  tracked_cells.reserve(n);
  seeds.reserve(n);
  const auto predictSeeds = [&](const Eigen::Matrix3f& R, const Eigen::Vector3f& t) {
    tracked_cells.clear();
    seeds.clear();
    for (std::size_t i = 0; i < n; ++i) {
      if (!trackable(i))
        continue;
      const Eigen::Vector3f q =
          R * intrinsics.backproject(centres[i].x, centres[i].y, centre_depth[i]) + t;
      if (!(q.z() > 0.0f))
        continue;
      const Eigen::Vector2f seed = intrinsics.project(q);
      if (!(seed.x() >= 0.0f && seed.y() >= 0.0f && seed.x() <= width - 1.0f &&
            seed.y() <= height - 1.0f))
        continue;
      tracked_cells.push_back(i);
      seeds.emplace_back(seed.x(), seed.y());
    }
  };
  const Eigen::Matrix3f R = T_reference_current.topLeftCorner<3, 3>();
  const Eigen::Vector3f t = T_reference_current.topRightCorner<3, 1>();
  predictSeeds(R, t);
  if (shift_rotation)
    shift_rotation->setIdentity();
  // Frame to frame, the pyramid reaches (window / 2) * 2^max_level px (half a window on the
  // top level). When the image's own shift departs from the prediction's (medians over the
  // cells) by more than that, the prediction is turned onto it. A prediction within the
  // reach of the cells themselves is not needed, and the search starts at every cell itself.
  if (frame_to_frame && !seeds.empty()) {
    const float reach = 0.5f * static_cast<float>(params.window_size) *
                        static_cast<float>(1 << max_level);
    const auto median = [](std::vector<float>& v) {
      std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
      return v[v.size() / 2];
    };
    std::vector<float> x(seeds.size()), y(seeds.size());
    for (std::size_t k = 0; k < seeds.size(); ++k) {
      x[k] = seeds[k].x - centres[tracked_cells[k]].x;
      y[k] = seeds[k].y - centres[tracked_cells[k]].y;
    }
    // The image of the top level (the pyramid interleaves images and derivatives).
    const std::size_t top = 2 * static_cast<std::size_t>(max_level);
    const Eigen::Matrix3f R_shift = imageShiftRotation(
        curr.pyramid[top], prev.pyramid[top], static_cast<float>(1 << max_level),
        Eigen::Vector2f(median(x), median(y)), reach, intrinsics);
    if (!R_shift.isIdentity()) {
      predictSeeds(R_shift * R, R_shift * t);
      if (shift_rotation)
        *shift_rotation = R_shift;
    }
    std::vector<float> shift(seeds.size());
    for (std::size_t k = 0; k < seeds.size(); ++k)
      shift[k] = static_cast<float>(cv::norm(seeds[k] - centres[tracked_cells[k]]));
    if (!seeds.empty() && median(shift) <= reach) {
      tracked_cells.clear();
      seeds.clear();
      for (std::size_t i = 0; i < n; ++i)
        if (trackable(i)) {
          tracked_cells.push_back(i);
          seeds.push_back(centres[i]);
        }
    }
  }

  // Track every selected centre c_i from I^k into the reference (p_i), then p_i back
  // into I^k (c'_i).
  const std::size_t m = tracked_cells.size();
  std::vector<cv::Point2f> tracked(n, cv::Point2f(NaN, NaN));
  std::vector<std::uint8_t> valid2d(n, 0);
  LucasKanadeSettings lk;
  lk.window = params.window_size;
  lk.max_level = max_level;
  lk.max_iterations = params.max_iterations;
  lk.epsilon = params.epsilon;
  lk.min_eigen_threshold = params.min_eigen_threshold;
  const float fb2 =
      params.forward_backward_threshold * params.forward_backward_threshold;
  // Stripe s takes every stripes-th cell from the s-th: the stripes cover the whole image
  // alike, so their cost is even (contiguous stripes are not: the top and bottom of an image
  // differ in texture). Each point is tracked on its own: the same flow for any split.
  const std::size_t stripes = std::min<std::size_t>(threads, m);
  forEachStripe(stripes, stripes, [&](std::size_t s, std::size_t) {
    std::vector<std::size_t> cells;
    std::vector<cv::Point2f> from, to;
    for (std::size_t k = s; k < m; k += stripes) {
      cells.push_back(tracked_cells[k]);
      from.push_back(centres[tracked_cells[k]]);
      to.push_back(seeds[k]);
    }
    std::vector<std::uint8_t> status;
    trackLucasKanade(curr.pyramid, prev.pyramid, from, lk, to, status);
    std::vector<cv::Point2f> forward;
    std::vector<std::size_t> index;
    for (std::size_t k = 0; k < from.size(); ++k) {
      const std::size_t i = cells[k];
      tracked[i] = to[k];
      const cv::Point2f& p = to[k];
      if (status[k] && inside(p)) {
        forward.push_back(p);
        index.push_back(i);
      }
    }
    if (forward.empty())
      return;
    // Full: from scratch through the pyramid (the search starts at p_i itself); local:
    // from c_i on the finest level.
    std::vector<cv::Point2f> back;
    LucasKanadeSettings check = lk;
    if (params.forward_backward_check == ForwardBackwardCheck::full)
      back = forward;
    else {
      check.max_level = 0;
      for (const std::size_t i : index)
        back.push_back(centres[i]);
    }
    trackLucasKanade(prev.pyramid, curr.pyramid, forward, check, back, status);
    for (std::size_t k = 0; k < forward.size(); ++k) {
      const cv::Point2f d = back[k] - centres[index[k]];
      valid2d[index[k]] = status[k] && d.dot(d) <= fb2;
    }
  });

  // Each cell's image velocity (px/s): frame to frame, that of this track; to the keyframe,
  // the one the current frame kept from its own frame-to-frame track (none: zero). A cell
  // without a track (no depth, or LK or its check failed) takes its nearest tracked cell's:
  // the image motion is smooth, and zero put the depth instants of the keyframe points
  // falling in such a cell off by the velocity times the depth-colour offset
  // (docs/algorithm.md §1.2).
  velocity.assign(n, Eigen::Vector2f::Zero());
  if (frame_to_frame) {
    const double dt = curr.stamps.colour - prev.stamps.colour;
    if (dt > 0.0) { // false when a stamp is unknown
      for (std::size_t i = 0; i < n; ++i)
        if (valid2d[i])
          velocity[i] = Eigen::Vector2f(centres[i].x - tracked[i].x,
                                        centres[i].y - tracked[i].y) /
                        static_cast<float>(dt);
      fillFromNearest(velocity, valid2d, cols, rows);
    }
  }
  else if (curr.velocity.size() == n) {
    velocity = curr.velocity;
  }
  // The point a_i of the reference: frame to frame, the cell's own velocity; in the keyframe,
  // the keyframe's velocity of the cell p_i falls in.
  const auto reference_velocity = [&](std::size_t i, cv::Point2f p) {
    if (frame_to_frame)
      return velocity[i];
    if (prev.velocity.size() != n)
      return Eigen::Vector2f(Eigen::Vector2f::Zero());
    const int c = std::clamp(static_cast<int>(p.x) / cell, 0, cols - 1);
    const int row = std::clamp(static_cast<int>(p.y) / cell, 0, rows - 1);
    return prev.velocity[static_cast<std::size_t>(row) * cols + c];
  };
  const float offset_curr = depthOffset(curr.stamps);
  const float offset_prev = depthOffset(prev.stamps);
  // Where the depth image saw the point seen at q in the colour image: q moved along the
  // image velocity v by the frame's depth-minus-colour offset.
  const auto atDepthInstant = [](cv::Point2f q, const Eigen::Vector2f& v,
                                 float offset) {
    return cv::Point2f(q.x + v.x() * offset, q.y + v.y() * offset);
  };
  flow.resize(static_cast<std::uint32_t>(cols), static_cast<std::uint32_t>(rows));
  flow.is_dense = false;
  const float max_flow2 = params.max_flow * params.max_flow;
  const auto finish_cell = [&](std::size_t i) {
    PointFlow& f = flow[i];
    const cv::Point2f c = centres[i];
    const cv::Point2f p = tracked[i];
    f.u = c.x;
    f.v = c.y;
    f.valid_2d = valid2d[i];
    f.prev_u = f.valid_2d ? p.x : NaN;
    f.prev_v = f.valid_2d ? p.y : NaN;
    const float z_b = centre_depth[i];
    f.getVector3fMap() = std::isnan(z_b) ? Eigen::Vector3f::Constant(NaN)
                                         : intrinsics.backproject(c.x, c.y, z_b);
    f.prev_x = f.prev_y = f.prev_z = NaN;
    f.weight = 0.0f;
    f.valid_3d = 0;
    if (!f.valid_2d || std::isnan(z_b))
      return;
    // Both ends at their depth instants (docs/algorithm.md §1.2); no offset: where tracked.
    const cv::Point2f c_d = atDepthInstant(c, velocity[i], offset_curr);
    const cv::Point2f p_d = atDepthInstant(p, reference_velocity(i, p), offset_prev);
    if (c_d != c) {
      if (!inside(c_d))
        return;
      const float z = depthAt(curr.depth, width, height, c_d, r, params);
      if (std::isnan(z))
        return;
      f.getVector3fMap() = intrinsics.backproject(c_d.x, c_d.y, z);
    }
    if (!inside(p_d))
      return;
    const float z_a = depthAt(prev.depth, width, height, p_d, r, params);
    if (std::isnan(z_a))
      return;
    const Eigen::Vector3f a = intrinsics.backproject(p_d.x, p_d.y, z_a);
    if ((f.getVector3fMap() - a).squaredNorm() > max_flow2)
      return;
    f.prev_x = a.x();
    f.prev_y = a.y();
    f.prev_z = a.z();
    f.valid_3d = 1;
    const float ratio = params.weight_reference_depth / std::max(z_a, f.z);
    f.weight = std::min(1.0f, ratio * ratio * ratio * ratio);
  };
  // Cells are independent: the same flow for any split. Stripe s takes every stripes-th row
  // of cells from the s-th, as the tracks do: contiguous halves cost unlike (the image's
  // lower half holds more cells with depth: 117 against 178 us on tum_fr1_xyz_200).
  const std::size_t row_stripes = std::min<std::size_t>(threads, rows);
  forEachStripe(row_stripes, row_stripes, [&](std::size_t s, std::size_t) {
    for (std::size_t row = s; row < static_cast<std::size_t>(rows); row += row_stripes)
      for (std::size_t i = row * cols; i < (row + 1) * cols; ++i)
        finish_cell(i);
  });
}

} // namespace detail
} // namespace dynvo
