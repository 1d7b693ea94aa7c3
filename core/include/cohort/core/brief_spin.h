// Hand-overs between the core and its workers at sub-millisecond frames: a thread woken through a
// condition variable runs tens of microseconds after the notify (a futex wake, more on a VM), a few
// per cent of a frame of four GPUs. So the waiting side polls for a short while where the other side
// is about to answer, and blocks on the condition variable only after that.
#pragma once

#include <chrono>

namespace cohort::core {

inline void cpu_relax() {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#elif defined(__aarch64__)
  asm volatile("yield");
#endif
}

// Polls `ready` until it holds or `until` has passed; true when it holds.
template <class Ready>
bool spin_until(std::chrono::steady_clock::time_point until, Ready&& ready) {
  for (int polls = 0;; ++polls) {
    if (ready()) return true;
    if ((polls & 63) == 0 && std::chrono::steady_clock::now() >= until) return ready();
    cpu_relax();
  }
}

}  // namespace cohort::core
