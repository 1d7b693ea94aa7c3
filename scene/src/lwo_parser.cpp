// LightWave object reader after the engine's Model_lwo.cpp (lwGetObject, lwGetObject5) and the
// conversion in Model.cpp (ConvertLWOToModelSurfaces): see doom3-content.md section 4.
#include <cmath>
#include <cstring>
#include <map>

#include "cohort/scene/model_file.h"
#include "model_builder.h"

namespace cohort::scene {

namespace {

constexpr float kDefaultSurfaceColor = 200.0f / 255.0f;   // lwDefaultSurface COLR 0.78431
constexpr float kLwobSmoothingAngle = 1.56207f;           // LWOB FLAG bit 2

uint32_t id4(const char (&s)[5]) {
  return (uint32_t(uint8_t(s[0])) << 24) | (uint32_t(uint8_t(s[1])) << 16) | (uint32_t(uint8_t(s[2])) << 8) |
         uint32_t(uint8_t(s[3]));
}

std::string id_text(uint32_t id) {
  std::string s;
  for (int shift = 24; shift >= 0; shift -= 8) {
    char c = static_cast<char>((id >> shift) & 0xff);
    s += (c >= 32 && c < 127) ? c : '?';
  }
  return s;
}

// Big-endian reads within [pos, end) of the file; running past `end` is a ParseError naming the offset.
class Reader {
 public:
  Reader(std::string_view bytes, const std::string& file) : bytes_(bytes), file_(file), end_(bytes.size()) {}

  [[noreturn]] void fail(const std::string& message) const { throw ParseError::at_byte(file_, pos_, message); }
  void need(size_t n, const char* what) const {
    if (n > end_ - pos_) fail(std::string("truncated ") + what);
  }
  uint8_t u1(const char* what) {
    need(1, what);
    return uint8_t(bytes_[pos_++]);
  }
  uint16_t u2(const char* what) {
    need(2, what);
    uint16_t v = uint16_t((uint8_t(bytes_[pos_]) << 8) | uint8_t(bytes_[pos_ + 1]));
    pos_ += 2;
    return v;
  }
  uint32_t u4(const char* what) {
    need(4, what);
    uint32_t v = 0;
    for (int i = 0; i < 4; ++i) v = (v << 8) | uint8_t(bytes_[pos_ + i]);
    pos_ += 4;
    return v;
  }
  float f4(const char* what) {
    uint32_t bits = u4(what);
    float f;
    std::memcpy(&f, &bits, 4);
    if (!std::isfinite(f)) fail(std::string("not a finite number in ") + what);
    if (std::fpclassify(f) == FP_SUBNORMAL) f = 0.0f;   // getF4 reads denormals as 0
    return f;
  }
  // Variable-length index: 2 bytes, or 4 with a leading 0xFF (24-bit value).
  uint32_t vx(const char* what) {
    need(2, what);
    if (uint8_t(bytes_[pos_]) == 0xff) {
      need(4, what);
      uint32_t v = (uint32_t(uint8_t(bytes_[pos_ + 1])) << 16) | (uint32_t(uint8_t(bytes_[pos_ + 2])) << 8) |
                   uint8_t(bytes_[pos_ + 3]);
      pos_ += 4;
      return v;
    }
    return u2(what);
  }
  // NUL-terminated string padded to an even length.
  std::string s0(const char* what) {
    size_t start = pos_;
    while (pos_ < end_ && bytes_[pos_] != '\0') ++pos_;
    if (pos_ >= end_) {
      pos_ = start;
      fail(std::string("unterminated string in ") + what);
    }
    std::string s(bytes_.substr(start, pos_ - start));
    ++pos_;
    if ((pos_ - start) % 2 != 0 && pos_ < end_) ++pos_;
    return s;
  }
  size_t pos() const { return pos_; }
  size_t end() const { return end_; }
  void seek(size_t pos) { pos_ = pos; }
  // Limits reads to a chunk; returns the previous limit.
  size_t limit(size_t end) {
    size_t old = end_;
    end_ = end;
    return old;
  }
  bool done() const { return pos_ >= end_; }
  const std::string& file() const { return file_; }

