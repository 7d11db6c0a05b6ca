// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/registration/motion_evidence.h>

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

namespace {

using dynvo::FlowGrid;
using dynvo::LABEL_NONE;
using dynvo::MotionEvidence;
using dynvo::PointFlow;
using dynvo::SensorNoiseModel;

constexpr std::uint32_t WIDTH = 640, HEIGHT = 480, CELL = 16;
constexpr std::uint32_t COLS = WIDTH / CELL, ROWS = HEIGHT / CELL;
constexpr float FOCAL = 525.0f;
constexpr float DEPTH = 1.5f; ///< metres: a wall facing the camera

/** Frame pairs of a wall seen by a camera moving 1 cm and 0.5 deg per frame: every cell's
 * a_i = T_prev_curr b_i plus the sensor model's noise (axial along the ray, lateral across
 * it), plus for the cells of a block a displacement of `sigmas` lateral sigmas per frame
 * (a mover that steady, and that small, falls into the background's segment of one pair).
 */
class WallSequence {
public:
  WallSequence()
  {
    T_prev_curr_.linear() = Eigen::AngleAxisf(0.5f * static_cast<float>(M_PI) / 180.0f,
                                              Eigen::Vector3f::UnitY())
                                .toRotationMatrix();
    T_prev_curr_.translation() = Eigen::Vector3f(0.01f, 0.0f, 0.002f);
  }

  /// Is cell (col, row) in the mover's block this frame.
  bool inBlock(std::uint32_t col, std::uint32_t row) const
  {
    return col >= block_col && col < block_col + block_size && row >= block_row &&
           row < block_row + block_size;
  }

  /// The next pair: the block moves `sigmas` lateral sigmas in the world, and
  /// block_step_cells cells to the right in the image (its cells' p_i are that many cells to
  /// the left; the wall it uncovers has no track).
  pcl::PointCloud<PointFlow> next(float sigmas, std::uint32_t block_step_cells = 0)
  {
    const std::uint32_t left_behind = block_col;
    block_col += block_step_cells;
    pcl::PointCloud<PointFlow> flow(COLS, ROWS);
    for (std::uint32_t row = 0; row < ROWS; ++row)
      for (std::uint32_t col = 0; col < COLS; ++col) {
        PointFlow& f = flow.at(col, row);
        f.u = static_cast<float>(col * CELL + CELL / 2);
        f.v = static_cast<float>(row * CELL + CELL / 2);
        const Eigen::Vector3f b((f.u - 320.0f) * DEPTH / FOCAL,
                                (f.v - 240.0f) * DEPTH / FOCAL, DEPTH);
        f.getVector3fMap() = b;
        const SensorNoiseModel::TransferVariance variance =
            noise_.transferVariance(b, b, FOCAL);
        const Eigen::Vector3f ray = b.normalized();
        const Eigen::Vector3f across1 = ray.unitOrthogonal();
        const Eigen::Vector3f across2 = ray.cross(across1);
        const float lateral = std::sqrt(variance.lateral); // per direction
        Eigen::Vector3f a =
            T_prev_curr_ * b + ray * std::sqrt(variance.axial) * normal_(rng_) +
            (across1 * normal_(rng_) + across2 * normal_(rng_)) * lateral;
        const bool mover = inBlock(col, row);
        if (mover)
          a += across1 * sigmas * std::sqrt(variance.lateral);
        f.prev_x = a.x();
        f.prev_y = a.y();
        f.prev_z = a.z();
        const float shift = mover ? static_cast<float>(block_step_cells * CELL) : 0.0f;
        f.prev_u = f.u - shift;
        f.prev_v = f.v;
        const bool uncovered = !mover && col >= left_behind && col < block_col &&
                               row >= block_row && row < block_row + block_size;
        f.valid_2d = f.valid_3d = uncovered ? 0 : 1;
        f.weight = 1.0f;
      }
    return flow;
  }

  Eigen::Matrix4d motion() const { return T_prev_curr_.matrix().cast<double>(); }

  std::uint32_t block_col = 4;
  std::uint32_t block_row = 10;
  std::uint32_t block_size = 8;

private:
  SensorNoiseModel noise_;
  Eigen::Affine3f T_prev_curr_ = Eigen::Affine3f::Identity();
  std::mt19937 rng_{7};
  std::normal_distribution<float> normal_{0.0f, 1.0f};
};

/// Share of the block's cells and of the others that are flagged moving.
struct Shares {
  double block = 0.0;
  double rest = 0.0;
};

Shares
flaggedShares(const FlowGrid& moving, const WallSequence& wall)
{
  std::size_t block = 0, block_n = 0, rest = 0, rest_n = 0;
  for (std::uint32_t row = 0; row < ROWS; ++row)
    for (std::uint32_t col = 0; col < COLS; ++col) {
      const bool flagged = moving.labels[row * COLS + col] != LABEL_NONE;
      if (wall.inBlock(col, row)) {
        block += flagged;
        ++block_n;
      }
      else {
        rest += flagged;
        ++rest_n;
      }
    }
  return {static_cast<double>(block) / block_n, static_cast<double>(rest) / rest_n};
}

class MotionEvidenceTest : public ::testing::Test {
protected:
  MotionEvidenceTest() { evidence_.setSensorNoise(SensorNoiseModel(), FOCAL); }

