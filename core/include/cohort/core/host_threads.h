// The host's per-pixel work (merging bands, blending frames, tone mapping) split over the CPU's cores
// by a small pool of threads that lives as long as the process, so a frame pays no thread start-up.
// Each range is independent, so results are the same as a serial loop's, bit for bit.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

namespace cohort::core {

class HostThreads {
 public:
  // The process's pool: one thread per hardware thread beyond the caller's.
  static HostThreads& shared();

  explicit HostThreads(unsigned threads);
  ~HostThreads();
  HostThreads(const HostThreads&) = delete;
  HostThreads& operator=(const HostThreads&) = delete;

  // Calls fn(begin, end) over [0, count) in contiguous ranges of at least min_range items, on the pool
  // and the calling thread, and returns when all have run. Calls from several threads take turns.
  void for_ranges(size_t count, size_t min_range, const std::function<void(size_t, size_t)>& fn);
  unsigned threads() const { return static_cast<unsigned>(workers_.size()) + 1; }

 private:
  struct Job {
    const std::function<void(size_t, size_t)>* fn = nullptr;
    size_t count = 0, ranges = 0;
    std::atomic<size_t> next{0}, unfinished{0};
  };
  void work_loop();
  void run_ranges(Job& job);

  std::vector<std::thread> workers_;
  std::mutex call_mutex_;            // one parallel region at a time
  std::mutex mutex_;                 // guards job_, generation_, quit_
  std::condition_variable wake_, done_;
  std::shared_ptr<Job> job_;
  unsigned long generation_ = 0;
  bool quit_ = false;
};

}  // namespace cohort::core
