// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/registration/inlier_noise_tracker.h>

#include <gtest/gtest.h>

#include <limits>
#include <stdexcept>

namespace {

TEST(InlierNoiseTracker, StartsAtTheUpperBound)
{
  dynvo::InlierNoiseTracker tracker;
  tracker.setUpperBound(6e-5);
  EXPECT_EQ(tracker.getInlierThreshold(), 6e-5);
  EXPECT_EQ(tracker.getResidualMean(), 0.0);
}

TEST(InlierNoiseTracker, FollowsTheRunningMeanWithinTheBounds)
{
  dynvo::InlierNoiseTracker tracker;
  tracker.setUpperBound(6e-5);
  // The first residual starts the mean; 3 x 1.5e-5 = 4.5e-5 lies inside [3e-5, 6e-5].
  tracker.addResidual(1.5e-5);
  EXPECT_DOUBLE_EQ(tracker.getResidualMean(), 1.5e-5);
  EXPECT_DOUBLE_EQ(tracker.getInlierThreshold(), 4.5e-5);
  // The next one weighs 0.1.
  tracker.addResidual(2.5e-5);
  EXPECT_DOUBLE_EQ(tracker.getResidualMean(), 0.9 * 1.5e-5 + 0.1 * 2.5e-5);
  EXPECT_DOUBLE_EQ(tracker.getInlierThreshold(), 3.0 * (0.9 * 1.5e-5 + 0.1 * 2.5e-5));

  // Clean synthetic residuals (2e-6 m^2) stay at the lower bound, the paper's 3e-5.
  tracker.reset();
  tracker.addResidual(2e-6);
  EXPECT_DOUBLE_EQ(tracker.getInlierThreshold(),
                   static_cast<double>(tracker.getMinInlierThreshold()));
  // Large residuals stop at the upper bound.
  tracker.reset();
  tracker.addResidual(1e-3);
  EXPECT_EQ(tracker.getInlierThreshold(), 6e-5);
}

TEST(InlierNoiseTracker, FactorZeroKeepsTheUpperBound)
{
  dynvo::InlierNoiseTracker tracker;
  tracker.setUpperBound(6e-5);
  tracker.setInlierNoiseFactor(0.0f);
  tracker.addResidual(1.5e-5);
  EXPECT_EQ(tracker.getInlierThreshold(), 6e-5);
}

TEST(InlierNoiseTracker, BadValuesThrowAndKeepTheOldOnes)
{
  const dynvo::InlierNoiseTrackerParameters defaults;
  EXPECT_NO_THROW(defaults.validate());
  EXPECT_FLOAT_EQ(defaults.inlier_noise_factor, 3.0f);
  EXPECT_FLOAT_EQ(defaults.min_inlier_threshold, 3e-5f);
  dynvo::InlierNoiseTracker tracker;
  EXPECT_THROW(tracker.setInlierNoiseFactor(-1.0f), std::invalid_argument);
  EXPECT_THROW(tracker.setMinInlierThreshold(0.0f), std::invalid_argument);
  EXPECT_THROW(tracker.setUpperBound(0.0), std::invalid_argument);
  EXPECT_THROW(tracker.setUpperBound(std::numeric_limits<double>::quiet_NaN()),
               std::invalid_argument);
  EXPECT_FLOAT_EQ(tracker.getInlierNoiseFactor(), 3.0f);
  EXPECT_EQ(tracker.getUpperBound(), 3e-5);
}

} // namespace
