#pragma once

#include <cstddef>
#include <vector>

#include <cuda_runtime.h>

namespace cohort::tracers {

// Host ranges page-locked with cudaHostRegister, so that copies to and from them are true asynchronous
// DMA at full bus speed instead of going through the driver's pageable staging. Callers reuse their
// buffers frame after frame, so the most recent `capacity` ranges stay registered (the oldest is let go).
// A range the driver will not register is not an error: copies still work from pageable memory, slower.
// A new range overlapping a registered one means that one was freed and its memory reused: it is
// unregistered first (a band target resized between frames, or a test's buffers one after another).
class HostRegistrations {
 public:
  explicit HostRegistrations(size_t capacity) : slots_(capacity) {}
  ~HostRegistrations() {
    for (const Slot& s : slots_)
      if (s.ptr) cudaHostUnregister(s.ptr);
  }
  HostRegistrations(const HostRegistrations&) = delete;
  HostRegistrations& operator=(const HostRegistrations&) = delete;

  // `what` names the range in the one warning logged when the driver refuses to page-lock it (the
  // copies then run at pageable speed: a third of the bus on an H100, measured).
  void ensure(const void* ptr, size_t bytes, const char* what);
  // Whether exactly this range is registered (ensure() would change nothing).
  bool contains(const void* ptr, size_t bytes) const {
    for (const Slot& s : slots_)
      if (s.ptr == ptr && s.bytes == bytes) return true;
    return false;
  }

 private:
  struct Slot {
    void* ptr = nullptr;
    size_t bytes = 0;
  };
  std::vector<Slot> slots_;
  size_t next_ = 0;
  bool warned_ = false;
};

}  // namespace cohort::tracers
