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

constexpr size_t kVertexBytes = 12 * 4;
constexpr size_t kSurfaceBytes = 3 * 4;
constexpr size_t kJointBytes = 7 * 4;

// Each argument's layout, as docs/delta-stream.md gives it: one list for both directions, with
// Codec an Encoder (and a const argument) or a Decoder.

template <class Codec, class Entity>
void entity_layout(Codec& c, Entity& v) {
  c.fields(v.model, v.model_name, v.origin, v.axis, v.shader_parms, v.custom_shader);
  c.flags("entity", v.no_shadows, v.no_self_shadow);
  c.fields(v.suppress_surface_in_view_id, v.allow_surface_in_view_id);
  c.sequence(v.joints, kJointBytes, "joint", [&](auto& j) {
    c.fields(j.rotation.x, j.rotation.y, j.rotation.z, j.rotation.w, j.position);
  });
}

template <class Codec, class Light>
void light_layout(Codec& c, Light& v) {
  c.fields(v.origin, v.axis);
  c.flags("light", v.point_light, v.parallel, v.has_start_end, v.no_shadows, v.no_specular);
  c.fields(v.radius, v.center, v.target, v.right, v.up, v.start, v.end, v.shader, v.shader_name, v.shader_parms);
}

template <class Codec, class Mat>
void material_layout(Codec& c, Mat& v) {
  c.fields(v.name, v.source_file, v.source_line, v.diffuse_image, v.normal_image, v.specular_image,
           v.emissive_image, v.light_image, v.falloff_image, v.diffuse_color, v.specular_color, v.emissive_color,
           v.tex_transform);
  c.flags("material", v.alpha_test, v.translucent, v.no_shadows, v.two_sided, v.nonsolid, v.emitter,
          v.vertex_color, v.is_light_material, v.is_default, v.no_self_shadow, v.inverse_vertex_color);
  c.fields(v.alpha_ref, v.blend, v.light_stage_color, v.light_kind, v.light_stage_alpha);
  c.flags("light material", v.light_blend_adds);
  c.fields(v.sky_cube_image, v.sky_axis, v.blend_diffuse_image, v.environment_cube_image, v.environment_color);
  c.flags("environment", v.environment_by_normal, v.environment_under_layer);
}

template <class Codec, class Img>
void image_layout(Codec& c, Img& v) {
  c.fields(v.name, v.width, v.height);
  c.flags("image", v.is_normal_map, v.is_placeholder);
  c.texels(v);
}

template <class Codec, class M>
void mesh_layout(Codec& c, M& v) {
  c.field(v.name);
  c.sequence(v.vertices, kVertexBytes, "vertex",
             [&](auto& x) { c.fields(x.position, x.st, x.normal, x.tangent); });
  c.sequence(v.colors, 4, "vertex colour", [&](auto& rgba) { c.field(rgba); });
  c.sequence(v.indices, 4, "index", [&](auto& i) { c.field(i); });
  c.sequence(v.surfaces, kSurfaceBytes, "surface",
             [&](auto& s) { c.fields(s.material, s.first_index, s.index_count); });
}

template <class Codec, class View>
void view_layout(Codec& c, View& v) {
  c.fields(v.origin, v.axis, v.fov_x, v.fov_y, v.time_ms, v.view_id);
}

}  // namespace

void Encoder::str(const std::string& s) {
  u32(static_cast<uint32_t>(s.size()));
  bytes(reinterpret_cast<const uint8_t*>(s.data()), s.size());
}

void Encoder::field(const RenderEntity& v) { entity_layout(*this, v); }
void Encoder::field(const RenderLight& v) { light_layout(*this, v); }
void Encoder::field(const Material& v) { material_layout(*this, v); }
void Encoder::field(const Image& v) { image_layout(*this, v); }
void Encoder::field(const Mesh& v) { mesh_layout(*this, v); }
void Encoder::field(const RenderView& v) { view_layout(*this, v); }

void Encoder::texels(const Image& v) {
  u32(static_cast<uint32_t>(v.rgba.size()));
  bytes(v.rgba.data(), v.rgba.size());
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

void Decoder::check_flags(uint32_t bits, size_t flag_count, const char* what) const {
  const uint32_t known = (1u << flag_count) - 1;
  if (bits & ~known) fail(fmt::format("{} flags 0x{:x} has unknown bits", what, bits));
}

void Decoder::field(BlendClass& v) {
  uint8_t blend = u8();
  if (blend > static_cast<uint8_t>(BlendClass::Sky)) fail(fmt::format("blend class {} unknown", blend));
  v = static_cast<BlendClass>(blend);
}

void Decoder::field(LightKind& v) {
  uint8_t kind = u8();
  if (kind > static_cast<uint8_t>(LightKind::Ambient)) fail(fmt::format("light kind {} unknown", kind));
  v = static_cast<LightKind>(kind);
}

void Decoder::field(RenderEntity& v) { entity_layout(*this, v); }
void Decoder::field(RenderLight& v) { light_layout(*this, v); }
void Decoder::field(Material& v) { material_layout(*this, v); }
void Decoder::field(Image& v) { image_layout(*this, v); }
void Decoder::field(Mesh& v) { mesh_layout(*this, v); }
void Decoder::field(RenderView& v) { view_layout(*this, v); }

void Decoder::texels(Image& v) {
  uint32_t n = count(1, "texel byte");
  if (v.width <= 0 || v.height <= 0 || uint64_t(v.width) * uint64_t(v.height) * 4 != n)
    fail(fmt::format("image '{}' is {}x{} but carries {} bytes of RGBA", v.name, v.width, v.height, n));
  v.rgba.resize(n);
  bytes(v.rgba.data(), n);
}

}  // namespace stream_codec
}  // namespace cohort::scene
