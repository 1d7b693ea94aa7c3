// What the tracers that enqueue their next band while the current one renders (core::Tracer::enqueues_ahead:
// the CUDA and OpenCL tracers) share: the signal a device's completion callback fires to wake the worker
// waiting for the next job, the guards around that wait, and whether a job is the one a band went ahead for.
#pragma once

#include <atomic>
#include <cstring>
#include <memory>
#include <mutex>

#include "cohort/core/tracer.h"

namespace cohort::tracers {

// Fired from a device's completion callback once a band is back (on a thread of the driver's, maybe after the
// band's wait has returned): while armed, it wakes the worker waiting for the next job. The callback holds a
// reference of its own (callback_argument), so a late callback finds the signal alive; the tracer disarms it
// (DisarmOnExit) before it stops waiting, so such a callback wakes nobody.
struct BandSignal {
  std::atomic<bool> done{false};
  std::mutex mutex;
  bool armed = true;
  const core::Tracer* tracer = nullptr;
  void fire() {
    done = true;
    std::lock_guard lock(mutex);
    if (armed) tracer->wake_queued_next();
  }
  void disarm() {
    std::lock_guard lock(mutex);
    armed = false;
  }
  // The callback's user pointer: a reference to `signal` that fire_and_release (or release, when the callback
  // could not be set) lets go.
  static void* callback_argument(const std::shared_ptr<BandSignal>& signal) {
    return new std::shared_ptr<BandSignal>(signal);
  }
  static void fire_and_release(void* user) {
    auto* signal = static_cast<std::shared_ptr<BandSignal>*>(user);
    (*signal)->fire();
    delete signal;
  }
  static void release(void* user) { delete static_cast<std::shared_ptr<BandSignal>*>(user); }
};

struct DisarmOnExit {
  BandSignal& signal;
  ~DisarmOnExit() { signal.disarm(); }
};

// Sets `flag` for its scope (the tracer applying the next job's commit ahead, inside queued_next).
struct FlagForScope {
  bool& flag;
  explicit FlagForScope(bool& f) : flag(f) { flag = true; }
  ~FlagForScope() { flag = false; }
  FlagForScope(const FlagForScope&) = delete;
  FlagForScope& operator=(const FlagForScope&) = delete;
};

// Whether job b is job a (the band enqueued ahead for a is b's): the same parameters, camera, previous camera
// and keep-on-device choice.
inline bool same_band_job(const core::BandJob& a, const core::BandJob& b) {
  return std::memcmp(&a.params, &b.params, sizeof a.params) == 0 && std::memcmp(&a.camera, &b.camera, sizeof a.camera) == 0 &&
         std::memcmp(&a.previous_camera, &b.previous_camera, sizeof a.previous_camera) == 0 &&
         a.keep_on_device == b.keep_on_device;
}

}  // namespace cohort::tracers
