#include "host_registrations.h"

#include <algorithm>

#include <spdlog/spdlog.h>

namespace cohort::tracers {

void HostRegistrations::ensure(const void* ptr, size_t bytes, const char* what) {
  for (const Slot& s : slots_)
    if (s.ptr == ptr && s.bytes == bytes) return;
  // A registered range the new one overlaps was freed by its owner (live buffers never overlap) and its
  // memory handed out again: its registration must go first. Left in place, the driver refuses the new
  // range ("already mapped") and a copy that starts in the stale range and runs past it fails.
  const char* begin = static_cast<const char*>(ptr);
  for (Slot& s : slots_) {
    const char* s_begin = static_cast<const char*>(s.ptr);
    if (s.ptr && s_begin < begin + bytes && begin < s_begin + s.bytes) {
      cudaHostUnregister(s.ptr);
      cudaGetLastError();
      s = {};
    }
  }
  // A slot left empty (by the stale ranges above, or never used) before the oldest live registration, which
  // would cost its buffer another registration when it comes back.
  auto empty = std::find_if(slots_.begin(), slots_.end(), [](const Slot& s) { return !s.ptr; });
  Slot& slot = empty != slots_.end() ? *empty : slots_[next_];
  if (empty == slots_.end()) next_ = (next_ + 1) % slots_.size();
  if (slot.ptr) cudaHostUnregister(slot.ptr);
  slot = {};
  const cudaError_t error = cudaHostRegister(const_cast<void*>(ptr), bytes, cudaHostRegisterPortable);
  if (error == cudaSuccess) {
    slot = {const_cast<void*>(ptr), bytes};
    return;
  }
  cudaGetLastError();  // clear the sticky error; the copy goes through pageable memory
  if (!warned_)
    spdlog::warn("CUDA could not page-lock {} ({} bytes at {}): {}; its copies run at pageable speed", what, bytes, ptr,
                 cudaGetErrorString(error));
  warned_ = true;
}

}  // namespace cohort::tracers