 private:
  std::string_view bytes_;
  const std::string& file_;
  size_t pos_ = 0, end_;
};

struct LwSurface {
  std::string name;
  glm::vec3 color{kDefaultSurfaceColor};
  float smoothing = 0.0f;   // max smoothing angle, radians; <= 0 faceted
};

struct LwPolygon {
  std::vector<uint32_t> points;
  int surface = -1;          // tag (LWO2) or surface (LWOB) index
  int smoothing_group = 0;
  size_t offset = 0;         // where it was read, for messages
};

struct LwVmapValue {
  uint32_t point = 0;
  int polygon = -1;          // -1: per point (VMAP); otherwise VMAD's polygon
  float v[4] = {0, 0, 0, 0};
};

struct LwLayer {
  std::vector<glm::vec3> points;   // LightWave axes
  std::vector<LwPolygon> polygons;
  std::vector<LwVmapValue> uvs, rgbas;
  bool has_uv_map = false;
};

class LwoReader {
 public:
  LwoReader(std::string_view bytes, const std::string& file) : in_(bytes, file) {}

  ModelFile read() {
    if (in_.u4("FORM header") != id4("FORM")) in_.fail("not an IFF file (no FORM header)");
    uint32_t form_size = in_.u4("FORM size");
    if (form_size > in_.end() - in_.pos()) in_.fail("FORM size " + std::to_string(form_size) + " runs past the file end");
    in_.limit(in_.pos() + form_size);
    uint32_t type = in_.u4("form type");
    if (type == id4("LWO2")) {
      lwo2_ = true;
    } else if (type != id4("LWOB")) {
      in_.fail("FORM type " + id_text(type) + " is neither LWO2 nor LWOB");
    }
    while (!in_.done()) read_chunk();
    return convert();
  }

 private:
  void read_chunk() {
    const size_t at = in_.pos();
    uint32_t id = in_.u4("chunk id");
    uint32_t size = in_.u4("chunk size");
    if (size > in_.end() - in_.pos()) {
      in_.seek(at);
      in_.fail("chunk " + id_text(id) + " size " + std::to_string(size) + " runs past the FORM end");
    }
    const size_t chunk_end = in_.pos() + size;
    size_t outer = in_.limit(chunk_end);
    // Only the first layer is converted ("we only ever use the first layer").
    bool geometry = layers_seen_ <= 1;
    if (id == id4("LAYR")) {
      ++layers_seen_;
    } else if (id == id4("PNTS") && geometry) {
      if (size % 12 != 0) in_.fail("PNTS size " + std::to_string(size) + " is not a multiple of 12");
      for (uint32_t i = 0; i < size / 12; ++i) {
        glm::vec3 p;
        for (int k = 0; k < 3; ++k) p[k] = in_.f4("PNTS");
        layer_.points.push_back(p);
      }
    } else if (id == id4("POLS") && geometry) {
      lwo2_ ? read_pols2() : read_pols_lwob();
    } else if (id == id4("TAGS") && lwo2_) {
      while (!in_.done()) tags_.push_back(in_.s0("TAGS"));
    } else if (id == id4("SRFS") && !lwo2_) {
      while (!in_.done()) tags_.push_back(in_.s0("SRFS"));
    } else if (id == id4("PTAG") && geometry && lwo2_) {
      read_ptag();
    } else if ((id == id4("VMAP") || id == id4("VMAD")) && geometry && lwo2_) {
      read_vmap(id == id4("VMAD"));
    } else if (id == id4("SURF")) {
      lwo2_ ? read_surf2() : read_surf_lwob();
    }
    in_.limit(outer);
    in_.seek(chunk_end + (size % 2));   // odd sizes are padded
    if (in_.pos() > in_.end()) in_.seek(in_.end());
  }

