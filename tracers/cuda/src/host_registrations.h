#pragma once

#include <cstddef>
#include <vector>

#include <cuda_runtime.h>

namespace cohort::tracers {

// Host ranges page-locked with cudaHostRegister, so that copies to and from them are true asynchronous
// DMA at full bus speed instead of going through the driver's pageable staging. Callers reuse their
// buffers frame after frame, so the most recent `capacity` ranges stay registered (the oldest is let go).
// A range the driver will not register is not an error: copies still work from pageable memory, slower.
class HostRegistrations {
 public:
  explicit HostRegistrations(size_t capacity) : slots_(capacity) {}
  ~HostRegistrations() {
    for (const Slot& s : slots_)
      if (s.ptr) cudaHostUnregister(s.ptr);
  }
  HostRegistrations(const HostRegistrations&) = delete;
  HostRegistrations& operator=(const HostRegistrations&) = delete;

  void ensure(const void* ptr, size_t bytes) {
    for (const Slot& s : slots_)
      if (s.ptr == ptr && s.bytes == bytes) return;
    Slot& slot = slots_[next_];
    next_ = (next_ + 1) % slots_.size();
    if (slot.ptr) cudaHostUnregister(slot.ptr);
    slot = {};
    if (cudaHostRegister(const_cast<void*>(ptr), bytes, cudaHostRegisterPortable) == cudaSuccess)
      slot = {const_cast<void*>(ptr), bytes};
    else
      cudaGetLastError();  // clear the sticky error; the copy goes through pageable memory
  }

 private:
  struct Slot {
    void* ptr = nullptr;
    size_t bytes = 0;
  };
  std::vector<Slot> slots_;
  size_t next_ = 0;
};

}  // namespace cohort::tracers
