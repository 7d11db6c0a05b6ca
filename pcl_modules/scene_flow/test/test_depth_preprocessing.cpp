// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/scene_flow/depth_preprocessing.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

namespace {

constexpr float NaN = std::numeric_limits<float>::quiet_NaN();

class DepthPreprocessingTest : public ::testing::Test {
protected:
  /// w x h map at a constant depth (metres).
  void flat(std::uint32_t w, std::uint32_t h, float z)
  {
    width_ = w;
    height_ = h;
    depth_.assign(static_cast<std::size_t>(w) * h, z);
  }

  float& at(std::uint32_t x, std::uint32_t y)
  {
    return depth_[static_cast<std::size_t>(y) * width_ + x];
  }

  float out(std::uint32_t x, std::uint32_t y) const
  {
    return out_[static_cast<std::size_t>(y) * width_ + x];
  }

  void run() { preprocessing_.apply(depth_, width_, height_, out_); }

  dynvo::DepthPreprocessing preprocessing_;
  std::uint32_t width_ = 0, height_ = 0;
  std::vector<float> depth_, out_;
};

TEST_F(DepthPreprocessingTest, RangeLimitsMakeMissingAndOutOfRangeDepthsNaN)
{
  flat(12, 1, 1.0f);
  at(2, 0) = 0.0f;  // raw 0: no measurement
  at(5, 0) = 0.29f; // nearer than z_min = 0.3 m
  at(8, 0) = 5.01f; // farther than z_max = 5 m
  at(10, 0) = 5.0f; // the range is closed
  preprocessing_.setParameters({0.3f, 5.0f, 0.05f, 0, 0.05f}); // no hole filling
  run();
  EXPECT_TRUE(std::isnan(out(2, 0)));
  EXPECT_TRUE(std::isnan(out(5, 0)));
  EXPECT_TRUE(std::isnan(out(8, 0)));
  EXPECT_EQ(out(10, 0), 5.0f);
  EXPECT_EQ(out(0, 0), 1.0f);
}

TEST_F(DepthPreprocessingTest,
       IsolatedFlyingPixelIsRemovedButSmallDeviationsAndEdgesStay)
{
  flat(20, 10, 1.0f);
  at(4, 4) = 1.5f;   // 50% off its neighbours' median: flying
  at(10, 4) = 1.04f; // 4% off: within tau_fly = 5%
  for (std::uint32_t y = 0; y < 10; ++y)
    for (std::uint32_t x = 15; x < 20; ++x)
      at(x, y) =
          2.0f; // a clean step edge: each side's pixels have a majority on their side
  preprocessing_.setParameters({0.3f, 5.0f, 0.05f, 0, 0.05f}); // no hole filling
  run();
  EXPECT_TRUE(std::isnan(out(4, 4)));
  EXPECT_EQ(out(10, 4), 1.04f);
  for (std::uint32_t y = 0; y < 10; ++y) {
    EXPECT_EQ(out(14, y), 1.0f);
    EXPECT_EQ(out(15, y), 2.0f);
  }
  // With hole filling on, the removed pixel is a 1 px hole between equal depths.
  preprocessing_.setParameters({});
  run();
  EXPECT_EQ(out(4, 4), 1.0f);
}

TEST_F(DepthPreprocessingTest, PixelWithFewerThanFiveValidNeighboursIsKept)
{
  flat(5, 5, NaN);
  at(2, 2) = 3.0f;
  at(1, 1) = at(3, 1) = at(1, 3) = at(3, 3) = 1.0f; // four valid neighbours only
  preprocessing_.setParameters({0.3f, 5.0f, 0.05f, 0, 0.05f});
  run();
  EXPECT_EQ(out(2, 2), 3.0f);
}

TEST_F(DepthPreprocessingTest, NarrowRowHoleIsInterpolatedWideOrDiscontinuousHolesStay)
{
  flat(30, 1, 1.0f);
  for (std::uint32_t x = 3; x < 8; ++x) // 5 px hole between 1.0 and 1.03 m (3% apart)
    at(x, 0) = NaN;
  at(8, 0) = at(9, 0) = 1.03f;
  for (std::uint32_t x = 12; x < 18; ++x) // 6 px hole: wider than w_hole = 5
    at(x, 0) = NaN;
  for (std::uint32_t x = 20; x < 22; ++x) // 2 px hole between 1.0 and 1.5 m: an edge
    at(x, 0) = NaN;
  for (std::uint32_t x = 22; x < 30; ++x)
    at(x, 0) = 1.5f;
  run();
  for (std::uint32_t x = 3; x < 8; ++x)
    EXPECT_NEAR(out(x, 0), 1.0f + 0.03f * (x - 2.0f) / 6.0f, 1e-6f) << "x=" << x;
  for (std::uint32_t x = 12; x < 18; ++x)
    EXPECT_TRUE(std::isnan(out(x, 0))) << "x=" << x;
  EXPECT_TRUE(std::isnan(out(20, 0)));
  EXPECT_TRUE(std::isnan(out(21, 0)));
}

TEST_F(DepthPreprocessingTest, ColumnPassFillsHolesThatNoRowCanBridge)
{
  flat(10, 12, 1.0f);
  for (std::uint32_t y = 4; y < 7;
       ++y) // three whole rows missing: no row has valid ends
    for (std::uint32_t x = 0; x < 10; ++x)
      at(x, y) = NaN;
  run();
  for (std::uint32_t y = 4; y < 7; ++y)
    for (std::uint32_t x = 0; x < 10; ++x)
      EXPECT_EQ(out(x, y), 1.0f) << x << "," << y;
}

TEST_F(DepthPreprocessingTest, RowsThenColumnsIsApply)
{
  // The scene flow runs the column pass beside its pyramid: applyRows() must leave exactly
  // the column pass to applyColumns(), and the two in turn must be apply().
  flat(10, 12, 1.0f);
  for (std::uint32_t x = 0; x < 10; ++x)
    at(x, 5) = NaN; // a whole row missing: only the column pass bridges it
  at(3, 9) = NaN;   // a narrow row hole: the row pass fills it
  std::vector<float> rows;
  preprocessing_.applyRows(depth_, width_, height_, rows);
  EXPECT_TRUE(std::isnan(rows[5 * 10 + 4]));
  EXPECT_EQ(rows[9 * 10 + 3], 1.0f);
  preprocessing_.applyColumns(width_, height_, rows);
  EXPECT_EQ(rows[5 * 10 + 4], 1.0f);
  run();
  EXPECT_EQ(rows, out_);
  EXPECT_THROW(preprocessing_.applyColumns(width_, height_ + 1, rows),
               std::invalid_argument);
}

TEST_F(DepthPreprocessingTest, ResultDoesNotDependOnThreadCount)
{
  flat(97, 61, 1.0f);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> z(0.2f, 5.5f); // covers both range limits
  std::bernoulli_distribution missing(0.2);
  for (float& d : depth_)
    d = missing(rng) ? NaN : z(rng);
  run();
  const std::vector<float> single = out_;
  // Not vacuous: every rule fired somewhere, so the output holds both kept depths and
  // removed ones (an all-NaN output would compare equal with any thread count).
  const auto kept = std::count_if(single.begin(), single.end(), [](float z) {
    return std::isfinite(z);
  });
  EXPECT_GT(kept, 50);
  EXPECT_LT(kept, static_cast<long>(single.size()) - 50);
  for (unsigned threads : {2u, 3u}) {
    preprocessing_.setNumberOfThreads(threads);
    run();
    ASSERT_EQ(out_.size(), single.size());
    for (std::size_t i = 0; i < single.size(); ++i)
      ASSERT_TRUE(out_[i] == single[i] ||
                  (std::isnan(out_[i]) && std::isnan(single[i])))
          << "pixel " << i << " with " << threads << " threads";
  }
}

TEST_F(DepthPreprocessingTest, BadParametersAndSizesThrow)
{
  using P = dynvo::DepthPreprocessing::Parameters;
  EXPECT_THROW(preprocessing_.setParameters(P{0.0f, 5.0f, 0.05f, 5, 0.05f}),
               std::invalid_argument);
  EXPECT_THROW(preprocessing_.setParameters(P{2.0f, 1.0f, 0.05f, 5, 0.05f}),
               std::invalid_argument);
  EXPECT_THROW(preprocessing_.setParameters(P{0.3f, 5.0f, 1.0f, 5, 0.05f}),
               std::invalid_argument);
  EXPECT_THROW(preprocessing_.setParameters(P{0.3f, 5.0f, 0.05f, -1, 0.05f}),
               std::invalid_argument);
  EXPECT_THROW(preprocessing_.setParameters(P{0.3f, 5.0f, 0.05f, 5, -0.1f}),
               std::invalid_argument);
  EXPECT_THROW(preprocessing_.setNumberOfThreads(0), std::invalid_argument);
  flat(4, 4, 1.0f);
  EXPECT_THROW(preprocessing_.apply(depth_, 5, 4, out_), std::invalid_argument);
  EXPECT_THROW(preprocessing_.apply(depth_, 4, 4, depth_), std::invalid_argument);
}

} // namespace
