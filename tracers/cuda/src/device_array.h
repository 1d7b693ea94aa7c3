#pragma once

#include <cstddef>
#include <vector>

#include "cuda_check.h"

namespace cohort::tracers {

// A device copy of one TracerScene array. Grows by doubling so appended BLASes rarely reallocate;
// uploads only the changed suffix when the array kept its storage.
template <class T>
class DeviceArray {
 public:
  DeviceArray() = default;
  DeviceArray(const DeviceArray&) = delete;
  DeviceArray& operator=(const DeviceArray&) = delete;
  ~DeviceArray() { if (ptr_) cudaFree(ptr_); }

  // Returns true when the storage moved (so views holding the old pointer must be rebuilt).
  bool upload(const std::vector<T>& host, size_t first_changed, cudaStream_t stream) {
    bool moved = false;
    if (host.size() > capacity_) {
      size_t capacity = capacity_ ? capacity_ : 64;
      while (capacity < host.size()) capacity *= 2;
      T* fresh = nullptr;
      COHORT_CUDA(cudaMalloc(&fresh, capacity * sizeof(T)));
      if (ptr_) COHORT_CUDA(cudaFree(ptr_));
      ptr_ = fresh;
      capacity_ = capacity;
      first_changed = 0;
      moved = true;
    }
    size_ = host.size();
    if (first_changed < size_)
      COHORT_CUDA(cudaMemcpyAsync(ptr_ + first_changed, host.data() + first_changed,
                                  (size_ - first_changed) * sizeof(T), cudaMemcpyHostToDevice, stream));
    return moved;
  }
  // Device-only storage of at least n elements (contents undefined), e.g. per-launch scratch.
  T* scratch(size_t n) {
    if (n > capacity_) {
      size_t capacity = capacity_ ? capacity_ : 64;
      while (capacity < n) capacity *= 2;
      if (ptr_) COHORT_CUDA(cudaFree(ptr_));
      ptr_ = nullptr;
      COHORT_CUDA(cudaMalloc(&ptr_, capacity * sizeof(T)));
      capacity_ = capacity;
    }
    size_ = n;
    return ptr_;
  }
  T* data() const { return ptr_; }
  size_t size() const { return size_; }
  size_t bytes() const { return capacity_ * sizeof(T); }

 private:
  T* ptr_ = nullptr;
  size_t size_ = 0, capacity_ = 0;
};

}  // namespace cohort::tracers
