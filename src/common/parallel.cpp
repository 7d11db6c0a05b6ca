// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/common/parallel.h>

#include <opencv2/core/utility.hpp>

#include <algorithm>

namespace dynvo {

void
forEachStripe(std::size_t n,
              unsigned threads,
              const std::function<void(std::size_t, std::size_t)>& body)
{
  const std::size_t stripes = std::min<std::size_t>(threads, n);
  if (stripes == 0)
    return;
  // One stripe goes through parallel_for_ too: OpenCV runs it on the caller's thread, and
  // the OpenCV calls body makes inside it serially (not on OpenCV's whole pool).
  cv::parallel_for_(
      cv::Range(0, static_cast<int>(stripes)),
      [&](const cv::Range& range) {
        for (int s = range.start; s < range.end; ++s) {
          const auto k = static_cast<std::size_t>(s);
          body(n * k / stripes, n * (k + 1) / stripes);
        }
      },
      static_cast<double>(stripes));
}

TaskThread::TaskThread()
    : thread_([this] { loop(); })
{
}

TaskThread::~TaskThread()
{
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_one();
  thread_.join();
}

void
TaskThread::post(std::function<void()> job)
{
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    jobs_.push_back(std::move(job));
  }
  wake_.notify_one();
}

void
TaskThread::loop()
{
  for (;;) {
    std::function<void()> job;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [this] { return stop_ || !jobs_.empty(); });
      if (jobs_.empty())
        return; // stopped, nothing left
      job = std::move(jobs_.front());
      jobs_.pop_front();
    }
    job();
  }
}

} // namespace dynvo
