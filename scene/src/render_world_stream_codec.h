// Little-endian encoding of RenderWorld calls' arguments for the delta stream (docs/delta-stream.md).
// Private to the stream reader and writer.
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
  void vec(const glm::vec2& v) { f32(v.x); f32(v.y); }
  void vec(const glm::vec3& v) { f32(v.x); f32(v.y); f32(v.z); }
  void vec(const glm::vec4& v) { f32(v.x); f32(v.y); f32(v.z); f32(v.w); }
  void mat(const glm::mat3& m) { vec(m[0]); vec(m[1]); vec(m[2]); }
  void bytes(const uint8_t* p, size_t n) { out_.insert(out_.end(), p, p + n); }

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
  glm::vec2 vec2() { float x = f32(); return {x, f32()}; }
  glm::vec3 vec3() { float x = f32(), y = f32(); return {x, y, f32()}; }
  glm::vec4 vec4() { float x = f32(), y = f32(), z = f32(); return {x, y, z, f32()}; }
  glm::mat3 mat3() { glm::vec3 a = vec3(), b = vec3(); return {a, b, vec3()}; }
  // A count of elements of `element_bytes` each that must fit in what is left.
  uint32_t count(size_t element_bytes, const char* what);
  void bytes(uint8_t* out, size_t n) { need(n, "bytes"); std::memcpy(out, p_ + pos_, n); pos_ += n; }
  [[noreturn]] void fail(const std::string& what) const { throw DecodeError(pos_, what); }

 private:
  const uint8_t* p_;
  size_t size_, pos_ = 0;
};

void encode(Encoder& e, const RenderEntity& v);
void encode(Encoder& e, const RenderLight& v);
void encode(Encoder& e, const Material& v);
void encode(Encoder& e, const Image& v);
void encode(Encoder& e, const Mesh& v);
void encode(Encoder& e, const RenderView& v);

RenderEntity decode_entity(Decoder& d);
RenderLight decode_light(Decoder& d);
Material decode_material(Decoder& d);
Image decode_image(Decoder& d);
Mesh decode_mesh(Decoder& d);
RenderView decode_view(Decoder& d);

constexpr char kMagic[8] = {'C', 'O', 'H', 'D', 'E', 'L', 'T', 'A'};
constexpr uint32_t kFrameTag = 0x4D415246u;  // "FRAM"
constexpr uint32_t kDoneTag = 0x454E4F44u;   // "DONE"
constexpr size_t kChunkHeaderBytes = 16;     // tag, frame index, payload length, CRC-32
constexpr size_t kRecordHeaderBytes = 8;     // type u16, reserved u16, body length u32

}  // namespace cohort::scene::stream_codec
