#include "host_registrations.h"

#include <spdlog/spdlog.h>

namespace cohort::tracers {

void HostRegistrations::ensure(const void* ptr, size_t bytes, const char* what) {
  for (const Slot& s : slots_)
    if (s.ptr == ptr && s.bytes == bytes) return;
  Slot& slot = slots_[next_];
  next_ = (next_ + 1) % slots_.size();
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
