// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/common/parallel.h>

#include <gtest/gtest.h>
#include <opencv2/core/utility.hpp>

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <future>
#include <mutex>
#include <stdexcept>
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

TEST(ForEachStripe, OneThreadKeepsOpenCVsOwnLoopsOnIt)
{
  // OpenCV's functions (LK, pyramids) run their own parallel_for_ on its whole pool unless
  // they are nested in a running one: a single stripe must still be such a region, or
  // `-threads 1` uses every core (a bug seen in the benchmark, not in any result).
  if (cv::getNumThreads() < 2)
    GTEST_SKIP() << "OpenCV's pool has one thread here: nothing to keep off it";
  std::mutex mutex;
  std::vector<std::thread::id> seen;
  dynvo::forEachStripe(1, 1, [&](std::size_t, std::size_t) {
    cv::parallel_for_(
        cv::Range(0, 64),
        [&](const cv::Range& range) {
          for (int i = range.start; i < range.end; ++i) {
            // Long enough for OpenCV's idle workers to wake up and take items, had they
            // been allowed to.
            std::this_thread::sleep_for(std::chrono::milliseconds(1));
            const std::lock_guard<std::mutex> lock(mutex);
            seen.push_back(std::this_thread::get_id());
          }
        },
        64.0);
  });
  ASSERT_EQ(seen.size(), 64u);
  for (const std::thread::id& id : seen)
    EXPECT_EQ(id, std::this_thread::get_id());
}

TEST(TaskThread, RunsTasksInTurnBesideTheCaller)
{
  // The pipeline hands its backend inputs, then its pixel stage, to one kept thread: they
  // must run off the caller's thread, one after the other in the order handed over, each
  // result (or exception) reaching its own future.
  dynvo::TaskThread worker;
  std::vector<int> order; // written by the worker only
  std::promise<void> release;
  std::shared_future<void> released = release.get_future().share();
  auto first = worker.run([&] {
    released.wait(); // the caller queues the others meanwhile
    order.push_back(1);
    return std::this_thread::get_id();
  });
  auto second = worker.run([&] {
    order.push_back(2);
    return 2.5;
  });
  auto third = worker.run([&]() -> int {
    order.push_back(3);
    throw std::runtime_error("a failing task");
  });
  release.set_value();
  EXPECT_NE(first.get(), std::this_thread::get_id());
  EXPECT_EQ(second.get(), 2.5);
  EXPECT_THROW(third.get(), std::runtime_error);
  EXPECT_EQ(order, (std::vector<int>{1, 2, 3}));
}

TEST(TaskThread, DestructorRunsWhatWasHandedOver)
{
  // The pipeline's members outlive its worker: a task still queued at the end must run
  // before the thread is joined, not be dropped with its future's waiter left hanging.
  std::future<int> late;
  {
    dynvo::TaskThread worker;
    worker.run([] { std::this_thread::sleep_for(std::chrono::milliseconds(20)); });
    late = worker.run([] { return 7; });
  }
  ASSERT_EQ(late.wait_for(std::chrono::seconds(0)), std::future_status::ready);
  EXPECT_EQ(late.get(), 7);
}

} // namespace