  // A VX index below `count`; an error at the index's offset names what it indexes.
  uint32_t checked_index(const char* what, const char* kind, size_t count) {
    size_t at = in_.pos();
    uint32_t p = in_.vx(what);
    if (p >= count) {
      in_.seek(at);
      in_.fail(std::string(what) + ": " + kind + " " + std::to_string(p) + " out of range (" + std::to_string(count) +
               " " + kind + "s)");
    }
    return p;
  }
  uint32_t point_index(const char* what) { return checked_index(what, "point", layer_.points.size()); }
  uint32_t polygon_index(const char* what) { return checked_index(what, "polygon", layer_.polygons.size()); }

  void read_pols2() {
    in_.u4("POLS type");   // FACE, PTCH, ...: the converter does not check it
    while (!in_.done()) {
      LwPolygon polygon;
      polygon.offset = in_.pos();
      uint16_t count = in_.u2("POLS vertex count") & 0x3ff;
      polygon.points.reserve(count);
      for (uint16_t i = 0; i < count; ++i) polygon.points.push_back(point_index("POLS"));
      layer_.polygons.push_back(std::move(polygon));
    }
  }

  void read_pols_lwob() {
    while (!in_.done()) {
      LwPolygon polygon;
      polygon.offset = in_.pos();
      uint16_t count = in_.u2("POLS vertex count");
      for (uint16_t i = 0; i < count; ++i) {
        size_t at = in_.pos();
        uint16_t p = in_.u2("POLS");
        if (p >= layer_.points.size()) {
          in_.seek(at);
          in_.fail("POLS: point " + std::to_string(p) + " out of range");
        }
        polygon.points.push_back(p);
      }
      int16_t surface = static_cast<int16_t>(in_.u2("POLS surface"));
      if (surface < 0) {
        in_.u2("POLS detail count");   // detail polygons follow as ordinary ones
        surface = static_cast<int16_t>(-surface);
      }
      polygon.surface = surface - 1;
      layer_.polygons.push_back(std::move(polygon));
    }
  }

  void read_ptag() {
    uint32_t type = in_.u4("PTAG type");
    bool surf = type == id4("SURF"), smgp = type == id4("SMGP");
    if (!surf && !smgp) return;
    while (!in_.done()) {
      uint32_t polygon = polygon_index("PTAG");
      uint32_t tag = in_.vx("PTAG tag");
      if (surf) layer_.polygons[polygon].surface = static_cast<int>(std::min<uint32_t>(tag, 0x7fffffff));
      else layer_.polygons[polygon].smoothing_group = static_cast<int>(std::min<uint32_t>(tag, 0x7fffffff));
    }
  }

  void read_vmap(bool per_polygon) {
    uint32_t type = in_.u4("VMAP type");
    uint16_t dimension = in_.u2("VMAP dimension");
    in_.s0("VMAP name");
    // Colour maps: RGBA (the engine's), and RGB read as opaque RGBA (LightWave writes either).
    bool uv = type == id4("TXUV") && dimension == 2;
    bool rgba = (type == id4("RGBA") && dimension == 4) || (type == id4("RGB ") && dimension == 3);
    if (!uv && !rgba) return;
    if (uv) layer_.has_uv_map = true;
    while (!in_.done()) {
      LwVmapValue value;
      value.point = point_index(per_polygon ? "VMAD" : "VMAP");
      if (per_polygon) value.polygon = static_cast<int>(polygon_index("VMAD"));
      value.v[3] = 1.0f;
      for (int k = 0; k < dimension; ++k) value.v[k] = in_.f4("VMAP value");
      (uv ? layer_.uvs : layer_.rgbas).push_back(value);
    }
  }

  void read_surf2() {
    std::string name = in_.s0("SURF name");
    in_.s0("SURF source");
    LwSurface surface;
    surface.name = name;
    read_surf_subchunks([&](uint32_t id) {
      if (id == id4("COLR")) {
        for (int k = 0; k < 3; ++k) surface.color[k] = in_.f4("COLR");
      } else if (id == id4("SMAN")) {
        surface.smoothing = in_.f4("SMAN");
      }
    });
    add_surface(surface);
  }

