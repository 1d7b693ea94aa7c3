#pragma once
// Reads a binary format in order from bytes in memory: raw bytes and trivially copyable scalars, with
// the bounds check before every copy. Shared by the scene pack (scene_pack.cpp) and the MPI messages
// (tracers/mpi/src/mpi_wire.cpp); each format derives from it and chooses its error: Derived must have
// `[[noreturn]] void fail(const std::string&) const`, which throws with the format's own context.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <type_traits>

#include <fmt/format.h>

namespace cohort::core {

template <class Derived> class ByteReader {
 public:
  void raw(void* p, size_t n) {
    if (n > left()) derived().fail(fmt::format("truncated: needs {} more bytes, {} left", n, left()));
    std::memcpy(p, data_ + pos_, n);
    pos_ += n;
  }
  template <class T> T scalar() {
    static_assert(std::is_trivially_copyable_v<T>);
    T v;
    raw(&v, sizeof v);
    return v;
  }
  size_t left() const { return size_ - pos_; }
  bool at_end() const { return pos_ == size_; }

 protected:
  // The bytes are not copied: they must outlive the reader.
  ByteReader(const uint8_t* data, size_t size) : data_(data), size_(size) {}

  const uint8_t* data_;
  size_t size_;
  size_t pos_ = 0;

 private:
  const Derived& derived() const { return static_cast<const Derived&>(*this); }
};

}  // namespace cohort::core
