#include "cohort/core/scene_pack.h"

#include <cstring>
#include <fstream>

#include <fmt/format.h>

#include "cohort/core/byte_reader.h"
#include "cohort/core/light_sampling.h"

namespace cohort::core {
namespace {

constexpr char kMagic[8] = {'C', 'O', 'H', 'O', 'R', 'T', 'P', 'K'};

constexpr uint32_t fourcc(const char (&s)[5]) {
  return uint32_t(uint8_t(s[0])) | uint32_t(uint8_t(s[1])) << 8 | uint32_t(uint8_t(s[2])) << 16 |
         uint32_t(uint8_t(s[3])) << 24;
}

uint32_t fnv1a(const uint8_t* data, size_t size) {
  uint32_t h = 2166136261u;
  for (size_t i = 0; i < size; ++i) h = (h ^ data[i]) * 16777619u;
  return h;
}

// Each section: tag, element size, element count, payload, FNV-1a of the payload.
class Writer {
 public:
  explicit Writer(std::vector<uint8_t>& out) : out_(out) {}
  void raw(const void* p, size_t n) {
    auto* b = static_cast<const uint8_t*>(p);
    out_.insert(out_.end(), b, b + n);
  }
  template <class T> void scalar(T v) { raw(&v, sizeof v); }
  template <class T> void section(uint32_t tag, const T* data, size_t count) {
    scalar(tag);
    scalar(uint32_t(sizeof(T)));
    scalar(uint64_t(count));
    size_t start = out_.size();
    raw(data, count * sizeof(T));
    scalar(fnv1a(out_.data() + start, count * sizeof(T)));
  }
  template <class T> void section(uint32_t tag, const std::vector<T>& v) { section(tag, v.data(), v.size()); }

 private:
  std::vector<uint8_t>& out_;
};

class Reader : public ByteReader<Reader> {
 public:
  Reader(std::string file, const std::vector<uint8_t>& bytes)
      : ByteReader(bytes.data(), bytes.size()), file_(std::move(file)) {}
  [[noreturn]] void fail(const std::string& what) const { throw PackError(file_, pos_, what); }
  template <class T> std::vector<T> section(uint32_t expected_tag, const char* name) {
    uint32_t tag = scalar<uint32_t>();
    if (tag != expected_tag) fail(fmt::format("expected section '{}', found tag 0x{:08x}", name, tag));
    uint32_t element_size = scalar<uint32_t>();
    if (element_size != sizeof(T))
      fail(fmt::format("section '{}': element size {} but this build's layout is {} bytes", name, element_size,
                       sizeof(T)));
    uint64_t count = scalar<uint64_t>();
    if (count > left() / sizeof(T))
      fail(fmt::format("section '{}': {} elements do not fit in the {} bytes left", name, count, left()));
    std::vector<T> v(count);
    size_t start = pos_;
    raw(v.data(), count * sizeof(T));
    uint32_t checksum = scalar<uint32_t>();
    if (checksum != fnv1a(data_ + start, count * sizeof(T)))
      fail(fmt::format("section '{}': checksum mismatch (file corrupt)", name));
    return v;
  }