  void read_surf_lwob() {
    LwSurface surface;
    surface.name = in_.s0("SURF name");
    read_surf_subchunks([&](uint32_t id) {
      if (id == id4("COLR")) {
        for (int k = 0; k < 3; ++k) surface.color[k] = in_.u1("COLR") / 255.0f;
      } else if (id == id4("FLAG")) {
        if (in_.u2("FLAG") & 4) surface.smoothing = kLwobSmoothingAngle;
      } else if (id == id4("SMAN")) {
        surface.smoothing = in_.f4("SMAN");
      }
    });
    add_surface(surface);
  }

  // The subchunks of a SURF chunk, each read by `read(id)` within its bounds (what it does not read is
  // skipped, with the pad byte of an odd size).
  template <class Read> void read_surf_subchunks(Read&& read) {
    while (!in_.done()) {
      uint32_t id = in_.u4("SURF subchunk id");
      uint16_t size = in_.u2("SURF subchunk size");
      in_.need(size, "SURF subchunk");
      size_t sub_end = in_.pos() + size;
      size_t outer = in_.limit(sub_end);
      read(id);
      in_.limit(outer);
      in_.seek(std::min(in_.end(), sub_end + (size % 2)));
    }
  }

  void add_surface(const LwSurface& surface) {
    for (const LwSurface& s : surfaces_)
      if (s.name == surface.name) return;   // the first definition is used
    surfaces_.push_back(surface);
  }

