#include "cohort/tracers/mpi_wire.h"

#include <algorithm>
#include <cstring>
#include <type_traits>

#include <fmt/format.h>

#include "cohort/core/byte_reader.h"

namespace cohort::tracers::wire {
namespace {

// Record tags of an incremental commit, in the order they are written: counts before elements, since
// a count drops the writes past it.
enum class Record : uint32_t {
  end = 0,
  instance_count, light_count, material_count, texture_count,
  instance, light, material, texture,
  tlas, light_tree, emissive, blas, texels, skin, skin_joints, camera,
};

class Writer {
 public:
  void raw(const void* p, size_t n) {
    auto* b = static_cast<const uint8_t*>(p);
    out.insert(out.end(), b, b + n);
  }
  template <class T> void scalar(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    raw(&v, sizeof v);
  }
  template <class T> void array(const T* data, size_t count) {
    static_assert(std::is_trivially_copyable_v<T>);
    scalar(uint64_t(count));
    raw(data, count * sizeof(T));
  }
  template <class T> void array(const std::vector<T>& v) { array(v.data(), v.size()); }
  void text(const std::string& s) { array(s.data(), s.size()); }
  void tag(Record r) { scalar(uint32_t(r)); }

  std::vector<uint8_t> out;
};

class Reader : public core::ByteReader<Reader> {
 public:
  Reader(const std::vector<uint8_t>& bytes, const char* what) : Reader(bytes.data(), bytes.size(), what) {}
  Reader(const uint8_t* data, size_t size, const char* what) : ByteReader(data, size), what_(what) {}
  [[noreturn]] void fail(const std::string& why) const {
    throw WireError(fmt::format("{} message: byte {} of {}: {}", what_, pos_, size_, why));
  }
  template <class T> std::vector<T> array(const char* name) {
    const uint64_t count = scalar<uint64_t>();
    if (count > left() / sizeof(T))
      fail(fmt::format("{}: {} elements of {} bytes do not fit in the {} bytes left", name, count, sizeof(T),
                       left()));
    std::vector<T> v(count);
    raw(v.data(), count * sizeof(T));
    return v;
  }
  std::string text(const char* name) {
    auto chars = array<char>(name);
    return std::string(chars.begin(), chars.end());
  }
  void expect_end() const {
    if (!at_end()) fail(fmt::format("{} bytes left over after the last field", left()));
  }
  // The next n bytes where they lie (no copy); valid while the message is.
  const uint8_t* view(uint64_t n, const char* name) {
    if (n > left()) fail(fmt::format("{}: {} bytes do not fit in the {} bytes left", name, n, left()));
    const uint8_t* p = data_ + pos_;
    pos_ += n;
    return p;
  }

