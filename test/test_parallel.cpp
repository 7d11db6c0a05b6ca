// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/common/parallel.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cstddef>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>

namespace {

using Ranges = std::vector<std::pair<std::size_t, std::size_t>>;

/// The ranges forEachStripe() hands out, sorted, and the threads that ran them.
std::pair<Ranges, std::size_t>
stripesOf(std::size_t n, unsigned threads)
{
  std::mutex lock;
  Ranges ranges;
  std::vector<std::thread::id> ids;
  dynvo::forEachStripe(n, threads, [&](std::size_t begin, std::size_t end) {
    const std::lock_guard<std::mutex> guard(lock);
    ranges.emplace_back(begin, end);
    if (std::find(ids.begin(), ids.end(), std::this_thread::get_id()) == ids.end())
      ids.push_back(std::this_thread::get_id());
  });
  std::sort(ranges.begin(), ranges.end());
  return {ranges, ids.size()};
}

TEST(ForEachStripe, CoversEveryItemOnceInContiguousStripes)
{
  // Every caller relies on this to give the same result for any thread count: each item in
  // exactly one stripe, the stripes those of the documented split.
  EXPECT_EQ(stripesOf(10, 1).first, (Ranges{{0, 10}}));
  EXPECT_EQ(stripesOf(10, 2).first, (Ranges{{0, 5}, {5, 10}}));
  EXPECT_EQ(stripesOf(10, 3).first, (Ranges{{0, 3}, {3, 6}, {6, 10}}));
  EXPECT_EQ(stripesOf(2, 4).first, (Ranges{{0, 1}, {1, 2}})); // no empty stripe
  EXPECT_TRUE(stripesOf(0, 2).first.empty());
}

TEST(ForEachStripe, OneThreadRunsOnTheCallersThread)
{
  // `-threads 1` must not touch OpenCV's pool.
  std::thread::id seen;
  dynvo::forEachStripe(1000, 1, [&](std::size_t, std::size_t) {
    seen = std::this_thread::get_id();
  });
  EXPECT_EQ(seen, std::this_thread::get_id());
  EXPECT_EQ(stripesOf(1000, 1).second, 1u);
}

} // namespace