 private:
  std::string file_;
};

std::vector<char> join_names(const std::vector<std::string>& names) {
  std::vector<char> joined;
  for (const auto& n : names) {
    joined.insert(joined.end(), n.begin(), n.end());
    joined.push_back('\0');
  }
  return joined;
}

std::vector<std::string> split_names(const std::vector<char>& joined) {
  std::vector<std::string> names;
  std::string current;
  for (char c : joined) {
    if (c == '\0') {
      names.push_back(current);
      current.clear();
    } else {
      current.push_back(c);
    }
  }
  return names;
}

}  // namespace

PackError::PackError(const std::string& file, uint64_t offset, const std::string& what)
    : std::runtime_error(fmt::format("{}: byte {}: {}", file, offset, what)) {}

void write_scene_pack(const std::filesystem::path& file, const PackedScene& pack) {
  const auto& s = pack.tracer_scene;
  std::vector<uint8_t> bytes;
  Writer w(bytes);
  w.raw(kMagic, sizeof kMagic);
  w.scalar(kScenePackVersion);
  w.section(fourcc("NAME"), pack.map_name.data(), pack.map_name.size());
  w.section(fourcc("VERT"), s.vertices);
  w.section(fourcc("VCOL"), s.vertex_colors);
  w.section(fourcc("TRIS"), s.triangles);
  w.section(fourcc("BNOD"), s.blas_nodes);
  w.section(fourcc("BLAS"), s.blases);
  w.section(fourcc("INST"), s.instances);
  w.section(fourcc("TNOD"), s.tlas_nodes);
  w.section(fourcc("MATL"), s.materials);
  w.section(fourcc("TEXR"), s.textures);
  w.section(fourcc("TEXL"), s.texels);
  w.section(fourcc("LITE"), s.lights);
  w.section(fourcc("CAMR"), &s.camera, 1);
  w.section(fourcc("MBLS"), pack.blas_of_mesh);
  w.section(fourcc("WBLS"), &pack.world_blas, 1);
  w.section(fourcc("INAM"), join_names(pack.instance_names));
  float start[4] = {pack.player_start[0], pack.player_start[1], pack.player_start[2], pack.player_yaw};
  w.section(fourcc("PLYR"), start, 4);

  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  if (!out) throw PackError(file.string(), 0, "cannot open for writing");
  out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
  if (!out) throw PackError(file.string(), 0, "write failed (disk full?)");
}

bool is_scene_pack(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  char magic[sizeof kMagic] = {};
  in.read(magic, sizeof magic);
  return in && std::memcmp(magic, kMagic, sizeof kMagic) == 0;
}

PackedScene read_scene_pack(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw PackError(file.string(), 0, "cannot open");
  std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  Reader r(file.string(), bytes);   // reads bytes in place: they outlive r
  char magic[sizeof kMagic];
  r.raw(magic, sizeof magic);
  if (std::memcmp(magic, kMagic, sizeof kMagic) != 0) r.fail("not a Cohort scene pack (bad magic)");
  uint32_t version = r.scalar<uint32_t>();
  if (version != kScenePackVersion)
    r.fail(fmt::format("pack version {} is not supported (this build reads version {})", version, kScenePackVersion));

  PackedScene pack;
  auto name = r.section<char>(fourcc("NAME"), "map name");
  pack.map_name.assign(name.begin(), name.end());
  auto& s = pack.tracer_scene;
  s.vertices = r.section<KVertex>(fourcc("VERT"), "vertices");
  s.vertex_colors = r.section<KVertexColor>(fourcc("VCOL"), "vertex colours");
  if (s.vertex_colors.size() != s.vertices.size())
    r.fail(fmt::format("{} vertex colours for {} vertices", s.vertex_colors.size(), s.vertices.size()));
  s.triangles = r.section<KTriangle>(fourcc("TRIS"), "triangles");
  s.blas_nodes = r.section<KBvhNode>(fourcc("BNOD"), "BLAS nodes");
  s.blases = r.section<KBlas>(fourcc("BLAS"), "BLASes");
  s.instances = r.section<KInstance>(fourcc("INST"), "instances");
  s.tlas_nodes = r.section<KBvhNode>(fourcc("TNOD"), "TLAS nodes");
  s.materials = r.section<KMaterial>(fourcc("MATL"), "materials");
  s.textures = r.section<KTexture>(fourcc("TEXR"), "textures");
  s.texels = r.section<uint32_t>(fourcc("TEXL"), "texels");
  s.lights = r.section<KLight>(fourcc("LITE"), "lights");
  auto camera = r.section<KCamera>(fourcc("CAMR"), "camera");
  if (camera.size() != 1) r.fail("camera section must hold exactly one camera");
  s.camera = camera[0];
  pack.blas_of_mesh = r.section<uint32_t>(fourcc("MBLS"), "mesh to BLAS map");
  auto world = r.section<uint32_t>(fourcc("WBLS"), "world BLAS");
  if (world.size() != 1) r.fail("world BLAS section must hold exactly one index");
  pack.world_blas = world[0];
  pack.instance_names = split_names(r.section<char>(fourcc("INAM"), "instance names"));
  auto start = r.section<float>(fourcc("PLYR"), "player start");
  if (start.size() != 4) r.fail("player start section must hold 4 floats");
  std::memcpy(pack.player_start, start.data(), 3 * sizeof(float));
  pack.player_yaw = start[3];
  if (!r.at_end()) r.fail("trailing bytes after the last section");

  // Cross-references must be in range so that no tracer reads out of bounds.
  for (const KBlas& b : s.blases)
    if (uint64_t(b.node_offset) + b.node_count > s.blas_nodes.size() ||
        uint64_t(b.tri_offset) + b.tri_count > s.triangles.size())
      throw PackError(file.string(), 0, "a BLAS points outside the node or triangle arrays");
  for (const KInstance& i : s.instances)
    if (i.blas >= s.blases.size()) throw PackError(file.string(), 0, "an instance names a BLAS that does not exist");
  for (const KTriangle& t : s.triangles)
    if (t.v0 >= s.vertices.size() || t.v1 >= s.vertices.size() || t.v2 >= s.vertices.size() ||
        (t.material != K_NONE && t.material >= s.materials.size()))
      throw PackError(file.string(), 0, "a triangle names a vertex or material that does not exist");
  for (const KTexture& t : s.textures)
    if (uint64_t(t.offset) + uint64_t(t.width) * t.height > s.texels.size())
      throw PackError(file.string(), 0, "a texture points outside the texel array");
  for (const KMaterial& m : s.materials)
    if (m.env_tex1 != 0u && uint64_t(m.env_tex1) - 1u + 6u > s.textures.size())
      throw PackError(file.string(), 0, "a material's environment cube map points outside the texture table");
  // The light tree and the emissive triangles are derived from the arrays above, so packs do not carry them.
  rebuild_light_sampling(s);
  return pack;
}

}  // namespace cohort::core