  /// One frame: carry the evidence over, then add the pair under the true motion.
  Shares step(float sigmas, std::uint32_t block_step_cells = 0)
  {
    const pcl::PointCloud<PointFlow> flow = wall_.next(sigmas, block_step_cells);
    evidence_.predict(flow, WIDTH, HEIGHT);
    const Shares shares = flaggedShares(evidence_.getMovingCells(), wall_);
    evidence_.update(flow, wall_.motion());
    return shares;
  }

  MotionEvidence evidence_;
  WallSequence wall_;
};

TEST_F(MotionEvidenceTest, ASteadySmallMoverIsFlaggedAndTheStaticCellsAreNot)
{
  // 3 sigma per frame: chi-square about 3 + 9 = 12 against the static 3, so the mover's
  // evidence grows by about 12 - kappa per frame and passes h within a handful of frames;
  // a static cell's falls by kappa - 3.
  Shares shares;
  for (int frame = 0; frame < 12; ++frame)
    shares = step(3.0f);
  EXPECT_GE(shares.block, 0.9);
  // Static cells reach h only on two or more frames far out in the chi-square tail.
  EXPECT_LE(shares.rest, 0.01);
}

TEST_F(MotionEvidenceTest, OneFramePairIsNotEnough)
{
  // After one pair nothing is flagged, however large its residuals: one bad track (or one
  // pair) contributes at most c - kappa < h.
  step(10.0f);
  const Shares shares = step(0.0f);
  EXPECT_EQ(shares.block, 0.0);
  EXPECT_EQ(shares.rest, 0.0);
}

TEST_F(MotionEvidenceTest, AFrameWhoseFitIsOffAsAWholeFlagsNothing)
{
  // Every cell 3 sigma off (a fit that is wrong as a whole, e.g. over a dropped frame): the
  // median rescaling takes it as this frame's noise, not as motion.
  wall_.block_col = wall_.block_row = 0;
  wall_.block_size = COLS; // the "mover" is every cell
  Shares shares;
  for (int frame = 0; frame < 6; ++frame)
    shares = step(3.0f);
  EXPECT_EQ(shares.block, 0.0);
}

TEST_F(MotionEvidenceTest, TheEvidenceFollowsTheCellsAlongTheFlow)
{
  // The block crosses the image by 2 cells per frame and is 4 cells wide: each cell of the
  // image holds it for 2 frames, too few to flag without carrying the evidence along p_i.
  wall_.block_size = 4;
  wall_.block_col = 0;
  Shares shares;
  for (int frame = 0; frame < 8; ++frame)
    shares = step(3.0f, 2);
  EXPECT_GE(shares.block, 0.9);
  EXPECT_LE(shares.rest, 0.01);
}

TEST_F(MotionEvidenceTest, AMoverThatStopsRejoinsTheStaticSet)
{
  for (int frame = 0; frame < 20; ++frame)
    step(4.0f);
  ASSERT_GE(step(0.0f).block, 0.9);
  // From the ceiling 2 h down to h at kappa - 3 per frame on average: 10 frames with the
  // defaults; 25 leaves room for the chi-square's spread (sd 2.4 per frame, 8 over 10).
  Shares shares;
  for (int frame = 0; frame < 25; ++frame)
    shares = step(0.0f);
  EXPECT_EQ(shares.block, 0.0);
}

TEST_F(MotionEvidenceTest, LimitZeroFlagsNothingAndBadParametersThrow)
{
  MotionEvidence::Parameters off;
  off.evidence_limit = 0.0f;
  evidence_.setParameters(off);
  Shares shares;
  for (int frame = 0; frame < 12; ++frame)
    shares = step(5.0f);
  EXPECT_EQ(shares.block, 0.0);
  MotionEvidence::Parameters bad;
  bad.evidence_drift = 0.0f;
  EXPECT_THROW(evidence_.setParameters(bad), std::invalid_argument);
  bad = MotionEvidence::Parameters();
  bad.evidence_clip = -1.0f;
  EXPECT_THROW(evidence_.setParameters(bad), std::invalid_argument);
}

TEST_F(MotionEvidenceTest, AnotherGridStartsOver)
{
  for (int frame = 0; frame < 12; ++frame)
    step(3.0f);
  pcl::PointCloud<PointFlow> other(20, 15);
  for (auto& f : other)
    f.valid_2d = f.valid_3d = 0;
  evidence_.predict(other, WIDTH, HEIGHT); // 32 px cells
  const FlowGrid& moving = evidence_.getMovingCells();
  ASSERT_EQ(moving.size(), 300u);
  for (const auto label : moving.labels)
    EXPECT_EQ(label, LABEL_NONE);
}

} // namespace