 private:
  const char* what_;
};

core::BandFormat band_format_of(uint32_t value, Reader& r) {
  if (value == uint32_t(core::BandFormat::rgb16f)) return core::BandFormat::rgb16f;
  if (value == uint32_t(core::BandFormat::rgba32f)) return core::BandFormat::rgba32f;
  if (value == uint32_t(core::BandFormat::rgb9e5)) return core::BandFormat::rgb9e5;
  r.fail(fmt::format("unknown band format {}", value));
}

// Every array of the scene, in one order for the encoder, the decoder and the fingerprint.
template <class Visit> void visit_scene_arrays(const commit::TracerScene& s, Visit&& visit) {
  visit(s.vertices); visit(s.vertex_colors); visit(s.triangles); visit(s.blas_nodes); visit(s.blases); visit(s.instances);
  visit(s.tlas_nodes); visit(s.materials); visit(s.textures); visit(s.texels); visit(s.lights);
  visit(s.light_nodes); visit(s.emissive_triangles); visit(s.skins); visit(s.skin_vertices);
  visit(s.skin_weights); visit(s.skin_triangles); visit(s.skin_adjacency); visit(s.joints); visit(s.skin_faces);
}

void read_scene_arrays(Reader& r, commit::TracerScene& s) {
  s.vertices = r.array<KVertex>("vertices");
  s.vertex_colors = r.array<KVertexColor>("vertex colours");
  s.triangles = r.array<KTriangle>("triangles");
  s.blas_nodes = r.array<KBvhNode>("BLAS nodes");
  s.blases = r.array<KBlas>("BLASes");
  s.instances = r.array<KInstance>("instances");
  s.tlas_nodes = r.array<KBvhNode>("TLAS nodes");
  s.materials = r.array<KMaterial>("materials");
  s.textures = r.array<KTexture>("textures");
  s.texels = r.array<uint32_t>("texels");
  s.lights = r.array<KLight>("lights");
  s.light_nodes = r.array<KLightNode>("light tree");
  s.emissive_triangles = r.array<KEmissiveTriangle>("emissive triangles");
  s.skins = r.array<KSkin>("skins");
  s.skin_vertices = r.array<KSkinVertex>("skin vertices");
  s.skin_weights = r.array<KSkinWeight>("skin weights");
  s.skin_triangles = r.array<KSkinTriangle>("skin triangles");
  s.skin_adjacency = r.array<uint32_t>("skin adjacency");
  s.joints = r.array<KJoint>("joints");
  s.skin_faces = r.array<KSkinFace>("skin faces");
}

// A whole scene must be self-consistent before any tracer reads it: BLASes inside the pools,
// instances naming BLASes that exist.
void check_scene(const commit::TracerScene& s, Reader& r) {
  for (const KBlas& b : s.blases)
    if (uint64_t(b.node_offset) + b.node_count > s.blas_nodes.size() ||
        uint64_t(b.tri_offset) + b.tri_count > s.triangles.size())
      r.fail("a BLAS points outside the node or triangle arrays");
  for (const KInstance& i : s.instances)
    if (i.blas >= s.blases.size()) r.fail(fmt::format("an instance names BLAS {} of {}", i.blas, s.blases.size()));
}

}  // namespace

const char* to_string(Kind kind) {
  switch (kind) {
    case Kind::hello: return "hello";
    case Kind::load_failed: return "load_failed";
    case Kind::welcome: return "welcome";
    case Kind::refuse: return "refuse";
    case Kind::commit: return "commit";
    case Kind::full_local: return "full_local";
    case Kind::band_job: return "band_job";
    case Kind::band_rows: return "band_rows";
    case Kind::band_failed: return "band_failed";
    case Kind::shutdown: return "shutdown";
    case Kind::join: return "join";
    case Kind::warm: return "warm";
    case Kind::ready: return "ready";
  }
  return "unknown";
}

std::vector<uint8_t> frame_message(Kind kind, uint64_t sequence, const std::vector<uint8_t>& payload) {
  Header h;
  h.kind = uint16_t(kind);
  h.sequence = sequence;
  h.payload_bytes = payload.size();
  std::vector<uint8_t> out(sizeof h + payload.size());
  std::memcpy(out.data(), &h, sizeof h);
  if (!payload.empty()) std::memcpy(out.data() + sizeof h, payload.data(), payload.size());
  return out;
}

Header parse_header(const uint8_t* bytes, size_t size) {
  Header h;
  if (size < sizeof h)
    throw WireError(fmt::format("message of {} bytes is shorter than the {}-byte header", size, sizeof h));
  std::memcpy(&h, bytes, sizeof h);
  if (h.magic != kMagic) throw WireError(fmt::format("bad magic 0x{:08x} (not a Cohort message)", h.magic));
  if (h.protocol != kProtocolVersion)
    throw WireError(fmt::format("protocol version {} (this build speaks {})", h.protocol, kProtocolVersion));
  if (h.kind < uint16_t(Kind::hello) || h.kind > uint16_t(Kind::ready))
    throw WireError(fmt::format("unknown message kind {}", h.kind));
  if (h.payload_bytes != size - sizeof h)
    throw WireError(fmt::format("{} header announces {} payload bytes but {} arrived", to_string(Kind(h.kind)),
                                h.payload_bytes, size - sizeof h));
  return h;
}

Message parse_message(const uint8_t* bytes, size_t size) {
  const Header h = parse_header(bytes, size);
  Message m;
  m.kind = Kind(h.kind);
  m.sequence = h.sequence;
  m.payload.assign(bytes + sizeof h, bytes + size);
  return m;
}

std::vector<uint8_t> encode_hello(const Hello& hello) {
  Writer w;
  w.text(hello.cohort_version);
  w.scalar(hello.protocol);
  w.text(hello.host);
  w.text(hello.tracers);
  w.scalar(hello.scene_fingerprint);
  w.text(hello.scene_name);
  return std::move(w.out);
}

Hello decode_hello(const std::vector<uint8_t>& payload) {
  Reader r(payload, "hello");
  Hello h;
  h.cohort_version = r.text("version");
  h.protocol = r.scalar<uint32_t>();
  h.host = r.text("host");
  h.tracers = r.text("tracers");
  h.scene_fingerprint = r.scalar<uint64_t>();
  h.scene_name = r.text("scene name");
  r.expect_end();
  return h;
}

std::vector<uint8_t> encode_join(uint32_t slot) {
  Writer w;
  w.scalar(slot);
  return std::move(w.out);
}

uint32_t decode_join(const std::vector<uint8_t>& payload) {
  Reader r(payload, "join");
  const uint32_t slot = r.scalar<uint32_t>();
  r.expect_end();
  return slot;
}

std::string version_mismatch(const Hello& hello, int slot) {
  const std::string mine = cohort_version();
  if (hello.cohort_version == mine && hello.protocol == kProtocolVersion) return {};
  return fmt::format("version mismatch: rank 0 runs Cohort {} (protocol {}), rank {} on {} runs Cohort {} (protocol {}); "
                     "run the same build on every rank", mine, kProtocolVersion, slot, hello.host, hello.cohort_version,
                     hello.protocol);
}

std::vector<uint8_t> encode_text(const std::string& text) {
  Writer w;
  w.text(text);
  return std::move(w.out);
}

std::string decode_text(const std::vector<uint8_t>& payload) {
  Reader r(payload, "text");
  std::string text = r.text("text");
  r.expect_end();
  return text;
}

namespace {

// The incremental records of a buffer (a full resync may carry some on top of its scene: records
// folded in after it, applied after it).
void write_records(Writer& w, const commit::CommitBuffer& c) {
  auto count = [&](Record tag, const std::optional<uint32_t>& n) {
    if (!n) return;
    w.tag(tag);
    w.scalar(*n);
  };
  count(Record::instance_count, c.instance_count());
  count(Record::light_count, c.light_count());
  count(Record::material_count, c.material_count());
  count(Record::texture_count, c.texture_count());
  auto elements = [&](Record tag, const auto& map) {
    for (const auto& [index, value] : map) {
      w.tag(tag);
      w.scalar(index);
      w.scalar(value);
    }
  };
  elements(Record::instance, c.instances());
  elements(Record::light, c.lights());
  elements(Record::material, c.materials());
  elements(Record::texture, c.textures());
  if (c.tlas()) { w.tag(Record::tlas); w.array(*c.tlas()); }
  if (c.light_tree()) { w.tag(Record::light_tree); w.array(*c.light_tree()); }
  if (c.emissive_triangles()) { w.tag(Record::emissive); w.array(*c.emissive_triangles()); }
  for (const commit::BlasUpload& b : c.blas_uploads()) {
    w.tag(Record::blas);
    w.scalar(b.blas_index); w.scalar(b.blas);
    w.scalar(b.vertex_offset); w.array(b.vertices); w.array(b.vertex_colors);
    w.scalar(b.triangle_offset); w.array(b.triangles);
    w.scalar(b.node_offset); w.array(b.nodes);
  }
  for (const commit::TexelUpload& t : c.texel_uploads()) {
    w.tag(Record::texels);
    w.scalar(t.offset); w.array(t.texels);
  }
  for (const commit::SkinUpload& s : c.skin_uploads()) {
    w.tag(Record::skin);
    w.scalar(s.skin_index); w.scalar(s.skin);
    w.scalar(s.weight_offset); w.scalar(s.adjacency_offset);
    w.array(s.vertices); w.array(s.weights); w.array(s.triangles); w.array(s.adjacency);
  }
  for (const auto& [skin, joints] : c.skin_joints()) {
    w.tag(Record::skin_joints);
    w.scalar(skin); w.array(joints);
  }
  if (c.camera()) { w.tag(Record::camera); w.scalar(*c.camera()); }
  w.tag(Record::end);
}

// Reads records up to the end tag into `c` (which may be a full resync already) and expects the
// message to end there.
void read_records(Reader& r, commit::CommitBuffer& c) {
  for (;;) {
    const uint32_t tag = r.scalar<uint32_t>();
    switch (Record(tag)) {
      case Record::end: r.expect_end(); return;
      case Record::instance_count: c.set_instance_count(r.scalar<uint32_t>()); break;
      case Record::light_count: c.set_light_count(r.scalar<uint32_t>()); break;
      case Record::material_count: c.set_material_count(r.scalar<uint32_t>()); break;
      case Record::texture_count: c.set_texture_count(r.scalar<uint32_t>()); break;
      case Record::instance: { auto i = r.scalar<uint32_t>(); c.set_instance(i, r.scalar<KInstance>()); break; }
      case Record::light: { auto i = r.scalar<uint32_t>(); c.set_light(i, r.scalar<KLight>()); break; }
      case Record::material: { auto i = r.scalar<uint32_t>(); c.set_material(i, r.scalar<KMaterial>()); break; }
      case Record::texture: { auto i = r.scalar<uint32_t>(); c.set_texture(i, r.scalar<KTexture>()); break; }
      case Record::tlas: c.set_tlas(r.array<KBvhNode>("TLAS")); break;
      case Record::light_tree: c.set_light_tree(r.array<KLightNode>("light tree")); break;
      case Record::emissive: c.set_emissive_triangles(r.array<KEmissiveTriangle>("emissive triangles")); break;
      case Record::blas: {
        commit::BlasUpload b;
        b.blas_index = r.scalar<uint32_t>(); b.blas = r.scalar<KBlas>();
        b.vertex_offset = r.scalar<uint32_t>(); b.vertices = r.array<KVertex>("BLAS vertices");
        b.vertex_colors = r.array<KVertexColor>("BLAS vertex colours");
        b.triangle_offset = r.scalar<uint32_t>(); b.triangles = r.array<KTriangle>("BLAS triangles");
        b.node_offset = r.scalar<uint32_t>(); b.nodes = r.array<KBvhNode>("BLAS nodes");
        c.add_blas(std::move(b));
        break;
      }
      case Record::texels: {
        commit::TexelUpload t;
        t.offset = r.scalar<uint32_t>(); t.texels = r.array<uint32_t>("texels");
        c.add_texels(std::move(t));
        break;
      }
      case Record::skin: {
        commit::SkinUpload s;
        s.skin_index = r.scalar<uint32_t>(); s.skin = r.scalar<KSkin>();
        s.weight_offset = r.scalar<uint32_t>(); s.adjacency_offset = r.scalar<uint32_t>();
        s.vertices = r.array<KSkinVertex>("skin vertices"); s.weights = r.array<KSkinWeight>("skin weights");
        s.triangles = r.array<KSkinTriangle>("skin triangles"); s.adjacency = r.array<uint32_t>("skin adjacency");
        c.add_skin(std::move(s));
        break;
      }
      case Record::skin_joints: {
        auto skin = r.scalar<uint32_t>();
        c.set_skin_joints(skin, r.array<KJoint>("joints"));
        break;
      }
      case Record::camera: c.set_camera(r.scalar<KCamera>()); break;
      default: r.fail(fmt::format("unknown record tag {}", tag));
    }
  }
}

}  // namespace

std::vector<uint8_t> encode_commit(const commit::CommitBuffer& c) {
  Writer w;
  w.scalar(uint8_t(c.is_full_resync() ? 1 : 0));
  w.scalar(uint64_t(c.frame()));
  if (c.is_full_resync()) {
    const commit::TracerScene& s = *c.full_scene();
    visit_scene_arrays(s, [&](const auto& v) { w.array(v); });
    w.scalar(s.camera);
    w.scalar(s.version);
  }
  write_records(w, c);
  return std::move(w.out);
}

commit::CommitBuffer decode_commit(const std::vector<uint8_t>& payload) {
  Reader r(payload, "commit");
  const uint8_t full = r.scalar<uint8_t>();
  const uint64_t frame = r.scalar<uint64_t>();
  if (full > 1) r.fail(fmt::format("full-resync flag {} is neither 0 nor 1", full));
  commit::CommitBuffer c;
  if (full) {
    auto scene = std::make_shared<commit::TracerScene>();
    read_scene_arrays(r, *scene);
    scene->camera = r.scalar<KCamera>();
    scene->version = r.scalar<uint64_t>();
    check_scene(*scene, r);
    c = commit::CommitBuffer::full(std::move(scene), frame);
  }
  c.set_frame(frame);
  read_records(r, c);
  return c;
}

std::vector<uint8_t> encode_full_local(const commit::CommitBuffer& full) {
  Writer w;
  w.scalar(uint64_t(full.frame()));
  w.scalar(full.full_scene()->camera);
  w.scalar(full.full_scene()->version);
  write_records(w, full);
  return std::move(w.out);
}

commit::CommitBuffer decode_full_local(const std::vector<uint8_t>& payload,
                                       std::shared_ptr<const commit::TracerScene> own_scene) {
  Reader r(payload, "full_local");
  const uint64_t frame = r.scalar<uint64_t>();
  auto scene = std::make_shared<commit::TracerScene>(*own_scene);
  scene->camera = r.scalar<KCamera>();
  scene->version = r.scalar<uint64_t>();
  commit::CommitBuffer c = commit::CommitBuffer::full(std::move(scene), frame);
  read_records(r, c);
  return c;
}

namespace {
// A band travels in band_pieces of its rows; one that adopts a job ahead in one piece per run of rows
// beyond it (none to two).
void check_pieces(Reader& r, uint32_t pieces, uint32_t rows, bool adopts) {
  if (adopts) {
    if (pieces > kMaxBeyondPieces)
      r.fail(fmt::format("{} pieces beyond the adopted rows (at most {})", pieces, kMaxBeyondPieces));
  } else if (pieces != band_pieces(rows, pieces)) {
    r.fail(fmt::format("{} pieces for a band of {} rows (1 to {}, at most one a row)", pieces, rows, kMaxPieces));
  }
}
}  // namespace

std::vector<uint8_t> encode_band_request(const BandRequest& request) {
  Writer w;
  w.scalar(uint32_t(sizeof(core::BandJob)));
  w.scalar(request.job);
  w.scalar(uint32_t(request.format));
  w.scalar(uint32_t(request.aux ? 1 : 0));
  w.scalar(request.pieces);
  w.scalar(uint32_t(request.ahead ? 1 : 0));
  w.scalar(request.adopt);
  return std::move(w.out);
}

BandRequest decode_band_request(const std::vector<uint8_t>& payload) {
  Reader r(payload, "band_job");
  const uint32_t job_size = r.scalar<uint32_t>();
  if (job_size != sizeof(core::BandJob))
    r.fail(fmt::format("band job of {} bytes; this build's is {} (different Cohort versions?)", job_size,
                       sizeof(core::BandJob)));
  BandRequest q;
  q.job = r.scalar<core::BandJob>();
  q.format = band_format_of(r.scalar<uint32_t>(), r);
  const uint32_t aux = r.scalar<uint32_t>();
  if (aux > 1) r.fail(fmt::format("aux flag {} is neither 0 nor 1", aux));
  q.aux = aux == 1;
  q.pieces = r.scalar<uint32_t>();
  const uint32_t ahead = r.scalar<uint32_t>();
  if (ahead > 1) r.fail(fmt::format("ahead flag {} is neither 0 nor 1", ahead));
  q.ahead = ahead == 1;
  q.adopt = r.scalar<uint64_t>();
  r.expect_end();
  if (q.ahead && q.adopt != 0) r.fail(fmt::format("a job ahead cannot adopt another (job {})", q.adopt));
  const KFrameParams& p = q.job.params;
  if (q.job.camera.width == 0 || q.job.camera.height == 0 || q.job.camera.width > 65536 || q.job.camera.height > 65536)
    r.fail(fmt::format("camera size {}x{} is out of range", q.job.camera.width, q.job.camera.height));
  if (p.row_begin > p.row_end || p.row_end > q.job.camera.height)
    r.fail(fmt::format("rows [{}, {}) do not fit a frame of {} rows", p.row_begin, p.row_end, q.job.camera.height));
  check_pieces(r, q.pieces, p.row_end - p.row_begin, q.adopt != 0);
  return q;
}

std::vector<RowRange> rows_beyond(RowRange ahead, RowRange band) {
  std::vector<RowRange> beyond;
  if (band.begin < std::min(ahead.begin, band.end)) beyond.push_back({band.begin, std::min(ahead.begin, band.end)});
  if (std::max(ahead.end, band.begin) < band.end) beyond.push_back({std::max(ahead.end, band.begin), band.end});
  return beyond;
}

bool rows_overlap(RowRange a, RowRange b) { return std::max(a.begin, b.begin) < std::min(a.end, b.end); }

int piece_tag(uint64_t job, uint32_t piece, Plane plane) {
  return kPieceTagBase + int(((job % kPieceJobSlots) * kMaxPieces + piece % kMaxPieces) * 2 + uint32_t(plane));
}

bool decode_piece_tag(int tag, PieceTag& out) {
  if (tag < kPieceTagBase || tag >= kPieceTagBase + int(kPieceJobSlots * kMaxPieces * 2)) return false;
  const uint32_t index = uint32_t(tag - kPieceTagBase);
  out.plane = Plane(index % 2);
  out.piece = (index / 2) % kMaxPieces;
  out.job_slot = index / 2 / kMaxPieces;
  return true;
}

RowRange piece_rows(uint32_t row_begin, uint32_t row_end, uint32_t pieces, uint32_t index) {
  const uint64_t rows = row_end - row_begin;
  pieces = pieces == 0 ? 1 : pieces;
  return {row_begin + uint32_t(rows * index / pieces), row_begin + uint32_t(rows * (index + 1) / pieces)};
}

uint32_t band_pieces(uint32_t rows, uint32_t wanted) {
  return std::max(1u, std::min({wanted, kMaxPieces, rows}));
}

uint64_t piece_bytes(uint32_t rows, uint32_t width, core::BandFormat format, Plane plane) {
  return uint64_t(rows) * width * (plane == Plane::aux ? sizeof(KAuxTexel) : core::bytes_per_pixel(format));
}

std::vector<uint8_t> encode_band_rows(const BandRows& rows) {
  Writer w;
  w.scalar(rows.row_begin);
  w.scalar(rows.row_end);
  w.scalar(rows.width);
  w.scalar(uint32_t(rows.format));
  w.scalar(rows.pieces);
  w.scalar(uint32_t(rows.aux ? 1 : 0));
  w.scalar(rows.adopted);
  w.scalar(rows.device_ms);
  w.scalar(rows.timing);
  w.array(rows.row_work);
  return std::move(w.out);
}

BandRows decode_band_rows(const std::vector<uint8_t>& payload) { return decode_band_rows(payload.data(), payload.size()); }

BandRows decode_band_rows(const uint8_t* payload, size_t size) {
  Reader r(payload, size, "band_rows");
  BandRows b;
  b.row_begin = r.scalar<uint32_t>();
  b.row_end = r.scalar<uint32_t>();
  b.width = r.scalar<uint32_t>();
  b.format = band_format_of(r.scalar<uint32_t>(), r);
  b.pieces = r.scalar<uint32_t>();
  const uint32_t aux = r.scalar<uint32_t>();
  if (aux > 1) r.fail(fmt::format("aux flag {} is neither 0 nor 1", aux));
  b.aux = aux == 1;
  b.adopted = r.scalar<uint64_t>();
  b.device_ms = r.scalar<double>();
  b.timing = r.scalar<NodeTiming>();
  b.row_work = r.array<float>("row work");
  r.expect_end();
  if (b.row_end < b.row_begin) r.fail(fmt::format("rows [{}, {}) end before they begin", b.row_begin, b.row_end));
  if (b.width == 0 || b.width > 65536) r.fail(fmt::format("width {} is out of range", b.width));
  const uint32_t rows = b.row_end - b.row_begin;
  check_pieces(r, b.pieces, rows, b.adopted != 0);
  if (!b.row_work.empty() && b.row_work.size() != rows)
    r.fail(fmt::format("{} row work values for {} rows", b.row_work.size(), rows));
  const double times[] = {b.device_ms, b.timing.total_ms, b.timing.render_ms, b.timing.device_ms, b.timing.send_ms,
                          b.timing.first_piece_ms, b.timing.commit_ms, b.timing.commit_ahead_ms, b.timing.idle_ms,
                          b.timing.ahead_ms};
  for (double t : times)
    if (!(t >= 0.0 && t < 1e9)) r.fail(fmt::format("time {} ms is not a duration", t));
  return b;
}

std::vector<uint8_t> encode_warm(const Warm& warm) {
  Writer w;
  w.scalar(uint8_t(warm.has_job ? 1 : 0));
  if (warm.has_job) w.array(encode_band_request(warm.request));
  return std::move(w.out);
}

Warm decode_warm(const std::vector<uint8_t>& payload) {
  Reader r(payload, "warm");
  Warm warm;
  const uint8_t has_job = r.scalar<uint8_t>();
  if (has_job > 1) r.fail(fmt::format("job flag {} is neither 0 nor 1", has_job));
  warm.has_job = has_job == 1;
  if (warm.has_job) warm.request = decode_band_request(r.array<uint8_t>("band job"));
  r.expect_end();
  if (warm.has_job && (warm.request.ahead || warm.request.adopt != 0))
    r.fail("a warm-up band can be neither a job ahead nor adopt one");
  return warm;
}

std::vector<uint8_t> encode_ready(const Ready& ready) {
  Writer w;
  w.scalar(ready.resync_ms);
  w.scalar(ready.warm_ms);
  w.text(ready.failure);
  return std::move(w.out);
}

Ready decode_ready(const std::vector<uint8_t>& payload) {
  Reader r(payload, "ready");
  Ready ready;
  ready.resync_ms = r.scalar<double>();
  ready.warm_ms = r.scalar<double>();
  if (!(ready.resync_ms >= 0.0 && ready.resync_ms < 1e9) || !(ready.warm_ms >= 0.0 && ready.warm_ms < 1e9))
    r.fail(fmt::format("times {} and {} ms are out of range", ready.resync_ms, ready.warm_ms));
  ready.failure = r.text("failure");
  r.expect_end();
  return ready;
}

std::vector<uint8_t> encode_band_failure(const BandFailure& failure) {
  Writer w;
  w.scalar(uint8_t(failure.needs_full_resync ? 1 : 0));
  w.text(failure.reason);
  return std::move(w.out);
}

BandFailure decode_band_failure(const std::vector<uint8_t>& payload) {
  Reader r(payload, "band_failed");
  BandFailure f;
  const uint8_t resync = r.scalar<uint8_t>();
  if (resync > 1) r.fail(fmt::format("resync flag {} is neither 0 nor 1", resync));
  f.needs_full_resync = resync == 1;
  f.reason = r.text("reason");
  r.expect_end();
  return f;
}

uint64_t scene_fingerprint(const commit::TracerScene& scene) {
  // FNV-1a over 64-bit words (and the tail bytes), each array prefixed by its byte size.
  uint64_t h = 14695981039346656037ull;
  auto mix = [&](uint64_t v) { h = (h ^ v) * 1099511628211ull; };
  visit_scene_arrays(scene, [&](const auto& v) {
    const size_t bytes = v.size() * sizeof(v[0]);
    mix(bytes);
    const auto* p = reinterpret_cast<const uint8_t*>(v.data());
    size_t i = 0;
    for (; i + 8 <= bytes; i += 8) {
      uint64_t word;
      std::memcpy(&word, p + i, 8);
      mix(word);
    }
    for (; i < bytes; ++i) mix(p[i]);
  });
  return h == 0 ? 1 : h;  // 0 means "no scene"
}

std::string cohort_version() { return COHORT_VERSION; }

}  // namespace cohort::tracers::wire
