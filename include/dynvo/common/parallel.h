// SPDX-License-Identifier: BSD-3-Clause
// Contiguous stripes of work on an explicit number of threads (OpenCV's pool, kept private).
#pragma once

#include <dynvo/common/export.h>

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <functional>
#include <future>
#include <memory>
#include <mutex>
#include <thread>
#include <type_traits>

namespace dynvo {

/** \brief Runs body(begin, end) on the items [0, n) cut into k = min(threads, n) contiguous
 * stripes, stripe s being [n s / k, n (s + 1) / k), each on its own thread (k == 1: on the
 * caller's thread). With n == threads every stripe holds one item, and begin is the
 * stripe's index: the form for work a stripe chooses by its index (one task per stripe, or
 * items dealt to the stripes in turn).
 *
 * cv::setNumThreads() is process-wide, so the thread count is passed here instead. The
 * stripes go through cv::parallel_for_ (a single one too), which runs any parallel_for_
 * nested inside a running one serially (OpenCV 4.x, core/src/parallel.cpp): OpenCV calls
 * made by body (LK, pyramids) stay on the stripe's own thread, and one thread is one thread.
 * Side effect: while the stripes run, OpenCV calls from other threads of the process run
 * serially too. Whatever the count, body sees the same items: work whose items are
 * independent gives the same result for any thread count.
 */
DYNVO_EXPORTS void
forEachStripe(std::size_t n,
              unsigned threads,
              const std::function<void(std::size_t, std::size_t)>& body);

/** \brief One thread kept for the object's life, running the tasks handed to run() one after
 * another beside the caller. std::async(std::launch::async) starts a thread per task, about
 * 60 us of the caller's time on a 2-core VM (src/app/NOTES.md, twenty-third session); a pipeline
 * that hands a task over twice per frame keeps this one instead. The destructor runs the tasks
 * already handed over, then joins.
 */
class DYNVO_EXPORTS TaskThread {
public:
  TaskThread();
  ~TaskThread();
  TaskThread(const TaskThread&) = delete;
  TaskThread& operator=(const TaskThread&) = delete;

  /// Queues task; its result (or exception) arrives through the future.
  template <typename Task>
  std::future<std::invoke_result_t<Task>> run(Task task)
  {
    auto job = std::make_shared<std::packaged_task<std::invoke_result_t<Task>()>>(
        std::move(task));
    auto result = job->get_future();
    post([job] { (*job)(); });
    return result;
  }

private:
  void post(std::function<void()> job);
  void loop();

  std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<std::function<void()>> jobs_;
  bool stop_ = false;
  std::thread thread_; ///< last: started once the members above exist
};

} // namespace dynvo
