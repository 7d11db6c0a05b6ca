// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/common/timestamps.h>

#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

namespace {

using Pairs = std::vector<std::pair<std::size_t, std::size_t>>;

TEST(AssociateTimestamps, NearestWithinToleranceOneToOne)
{
  // Depth runs 4-5 ms behind colour, as in the TUM recordings: each colour stamp pairs
  // with the depth stamp just after it.
  const std::vector<double> rgb = {0.000, 0.033, 0.066, 0.100, 0.133};
  const std::vector<double> depth = {0.005, 0.038, 0.071, 0.104, 0.138};
  EXPECT_EQ(dynvo::associateTimestamps(rgb, depth),
            (Pairs{{0, 0}, {1, 1}, {2, 2}, {3, 3}, {4, 4}}));

  // 0.150 pairs with colour 0.133 (17 ms); 0.190 is 57 ms from any colour stamp, beyond
  // the 0.02 s tolerance, and stays unmatched.
  const std::vector<double> sparse = {0.005, 0.150, 0.190};
  EXPECT_EQ(dynvo::associateTimestamps(rgb, sparse), (Pairs{{0, 0}, {4, 1}}));
}

TEST(AssociateTimestamps, EachStampUsedOnceGreedyByDifference)
{
  // Both colour stamps are within tolerance of the single depth stamp; the closer wins
  // and the other stays unmatched rather than being paired twice.
  const std::vector<double> rgb = {1.000, 1.012};
  const std::vector<double> depth = {1.010};
  EXPECT_EQ(dynvo::associateTimestamps(rgb, depth), (Pairs{{1, 0}}));
}

TEST(AssociateTimestamps, UnsortedInputAndOffset)
{
  const std::vector<double> first = {3.0, 1.0, 2.0};
  const std::vector<double> second = {0.0, 2.0, 1.0};
  // With offset 1.0 the second list becomes {1, 3, 2}; result sorted by first stamp.
  EXPECT_EQ(dynvo::associateTimestamps(first, second, 0.02, 1.0),
            (Pairs{{1, 0}, {2, 2}, {0, 1}}));
}

TEST(FindClosestIndex, MatchesTheBenchmarkSearch)
{
  const std::vector<double> stamps = {0.0, 1.0, 2.0, 3.0, 4.0};
  EXPECT_EQ(dynvo::findClosestIndex(stamps, -5.0), 0u);
  EXPECT_EQ(dynvo::findClosestIndex(stamps, 2.0), 2u);
  EXPECT_EQ(dynvo::findClosestIndex(stamps, 2.4), 2u);
  EXPECT_EQ(dynvo::findClosestIndex(stamps, 2.6), 3u);
  EXPECT_EQ(dynvo::findClosestIndex(stamps, 40.0), 4u);
}

TEST(ParseDecimal, PlainDecimalsOnly)
{
  double value = -7.0;
  for (const auto& [text, expected] : std::vector<std::pair<std::string, double>>{
           {"1305031102.175304", 1305031102.175304},
           {"-1.5", -1.5},
           {"+2", 2.0},
           {".5", 0.5},
           {"3.", 3.0},
           {"1e3", 1000.0},
           {"2.5E-1", 0.25}}) {
    EXPECT_TRUE(dynvo::parseDecimal(text, value)) << text;
    EXPECT_DOUBLE_EQ(value, expected) << text;
  }
  // std::stod takes the first five; the rest are malformed or out of range.
  for (const std::string text : {"0x1p3", "inf", "nan", "-infinity", " 1", "1 ", "1.5s",
                                 "", ".", "e3", "1e", "1e+", "--1", "1e999", "1.2.3"}) {
    value = -7.0;
    EXPECT_FALSE(dynvo::parseDecimal(text, value)) << text;
    EXPECT_EQ(value, -7.0) << text;
  }
}

} // namespace
