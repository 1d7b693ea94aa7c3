// Little-endian encoding of RenderWorld calls' arguments for the delta stream (docs/delta-stream.md).
// Private to the stream reader and writer.
//
// Encoder and Decoder have the same field(), fields(), flags() and sequence() calls, so each
// argument's layout is written once (render_world_stream_codec.cpp) and serves both directions. What
// only reading needs (names for errors, element sizes to check counts against) the Encoder ignores.
#pragma once

#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "cohort/scene/render_world.h"

namespace cohort::scene::stream_codec {

class Encoder {
 public:
  explicit Encoder(std::vector<uint8_t>& out) : out_(out) {}
  void u8(uint8_t v) { out_.push_back(v); }
  void u16(uint16_t v) { u8(uint8_t(v)); u8(uint8_t(v >> 8)); }
  void u32(uint32_t v) { for (int s = 0; s < 32; s += 8) u8(uint8_t(v >> s)); }
  void i32(int32_t v) { u32(static_cast<uint32_t>(v)); }
  void f32(float v) { uint32_t bits; std::memcpy(&bits, &v, 4); u32(bits); }
  void str(const std::string& s);
  void bytes(const uint8_t* p, size_t n) { out_.insert(out_.end(), p, p + n); }

  void field(int32_t v) { i32(v); }
  void field(uint32_t v) { u32(v); }
  void field(float v) { f32(v); }
  void field(const std::string& v) { str(v); }
  void field(const glm::vec2& v) { fields(v.x, v.y); }
  void field(const glm::vec3& v) { fields(v.x, v.y, v.z); }
  void field(const glm::vec4& v) { fields(v.x, v.y, v.z, v.w); }
  void field(const glm::mat3& m) { fields(m[0], m[1], m[2]); }
  template <size_t N>
  void field(const float (&values)[N]) { for (float v : values) f32(v); }
  void field(BlendClass v) { u8(static_cast<uint8_t>(v)); }
  void field(LightKind v) { u8(static_cast<uint8_t>(v)); }
  void field(const RenderEntity& v);
  void field(const RenderLight& v);
  void field(const Material& v);
  void field(const Image& v);
  void field(const Mesh& v);
  void field(const RenderView& v);
  template <class... T>
  void fields(const T&... v) { (field(v), ...); }
  // A u32 whose bit i is the i-th flag, in the order docs/delta-stream.md lists them.
  template <class... Flag>
  void flags(const char* /*what*/, Flag... set) {
    uint32_t bits = 0, bit = 1;
    ((bits |= set ? bit : 0, bit <<= 1), ...);
    u32(bits);
  }
  // A u32 count, then each item as `each` writes it.
  template <class T, class Each>
  void sequence(const std::vector<T>& items, size_t /*bytes_each*/, const char* /*what*/, Each each) {
    u32(static_cast<uint32_t>(items.size()));
    for (const T& item : items) each(item);
  }
  void texels(const Image& v);

 private:
  std::vector<uint8_t>& out_;
};

// Thrown with the position inside the decoded range; the caller adds the file offset.
class DecodeError : public std::runtime_error {
 public:
  DecodeError(size_t at, const std::string& what) : std::runtime_error(what), at(at) {}
  size_t at;
};

class Decoder {
 public:
  Decoder(const uint8_t* data, size_t size) : p_(data), size_(size) {}
  size_t pos() const { return pos_; }
  size_t left() const { return size_ - pos_; }
  void need(size_t n, const char* what) const;
  uint8_t u8() { need(1, "u8"); return p_[pos_++]; }
  uint16_t u16() { need(2, "u16"); uint16_t v = uint16_t(p_[pos_] | p_[pos_ + 1] << 8); pos_ += 2; return v; }
  uint32_t u32();
  int32_t i32() { return static_cast<int32_t>(u32()); }
  float f32();  // rejects NaN and infinities: no def holds one
  std::string str();
  // A count of elements of `element_bytes` each that must fit in what is left.
  uint32_t count(size_t element_bytes, const char* what);
  void bytes(uint8_t* out, size_t n) { need(n, "bytes"); std::memcpy(out, p_ + pos_, n); pos_ += n; }
  [[noreturn]] void fail(const std::string& what) const { throw DecodeError(pos_, what); }

  void field(int32_t& v) { v = i32(); }
  void field(uint32_t& v) { v = u32(); }
  void field(float& v) { v = f32(); }
  void field(std::string& v) { v = str(); }
  void field(glm::vec2& v) { fields(v.x, v.y); }
  void field(glm::vec3& v) { fields(v.x, v.y, v.z); }
  void field(glm::vec4& v) { fields(v.x, v.y, v.z, v.w); }
  void field(glm::mat3& m) { fields(m[0], m[1], m[2]); }
  template <size_t N>
  void field(float (&values)[N]) { for (float& v : values) v = f32(); }
  void field(BlendClass& v);
  void field(LightKind& v);
  void field(RenderEntity& v);
  void field(RenderLight& v);
  void field(Material& v);
  void field(Image& v);
  void field(Mesh& v);
  void field(RenderView& v);
  template <class... T>
  void fields(T&... v) { (field(v), ...); }
  template <class T>
  T read() {
    T v;
    field(v);
    return v;
  }
  template <class... Flag>
  void flags(const char* what, Flag&... set) {
    const uint32_t bits = u32();
    check_flags(bits, sizeof...(set), what);
    uint32_t bit = 1;
    ((set = (bits & bit) != 0, bit <<= 1), ...);
  }
  // Reads the u32 count (checked against the bytes left), then each item as `each` reads it.
  template <class T, class Each>
  void sequence(std::vector<T>& items, size_t bytes_each, const char* what, Each each) {
    items.resize(count(bytes_each, what));
    for (T& item : items) each(item);
  }
  void texels(Image& v);

 private:
  void check_flags(uint32_t bits, size_t flag_count, const char* what) const;

  const uint8_t* p_;
  size_t size_, pos_ = 0;
};

constexpr char kMagic[8] = {'C', 'O', 'H', 'D', 'E', 'L', 'T', 'A'};
constexpr uint32_t kFrameTag = 0x4D415246u;  // "FRAM"
constexpr uint32_t kDoneTag = 0x454E4F44u;   // "DONE"
constexpr size_t kChunkHeaderBytes = 16;     // tag, frame index, payload length, CRC-32
constexpr size_t kRecordHeaderBytes = 8;     // type u16, reserved u16, body length u32

}  // namespace cohort::scene::stream_codec
