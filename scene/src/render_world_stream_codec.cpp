#include "render_world_stream_codec.h"

#include <cmath>

#include <fmt/format.h>

#include "cohort/scene/render_world_stream.h"

namespace cohort::scene {

uint32_t crc32(const uint8_t* data, size_t size, uint32_t crc) {
  static const auto table = [] {
    std::vector<uint32_t> t(256);
    for (uint32_t i = 0; i < 256; ++i) {
      uint32_t c = i;
      for (int k = 0; k < 8; ++k) c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
      t[i] = c;
    }
    return t;
  }();
  crc = ~crc;
  for (size_t i = 0; i < size; ++i) crc = table[(crc ^ data[i]) & 0xFFu] ^ (crc >> 8);
  return ~crc;
}

const char* delta_record_name(uint16_t type) {
  switch (static_cast<DeltaRecord>(type)) {
    case DeltaRecord::AddEntityDef: return "AddEntityDef";
    case DeltaRecord::UpdateEntityDef: return "UpdateEntityDef";
    case DeltaRecord::FreeEntityDef: return "FreeEntityDef";
    case DeltaRecord::AddLightDef: return "AddLightDef";
    case DeltaRecord::UpdateLightDef: return "UpdateLightDef";
    case DeltaRecord::FreeLightDef: return "FreeLightDef";
    case DeltaRecord::DefineMaterial: return "DefineMaterial";
    case DeltaRecord::DefineTexture: return "DefineTexture";
    case DeltaRecord::DefineModel: return "DefineModel";
    case DeltaRecord::RenderScene: return "RenderScene";
    case DeltaRecord::EndFrame: return "EndFrame";
  }
  return "unknown";
}

namespace stream_codec {
namespace {

constexpr uint32_t kEntNoShadows = 1, kEntNoSelfShadow = 2;
constexpr uint32_t kLightPoint = 1, kLightParallel = 2, kLightStartEnd = 4, kLightNoShadows = 8, kLightNoSpecular = 16;
constexpr uint32_t kMatAlphaTest = 1, kMatTranslucent = 2, kMatNoShadows = 4, kMatTwoSided = 8, kMatNonsolid = 16,
                   kMatEmitter = 32, kMatVertexColor = 64, kMatLight = 128, kMatDefault = 256;
constexpr uint32_t kImgNormalMap = 1, kImgPlaceholder = 2;

constexpr size_t kVertexBytes = 12 * 4;
constexpr size_t kSurfaceBytes = 3 * 4;

void check_flags(Decoder& d, uint32_t flags, uint32_t known, const char* what) {
  if (flags & ~known) d.fail(fmt::format("{} flags 0x{:x} has unknown bits", what, flags));
}

}  // namespace

void Encoder::str(const std::string& s) {
  u32(static_cast<uint32_t>(s.size()));
  bytes(reinterpret_cast<const uint8_t*>(s.data()), s.size());
}

void Decoder::need(size_t n, const char* what) const {
  if (n > left()) throw DecodeError(pos_, fmt::format("reading {} needs {} bytes, only {} left in the record", what, n, left()));
}

uint32_t Decoder::u32() {
  need(4, "u32");
  uint32_t v = uint32_t(p_[pos_]) | uint32_t(p_[pos_ + 1]) << 8 | uint32_t(p_[pos_ + 2]) << 16 |
               uint32_t(p_[pos_ + 3]) << 24;
  pos_ += 4;
  return v;
}

float Decoder::f32() {
  size_t at = pos_;
  uint32_t bits = u32();
  float v;
  std::memcpy(&v, &bits, 4);
  if (!std::isfinite(v)) throw DecodeError(at, fmt::format("float 0x{:08x} is not finite", bits));
  return v;
}

std::string Decoder::str() {
  size_t at = pos_;
  uint32_t n = u32();
  if (n > kMaxDeltaStringBytes) throw DecodeError(at, fmt::format("string length {} over the limit {}", n, kMaxDeltaStringBytes));
  need(n, "string");
  std::string s(reinterpret_cast<const char*>(p_ + pos_), n);
  pos_ += n;
  return s;
}

uint32_t Decoder::count(size_t element_bytes, const char* what) {
  size_t at = pos_;
  uint32_t n = u32();
  if (uint64_t(n) * element_bytes > left())
    throw DecodeError(at, fmt::format("{} count {} needs {} bytes, only {} left in the record", what, n,
                                      uint64_t(n) * element_bytes, left()));
  return n;
}

void encode(Encoder& e, const RenderEntity& v) {
  e.i32(v.model);
  e.str(v.model_name);
  e.vec(v.origin);
  e.mat(v.axis);
  for (float p : v.shader_parms) e.f32(p);
  e.i32(v.custom_shader);
  e.u32((v.no_shadows ? kEntNoShadows : 0) | (v.no_self_shadow ? kEntNoSelfShadow : 0));
  e.i32(v.suppress_surface_in_view_id);
  e.i32(v.allow_surface_in_view_id);
}

RenderEntity decode_entity(Decoder& d) {
  RenderEntity v;
  v.model = d.i32();
  v.model_name = d.str();
  v.origin = d.vec3();
  v.axis = d.mat3();
  for (float& p : v.shader_parms) p = d.f32();
  v.custom_shader = d.i32();
  uint32_t flags = d.u32();
  check_flags(d, flags, kEntNoShadows | kEntNoSelfShadow, "entity");
  v.no_shadows = flags & kEntNoShadows;
  v.no_self_shadow = flags & kEntNoSelfShadow;
  v.suppress_surface_in_view_id = d.i32();
  v.allow_surface_in_view_id = d.i32();
  return v;
}

void encode(Encoder& e, const RenderLight& v) {
  e.vec(v.origin);
  e.mat(v.axis);
  e.u32((v.point_light ? kLightPoint : 0) | (v.parallel ? kLightParallel : 0) | (v.has_start_end ? kLightStartEnd : 0) |
        (v.no_shadows ? kLightNoShadows : 0) | (v.no_specular ? kLightNoSpecular : 0));
  for (const glm::vec3& x : {v.radius, v.center, v.target, v.right, v.up, v.start, v.end}) e.vec(x);
  e.i32(v.shader);
  e.str(v.shader_name);
  for (float p : v.shader_parms) e.f32(p);
}

RenderLight decode_light(Decoder& d) {
  RenderLight v;
  v.origin = d.vec3();
  v.axis = d.mat3();
  uint32_t flags = d.u32();
  check_flags(d, flags, kLightPoint | kLightParallel | kLightStartEnd | kLightNoShadows | kLightNoSpecular, "light");
  v.point_light = flags & kLightPoint;
  v.parallel = flags & kLightParallel;
  v.has_start_end = flags & kLightStartEnd;
  v.no_shadows = flags & kLightNoShadows;
  v.no_specular = flags & kLightNoSpecular;
  for (glm::vec3* x : {&v.radius, &v.center, &v.target, &v.right, &v.up, &v.start, &v.end}) *x = d.vec3();
  v.shader = d.i32();
  v.shader_name = d.str();
  for (float& p : v.shader_parms) p = d.f32();
  return v;
}

void encode(Encoder& e, const Material& v) {
  e.str(v.name);
  e.str(v.source_file);
  e.i32(v.source_line);
  for (int i : {v.diffuse_image, v.normal_image, v.specular_image, v.emissive_image, v.light_image, v.falloff_image})
    e.i32(i);
  e.vec(v.diffuse_color);
  e.vec(v.specular_color);
  e.vec(v.emissive_color);
  for (float m : v.tex_transform) e.f32(m);
  e.u32((v.alpha_test ? kMatAlphaTest : 0) | (v.translucent ? kMatTranslucent : 0) | (v.no_shadows ? kMatNoShadows : 0) |
        (v.two_sided ? kMatTwoSided : 0) | (v.nonsolid ? kMatNonsolid : 0) | (v.emitter ? kMatEmitter : 0) |
        (v.vertex_color ? kMatVertexColor : 0) | (v.is_light_material ? kMatLight : 0) |
        (v.is_default ? kMatDefault : 0));
  e.f32(v.alpha_ref);
  e.u8(static_cast<uint8_t>(v.blend));
  e.vec(v.light_stage_color);
}

Material decode_material(Decoder& d) {
  Material v;
  v.name = d.str();
  v.source_file = d.str();
  v.source_line = d.i32();
  for (int* i : {&v.diffuse_image, &v.normal_image, &v.specular_image, &v.emissive_image, &v.light_image,
                 &v.falloff_image})
    *i = d.i32();
  v.diffuse_color = d.vec4();
  v.specular_color = d.vec4();
  v.emissive_color = d.vec4();
  for (float& m : v.tex_transform) m = d.f32();
  uint32_t flags = d.u32();
  check_flags(d, flags, 511, "material");
  v.alpha_test = flags & kMatAlphaTest;
  v.translucent = flags & kMatTranslucent;
  v.no_shadows = flags & kMatNoShadows;
  v.two_sided = flags & kMatTwoSided;
  v.nonsolid = flags & kMatNonsolid;
  v.emitter = flags & kMatEmitter;
  v.vertex_color = flags & kMatVertexColor;
  v.is_light_material = flags & kMatLight;
  v.is_default = flags & kMatDefault;
  v.alpha_ref = d.f32();
  uint8_t blend = d.u8();
  if (blend > static_cast<uint8_t>(BlendClass::Alpha)) d.fail(fmt::format("blend class {} unknown", blend));
  v.blend = static_cast<BlendClass>(blend);
  v.light_stage_color = d.vec3();
  return v;
}

void encode(Encoder& e, const Image& v) {
  e.str(v.name);
  e.i32(v.width);
  e.i32(v.height);
  e.u32((v.is_normal_map ? kImgNormalMap : 0) | (v.is_placeholder ? kImgPlaceholder : 0));
  e.u32(static_cast<uint32_t>(v.rgba.size()));
  e.bytes(v.rgba.data(), v.rgba.size());
}

Image decode_image(Decoder& d) {
  Image v;
  v.name = d.str();
  v.width = d.i32();
  v.height = d.i32();
  uint32_t flags = d.u32();
  check_flags(d, flags, kImgNormalMap | kImgPlaceholder, "image");
  v.is_normal_map = flags & kImgNormalMap;
  v.is_placeholder = flags & kImgPlaceholder;
  uint32_t n = d.count(1, "texel byte");
  if (v.width <= 0 || v.height <= 0 || uint64_t(v.width) * uint64_t(v.height) * 4 != n)
    d.fail(fmt::format("image '{}' is {}x{} but carries {} bytes of RGBA", v.name, v.width, v.height, n));
  v.rgba.resize(n);
  d.bytes(v.rgba.data(), n);
  return v;
}

void encode(Encoder& e, const Mesh& v) {
  e.str(v.name);
  e.u32(static_cast<uint32_t>(v.vertices.size()));
  for (const Vertex& x : v.vertices) {
    e.vec(x.position);
    e.vec(x.st);
    e.vec(x.normal);
    e.vec(x.tangent);
  }
  e.u32(static_cast<uint32_t>(v.indices.size()));
  for (uint32_t i : v.indices) e.u32(i);
  e.u32(static_cast<uint32_t>(v.surfaces.size()));
  for (const Surface& s : v.surfaces) {
    e.i32(s.material);
    e.u32(s.first_index);
    e.u32(s.index_count);
  }
}

Mesh decode_mesh(Decoder& d) {
  Mesh v;
  v.name = d.str();
  v.vertices.resize(d.count(kVertexBytes, "vertex"));
  for (Vertex& x : v.vertices) {
    x.position = d.vec3();
    x.st = d.vec2();
    x.normal = d.vec3();
    x.tangent = d.vec4();
  }
  v.indices.resize(d.count(4, "index"));
  for (uint32_t& i : v.indices) i = d.u32();
  v.surfaces.resize(d.count(kSurfaceBytes, "surface"));
  for (Surface& s : v.surfaces) {
    s.material = d.i32();
    s.first_index = d.u32();
    s.index_count = d.u32();
  }
  return v;
}

void encode(Encoder& e, const RenderView& v) {
  e.vec(v.origin);
  e.mat(v.axis);
  e.f32(v.fov_x);
  e.f32(v.fov_y);
  e.i32(v.time_ms);
  e.i32(v.view_id);
}

RenderView decode_view(Decoder& d) {
  RenderView v;
  v.origin = d.vec3();
  v.axis = d.mat3();
  v.fov_x = d.f32();
  v.fov_y = d.f32();
  v.time_ms = d.i32();
  v.view_id = d.i32();
  return v;
}

}  // namespace stream_codec
}  // namespace cohort::scene