  ModelFile convert() {
    ModelFile out;
    const std::string& file = in_.file();
    if (layer_.polygons.empty()) throw ParseError::at_byte(file, in_.pos(), "no polygons in the first layer");
    // Per polygon: its surface (tag -> TAGS name -> SURF, a default surface when none has that name).
    std::vector<const LwSurface*> polygon_surface(layer_.polygons.size());
    std::vector<LwSurface> resolved;
    resolved.reserve(tags_.size() + 1);
    std::map<std::string, size_t> by_name;
    for (size_t i = 0; i < layer_.polygons.size(); ++i) {
      const LwPolygon& polygon = layer_.polygons[i];
      if (polygon.surface < 0 || static_cast<size_t>(polygon.surface) >= tags_.size())
        throw ParseError::at_byte(file, polygon.offset,
                                  "polygon " + std::to_string(i) + " has no surface tag in range (" +
                                      std::to_string(tags_.size()) + " tags)");
      const std::string& name = tags_[static_cast<size_t>(polygon.surface)];
      auto found = by_name.find(name);
      if (found == by_name.end()) {
        LwSurface s{name};
        for (const LwSurface& defined : surfaces_)
          if (defined.name == name) s = defined;
        found = by_name.emplace(name, resolved.size()).first;
        resolved.push_back(s);
      }
      polygon_surface[i] = &resolved[found->second];
    }

    // Polygon normals (LightWave axes): (p1 - p0) x (p_last - p0).
    std::vector<glm::vec3> normals(layer_.polygons.size(), glm::vec3(0.0f));
    std::vector<std::vector<uint32_t>> polygons_of_point(layer_.points.size());
    for (size_t i = 0; i < layer_.polygons.size(); ++i) {
      const auto& pts = layer_.polygons[i].points;
      for (uint32_t p : pts) polygons_of_point[p].push_back(static_cast<uint32_t>(i));
      if (pts.size() < 3) continue;
      glm::vec3 n = glm::cross(layer_.points[pts[1]] - layer_.points[pts[0]],
                               layer_.points[pts.back()] - layer_.points[pts[0]]);
      float length = glm::length(n);
      normals[i] = length > 0.0f ? n / length : glm::vec3(0.0f);
    }

    std::vector<glm::vec2> point_uv(layer_.points.size(), glm::vec2(0.0f));
    std::vector<bool> point_has_uv(layer_.points.size(), false);
    std::map<std::pair<uint32_t, int>, glm::vec2> corner_uv;
    for (const LwVmapValue& v : layer_.uvs) {
      if (v.polygon < 0) {
        if (!point_has_uv[v.point]) point_uv[v.point] = {v.v[0], v.v[1]};
        point_has_uv[v.point] = true;
      } else {
        corner_uv[{v.point, v.polygon}] = {v.v[0], v.v[1]};
      }
    }
    std::vector<glm::vec4> point_rgba(layer_.points.size(), glm::vec4(1.0f));
    std::vector<bool> point_has_rgba(layer_.points.size(), false);
    std::map<std::pair<uint32_t, int>, glm::vec4> corner_rgba;
    for (const LwVmapValue& v : layer_.rgbas) {
      glm::vec4 c(v.v[0], v.v[1], v.v[2], v.v[3]);
      if (v.polygon < 0) {
        point_rgba[v.point] = c;
        point_has_rgba[v.point] = true;
      } else corner_rgba[{v.point, v.polygon}] = c;
    }
    if (!layer_.has_uv_map)
      out.warnings.push_back(file + ": no TXUV vertex map; every texture coordinate is (0, 0)");

    auto to_idtech = [](glm::vec3 v) { return glm::vec3(v.x, v.z, v.y); };
    auto to_byte_color = [](glm::vec4 c) { return glm::round(glm::clamp(c, 0.0f, 1.0f) * 255.0f) / 255.0f; };
    ModelBuilder builder(file);
    builder.begin_group();
    size_t skipped = 0;
    for (size_t i = 0; i < layer_.polygons.size(); ++i) {
      const LwPolygon& polygon = layer_.polygons[i];
      if (polygon.points.size() != 3) {
        ++skipped;
        continue;
      }
      const LwSurface& surface = *polygon_surface[i];
      const float cos_limit = std::cos(surface.smoothing);
      ModelCorner corners[3];
      for (int k = 0; k < 3; ++k) {
        uint32_t p = polygon.points[static_cast<size_t>(k)];
        ModelCorner& c = corners[k];
        c.position = to_idtech(layer_.points[p]);
        glm::vec2 uv = point_uv[p];
        auto cu = corner_uv.find({p, static_cast<int>(i)});
        if (cu != corner_uv.end()) uv = cu->second;
        c.st = {uv.x, 1.0f - uv.y};
        glm::vec3 n = normals[i];
        if (surface.smoothing > 0.0f) {
          for (uint32_t other : polygons_of_point[p]) {
            if (other == i || layer_.polygons[other].smoothing_group != polygon.smoothing_group) continue;
            if (glm::dot(normals[i], normals[other]) < cos_limit) continue;
            n += normals[other];
          }
          float length = glm::length(n);
          n = length > 0.0f ? n / length : normals[i];
        }
        c.normal = glm::length(n) > 0.0f ? to_idtech(n) : glm::vec3(0.0f, 0.0f, 1.0f);
        c.has_normal = true;
        glm::vec4 color(surface.color, 1.0f);
        if (point_has_rgba[p]) color = point_rgba[p];
        auto cc = corner_rgba.find({p, static_cast<int>(i)});
        if (cc != corner_rgba.end()) color = cc->second;
        c.color = to_byte_color(color);
      }
      builder.add_triangle(canonical_decl_name(surface.name), corners);
    }
    if (skipped > 0)
      out.warnings.push_back(file + ": " + std::to_string(skipped) + " polygons are not triangles and were skipped");
    if (builder.triangle_count() == 0) throw ParseError::at_byte(file, 0, "no triangles in the first layer");
    ModelFile built = builder.finish(true);
    built.warnings = std::move(out.warnings);
    return built;
  }

  Reader in_;
  bool lwo2_ = false;
  int layers_seen_ = 0;
  LwLayer layer_;
  std::vector<std::string> tags_;
  std::vector<LwSurface> surfaces_;
};

}  // namespace

ModelFile parse_lwo(std::string_view bytes, const std::string& file_name) { return LwoReader(bytes, file_name).read(); }

}  // namespace cohort::scene
