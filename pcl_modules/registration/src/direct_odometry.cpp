// SPDX-License-Identifier: BSD-3-Clause
// Direct photometric alignment of two RGB-D frames on their static cells (docs/algorithm.md
// §7.7): inverse compositional Gauss-Newton on textured target pixels, coarse to fine.
#include <dynvo/registration/direct_odometry.h>

#include <dynvo/common/parallel.h>
#include <dynvo/common/vectorize.h>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

namespace dynvo::detail {

namespace {

// Fixed by measurement on the real clips (src/app/NOTES.md, ninth and twelfth sessions), not
// configuration: they set the cost. 2000 samples and 5 steps read as well as 6000 and 10 on
// the real clips at half the cost; fewer levels cost the fast clip, a sparser finest scan the
// noise-free synthetic scenes.
/// Gauss-Newton steps per level at most.
constexpr int MAX_ITERATIONS = 5;
/// Samples per level at most, spread evenly.
constexpr std::size_t BUDGET = 2000;
/// Grey levels per pixel (central difference) a sample needs at least.
constexpr float MIN_GRADIENT = 6.0f;
/// The finest level is scanned on every FINE_STEP-th row and column.
constexpr int FINE_STEP = 2;
/// Fewer residuals on a level: the alignment fails.
constexpr std::size_t MIN_RESIDUALS = 100;
/// Fewer samples are not worth a second thread: waking it costs about as much as their pass.
constexpr std::size_t MIN_PARALLEL_SAMPLES = 500;
/// Metres and radians: a smaller step ends the level.
constexpr float CONVERGED = 1e-5f;

} // namespace

struct DirectFrame::Level {
  int width = 0;
  int height = 0;
  int scale = 1; ///< full-resolution pixels per pixel of this level
  cv::Mat grey;  ///< CV_32FC1
  cv::Mat depth; ///< CV_32FC1, NaN where none
};

DirectFrame::DirectFrame() = default;

void
DirectFrame::resize(int width, int height)
{
  levels_.resize(LEVELS);
  Level& base = levels_[0];
  base.width = width;
  base.height = height;
  base.grey.create(height, width, CV_32FC1);
  base.depth.create(height, width, CV_32FC1);
}

float*
DirectFrame::grey()
{
  return levels_[0].grey.ptr<float>();
}

float*
DirectFrame::depth()
{
  return levels_[0].depth.ptr<float>();
}

void
DirectFrame::assign(const std::uint8_t* grey, const float* depth)
{
  Level& base = levels_[0];
  cv::Mat(base.height, base.width, CV_8UC1, const_cast<std::uint8_t*>(grey))
      .convertTo(base.grey, CV_32F);
  std::copy(depth, depth + static_cast<std::size_t>(base.width) * base.height,
            base.depth.ptr<float>());
}

void
DirectFrame::buildPyramid()
{
  samples_.reset();
  for (int l = 1; l < LEVELS; ++l) {
    const Level& fine = levels_[l - 1];
    Level& coarse = levels_[l];
    cv::pyrDown(fine.grey, coarse.grey);
    coarse.width = coarse.grey.cols;
    coarse.height = coarse.grey.rows;
    coarse.scale = 2 * fine.scale;
    // Nearest depth (pixel (2x, 2y) of the finer level): no mixing across depth edges.
    coarse.depth.create(coarse.height, coarse.width, CV_32FC1);
    for (int y = 0; y < coarse.height; ++y) {
      const float* in = fine.depth.ptr<float>(std::min(2 * y, fine.height - 1));
      float* out = coarse.depth.ptr<float>(y);
      for (int x = 0; x < coarse.width; ++x)
        out[x] = in[std::min(2 * x, fine.width - 1)];
    }
  }
}

DirectFrame::~DirectFrame() = default;

namespace {

/// A textured target pixel: its point, intensity and the inverse compositional Jacobian.
struct Sample {
  Eigen::Vector3f point;
  float intensity;
  /// 6 pose terms, the brightness offset, then 0 (8 floats: whole SIMD registers)
  Eigen::Matrix<float, 8, 1> jacobian;
};

/// Pinhole model of a pyramid level whose pixel (x, y) samples full-resolution (s x, s y).
struct LevelCamera {
  float fx, fy, cx, cy;
  LevelCamera(const CameraIntrinsics& k, int scale)
      : fx(static_cast<float>(k.fx / scale))
      , fy(static_cast<float>(k.fy / scale))
      , cx(static_cast<float>(k.cx / scale))
      , cy(static_cast<float>(k.cy / scale))
  {
  }
};

/// Which pixels of a pyramid level lie in a cell labelled LABEL_STATIC: the cell of pixel
/// (x, y) is rows[y] + cols[x], negative outside the grid.
struct StaticLookup {
  const FlowGrid& cells;
  std::vector<int> rows, cols;
  StaticLookup(const FlowGrid& grid, int width, int height, int scale)
      : cells(grid)
      , rows(height)
      , cols(width)
  {
    const auto index = [&grid, scale](int x, std::uint32_t count, int stride) {
      const std::uint32_t cell = static_cast<std::uint32_t>(x * scale) / grid.cell_size;
      return cell < count ? static_cast<int>(cell) * stride : -(1 << 30);
    };
    for (int y = 0; y < height; ++y)
      rows[y] = index(y, grid.rows, static_cast<int>(grid.cols));
    for (int x = 0; x < width; ++x)
      cols[x] = index(x, grid.cols, 1);
  }
  bool operator()(int x, int y) const
  {
    const int cell = rows[y] + cols[x];
    return cell >= 0 && cells.labels[cell] == LABEL_STATIC;
  }
};

/** Marks the pixels x = 1, 1 + step, ... < width - 1 of a row that can be samples (taken[k]
 * for the k-th): a depth in (0, max_depth], a central-difference gradient of at least
 * MIN_GRADIENT grey levels per pixel, a static column. Returns how many were scanned.
 * Branch-free, and built for AVX2 as well (the same comparisons and products).
 */
DYNVO_VECTORIZE_FOR_AVX2 int
markSamples(const float* up,
            const float* row,
            const float* down,
            const float* depth,
            const std::uint8_t* static_columns,
            int width,
            int step,
            float max_depth,
            std::uint8_t* taken)
{
  int k = 0;
  for (int x = 1; x + 1 < width; x += step, ++k) {
    const float z = depth[x];
    const float gx = row[x + 1] - row[x - 1];
    const float gy = down[x] - up[x];
    taken[k] = (z > 0.0f) & (z <= max_depth) &
               (gx * gx + gy * gy >= 4.0f * MIN_GRADIENT * MIN_GRADIENT) &
               (static_columns[x] != 0);
  }
  return k;
}

template <typename Level>
std::vector<Sample>
samplesOf(const Level& level,
          const FlowGrid& cells,
          const LevelCamera& camera,
          float max_depth)
{
  // The textured static pixels with depth (y * width + x), then at most BUDGET of them
  // evenly spread. Each row is marked (markSamples()), then every scanned pixel written and
  // the ones taken kept: no branch per pixel.
  const int step = level.scale == 1 ? FINE_STEP : 1;
  const int size = static_cast<int>(cells.cell_size);
  std::vector<int> pixels(static_cast<std::size_t>(level.width / step + 1) *
                          (level.height / step + 1));
  std::size_t found = 0;
  std::vector<std::uint8_t> static_columns(static_cast<std::size_t>(level.width));
  std::vector<std::uint8_t> taken(static_cast<std::size_t>(level.width));
  int columns_row = -1; // the cell row static_columns holds
  for (int y = 1; y + 1 < level.height; y += step) {
    const int cell_row = y * level.scale / size;
    if (cell_row >= static_cast<int>(cells.rows))
      break;
    if (cell_row != columns_row) {
      const std::uint8_t* labels =
          &cells.labels[static_cast<std::size_t>(cell_row) * cells.cols];
      for (int x = 0; x < level.width; ++x) {
        const int cell = x * level.scale / size;
        static_columns[x] =
            cell < static_cast<int>(cells.cols) && labels[cell] == LABEL_STATIC;
      }
      columns_row = cell_row;
    }
    const int scanned = markSamples(
        level.grey.template ptr<float>(y - 1), level.grey.template ptr<float>(y),
        level.grey.template ptr<float>(y + 1), level.depth.template ptr<float>(y),
        static_columns.data(), level.width, step, max_depth, taken.data());
    for (int k = 0; k < scanned; ++k) {
      pixels[found] = y * level.width + 1 + k * step;
      found += taken[static_cast<std::size_t>(k)];
    }
  }
  pixels.resize(found);
  const std::size_t count = std::min(pixels.size(), BUDGET);
  const double stride = count > 0 ? static_cast<double>(pixels.size()) / count : 0.0;
  std::vector<Sample> samples(count);
  for (std::size_t i = 0; i < count; ++i) {
    const int pixel = pixels[static_cast<std::size_t>(i * stride)];
    const int x = pixel % level.width, y = pixel / level.width;
    const float* row = level.grey.template ptr<float>(y);
    const float gx = 0.5f * (row[x + 1] - row[x - 1]);
    const float gy = 0.5f * (level.grey.template ptr<float>(y + 1)[x] -
                             level.grey.template ptr<float>(y - 1)[x]);
    const float z = level.depth.template ptr<float>(y)[x];
    Sample& s = samples[i];
    s.point = Eigen::Vector3f((x - camera.cx) * z / camera.fx,
                              (y - camera.cy) * z / camera.fy, z);
    s.intensity = row[x];
    const float X = s.point.x(), Y = s.point.y(), iz = 1.0f / z;
    // d(intensity)/d(point) through the projection, then d(point)/d(twist) = [I | -[P]x].
    const Eigen::Vector3f dI_dP(gx * camera.fx * iz, gy * camera.fy * iz,
                                -(gx * camera.fx * X + gy * camera.fy * Y) * iz * iz);
    s.jacobian.head<3>() = dI_dP;
    s.jacobian.segment<3>(3) = s.point.cross(dI_dP);
    s.jacobian[6] = 1.0f;
    s.jacobian[7] = 0.0f;
  }
  return samples;
}

float
bilinear(const cv::Mat& image, float u, float v)
{
  const int x = static_cast<int>(u), y = static_cast<int>(v);
  const float a = u - x, b = v - y;
  const float* r0 = image.ptr<float>(y) + x;
  const float* r1 = image.ptr<float>(y + 1) + x;
  return (1 - b) * ((1 - a) * r0[0] + a * r0[1]) + b * ((1 - a) * r1[0] + a * r1[1]);
}

} // namespace

struct DirectFrame::SampleCache {
  FlowGrid cells;
  CameraIntrinsics intrinsics;
  float max_depth = 0.0f;
  std::vector<std::vector<Sample>> levels;
};

const DirectFrame::Level&
DirectFrame::level(int l) const
{
  return levels_[static_cast<std::size_t>(l)];
}

const DirectFrame::SampleCache&
DirectFrame::samples(const FlowGrid& cells,
                     const CameraIntrinsics& intrinsics,
                     float max_depth) const
{
  const auto same = [&](const SampleCache& c) {
    return c.cells.cell_size == cells.cell_size && c.cells.labels == cells.labels &&
           c.intrinsics.fx == intrinsics.fx && c.intrinsics.fy == intrinsics.fy &&
           c.intrinsics.cx == intrinsics.cx && c.intrinsics.cy == intrinsics.cy &&
           c.max_depth == max_depth;
  };
  if (samples_ && same(*samples_))
    return *samples_;
  auto cache = std::make_unique<SampleCache>();
  cache->cells = cells;
  cache->intrinsics = intrinsics;
  cache->max_depth = max_depth;
  for (const Level& level : levels_)
    cache->levels.push_back(
        samplesOf(level, cells, LevelCamera(intrinsics, level.scale), max_depth));
  samples_ = std::move(cache);
  return *samples_;
}

bool
estimateDirectOdometry(const DirectFrame& source,
                       const FlowGrid& source_cells,
                       const DirectFrame& target,
                       const FlowGrid& target_cells,
                       const CameraIntrinsics& intrinsics,
                       const StaticMaskRegistrationParameters& parameters,
                       const Eigen::Matrix4f& guess,
                       unsigned threads,
                       Eigen::Matrix4f& T_target_source)
{
  Eigen::Isometry3f T(Eigen::Isometry3f(guess).inverse()); // T_source_target
  float offset = 0.0f;
  std::vector<float> residuals;  // per sample of a level
  std::vector<float> magnitudes; // of the residuals, for the robust scale
  const DirectFrame::SampleCache& target_samples =
      target.samples(target_cells, intrinsics, parameters.rgbd_max_depth);
  for (int l = DirectFrame::LEVELS - 1; l >= 0; --l) {
    const DirectFrame::Level& s = source.level(l);
    const LevelCamera camera(intrinsics, s.scale);
    const std::vector<Sample>& samples = target_samples.levels[l];
    const StaticLookup isStatic(source_cells, s.width, s.height, s.scale);
    residuals.resize(samples.size());
    float c = 0.0f; // Tukey's threshold of this level, from the first residuals' spread
    double last_cost = std::numeric_limits<double>::infinity();
    Eigen::Isometry3f last_T = T;
    float last_offset = offset;
    for (int iteration = 0; iteration <= MAX_ITERATIONS; ++iteration) {
      const Eigen::Matrix3f R = T.linear();
      const Eigen::Vector3f t = T.translation();
      // The residual of a sample under T, NaN when it has none (off the image, not static,
      // occluded).
      const auto residualOf = [&](const Sample& sample) {
        const float none = std::numeric_limits<float>::quiet_NaN();
        const Eigen::Vector3f q = R * sample.point + t;
        if (!(q.z() > 0.0f))
          return none;
        const float u = camera.fx * q.x() / q.z() + camera.cx;
        const float v = camera.fy * q.y() / q.z() + camera.cy;
        if (!(u >= 0.0f && v >= 0.0f && u < s.width - 1 && v < s.height - 1))
          return none;
        const int nx = static_cast<int>(u + 0.5f), ny = static_cast<int>(v + 0.5f);
        if (!isStatic(nx, ny))
          return none;
        const float zs = s.depth.ptr<float>(ny)[nx];
        if (std::abs(zs - q.z()) > parameters.rgbd_max_depth_difference)
          return none;
        return bilinear(s.grey, u, v) - sample.intensity - offset;
      };
      // Each sample's residual under T, once per step; NaN where it has none. Samples are
      // independent: stripes of them give the same residuals for any thread count (the sums
      // below stay in sample order).
      forEachStripe(samples.size(),
                    samples.size() >= MIN_PARALLEL_SAMPLES ? threads : 1,
                    [&](std::size_t begin, std::size_t end) {
                      for (std::size_t i = begin; i < end; ++i)
                        residuals[i] = residualOf(samples[i]);
                    });
      if (iteration == 0) { // Tukey's threshold of the level: 4.685 robust sigmas
        magnitudes.clear();
        for (const float r : residuals)
          if (!std::isnan(r))
            magnitudes.push_back(std::abs(r));
        if (magnitudes.size() < MIN_RESIDUALS)
          return false;
        const auto middle = magnitudes.begin() + magnitudes.size() / 2;
        std::nth_element(magnitudes.begin(), middle, magnitudes.end());
        c = 4.685f * std::max(1.4826f * *middle, 1.0f);
      }
      // Tukey's biweight: a residual beyond c (a mover, an occlusion) weighs nothing.
      const auto biweight = [c](float r) {
        const float u = std::abs(r) / c;
        return u < 1.0f ? 1.0f - u * u : 0.0f;
      };
      double cost = 0.0;
      std::size_t count = 0;
      for (const float r : residuals) {
        if (std::isnan(r))
          continue;
        const float b = biweight(r);
        cost += (c * c / 6.0) * (1.0 - b * b * b);
        ++count;
      }
      if (count < MIN_RESIDUALS)
        return false;
      cost /= static_cast<double>(count);
      if (!(cost < last_cost)) { // the last step went uphill: take the pose before it
        T = last_T;
        offset = last_offset;
        break;
      }
      last_cost = cost;
      last_T = T;
      last_offset = offset;
      if (iteration == MAX_ITERATIONS)
        break;
      Eigen::Matrix<float, 8, 8> H = Eigen::Matrix<float, 8, 8>::Zero();
      Eigen::Matrix<float, 8, 1> g = Eigen::Matrix<float, 8, 1>::Zero();
      for (std::size_t i = 0; i < samples.size(); ++i) {
        const float r = residuals[i];
        if (std::isnan(r))
          continue;
        const float b = biweight(r);
        const float w = b * b;
        // The lower triangle of H's 7x7 system, whole 4-float packets: LDLT reads no more.
        const Eigen::Matrix<float, 8, 1>& J = samples[i].jacobian;
        const Eigen::Matrix<float, 8, 1> wJ = w * J;
        for (int j = 0; j < 4; ++j)
          H.col(j) += wJ * J[j];
        for (int j = 4; j < 7; ++j)
          H.col(j).tail<4>() += wJ.tail<4>() * J[j];
        g.noalias() += (w * r) * J;
      }
      const Eigen::Matrix<double, 7, 1> delta =
          H.topLeftCorner<7, 7>().cast<double>().ldlt().solve(
              g.head<7>().cast<double>());
      if (!delta.allFinite())
        return false;
      const Eigen::Vector3f v = delta.head<3>().cast<float>();
      const Eigen::Vector3f w = delta.segment<3>(3).cast<float>();
      Eigen::Isometry3f step = Eigen::Isometry3f::Identity();
      const float angle = w.norm();
      if (angle > 0.0f)
        step.linear() = Eigen::AngleAxisf(angle, w / angle).toRotationMatrix();
      step.translation() = v;
      T = T * step.inverse();
      offset += static_cast<float>(delta[6]);
      if (v.norm() < CONVERGED && angle < CONVERGED)
        break;
    }
  }
  if (!T.matrix().allFinite())
    return false;
  T_target_source = T.inverse().matrix();
  return true;
}

} // namespace dynvo::detail
