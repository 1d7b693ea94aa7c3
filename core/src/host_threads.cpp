#include "cohort/core/host_threads.h"

#include <algorithm>

namespace cohort::core {

HostThreads& HostThreads::shared() {
  static HostThreads pool(std::max(1u, std::thread::hardware_concurrency()) - 1);
  return pool;
}

HostThreads::HostThreads(unsigned threads) {
  for (unsigned i = 0; i < threads; ++i) workers_.emplace_back([this] { work_loop(); });
}

HostThreads::~HostThreads() {
  {
    std::lock_guard lock(mutex_);
    quit_ = true;
  }
  wake_.notify_all();
  for (std::thread& t : workers_) t.join();
}

void HostThreads::run_ranges(Job& job) {
  for (;;) {
    const size_t r = job.next.fetch_add(1);
    if (r >= job.ranges) return;
    (*job.fn)(r * job.count / job.ranges, (r + 1) * job.count / job.ranges);
    if (job.unfinished.fetch_sub(1) == 1) {
      std::lock_guard lock(mutex_);
      done_.notify_all();
    }
  }
}

void HostThreads::work_loop() {
  unsigned long seen = 0;
  for (;;) {
    std::shared_ptr<Job> job;
    {
      std::unique_lock lock(mutex_);
      wake_.wait(lock, [&] { return quit_ || generation_ != seen; });
      if (quit_) return;
      seen = generation_;
      job = job_;  // a late waker holds a finished job: it finds no range left and goes back to sleep
    }
    if (job) run_ranges(*job);
  }
}

void HostThreads::for_ranges(size_t count, size_t min_range, const std::function<void(size_t, size_t)>& fn) {
  const size_t ranges = std::min<size_t>(threads(), count / std::max<size_t>(min_range, 1));
  if (ranges <= 1) {
    if (count > 0) fn(0, count);
    return;
  }
  std::lock_guard call(call_mutex_);
  auto job = std::make_shared<Job>();
  job->fn = &fn;
  job->count = count;
  job->ranges = ranges;
  job->unfinished = ranges;
  {
    std::lock_guard lock(mutex_);
    job_ = job;
    ++generation_;
  }
  wake_.notify_all();
  run_ranges(*job);
  std::unique_lock lock(mutex_);
  done_.wait(lock, [&] { return job->unfinished.load() == 0; });
  job_.reset();
}

}  // namespace cohort::core
