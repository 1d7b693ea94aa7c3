// What travels between rank 0 and a node (docs/cluster.md): every message is a 24-byte header (magic,
// protocol version, kind, sequence, payload size) and a payload whose arrays are length-prefixed. The
// codec is plain C++ with no MPI calls, so its refusals are tested on their own: a message that is
// malformed or truncated throws WireError with the reason and nothing of it is applied.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "cohort/commit/commit_buffer.h"
#include "cohort/core/band_buffer.h"
#include "cohort/core/tracer.h"

namespace cohort::tracers::wire {

constexpr uint32_t kMagic = 0x504d4843u;  // "CHMP" in memory order
constexpr uint16_t kProtocolVersion = 4;  // 2: vertex colours in scenes and BLAS uploads; 3: BandJob::keep_on_device;
                                          // 4: KMaterial carries an environment cube (128 bytes)

enum class Kind : uint16_t {
  hello = 1,        // node -> 0: versions, what scene it loaded, its tracers
  load_failed = 2,  // node -> 0: it could not load its scene (file:line) or open its tracers, and leaves
  welcome = 3,      // 0 -> node: versions agree, serve bands
  refuse = 4,       // 0 -> node: versions disagree (the reason), leave
  commit = 5,       // 0 -> node: a commit buffer (records, or a whole scene)
  full_local = 6,   // 0 -> node: a full resync to the scene the node loaded itself (same fingerprint)
  band_job = 7,     // 0 -> node: render these rows
  band_rows = 8,    // node -> 0: the band's rows
  band_failed = 9,  // node -> 0: the band could not be rendered (the reason)
  shutdown = 10,    // 0 -> node: leave cleanly
};
const char* to_string(Kind kind);

struct Header {
  uint32_t magic = kMagic;
  uint16_t protocol = kProtocolVersion;
  uint16_t kind = 0;
  uint64_t sequence = 0;  // the band job's id for band messages, the commit's frame for commits
  uint64_t payload_bytes = 0;
};
static_assert(sizeof(Header) == 24, "the wire header is 24 bytes");

class WireError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct Message {
  Kind kind{};
  uint64_t sequence = 0;
  std::vector<uint8_t> payload;
};

// A whole message: header then payload.
std::vector<uint8_t> frame_message(Kind kind, uint64_t sequence, const std::vector<uint8_t>& payload);
// Checks the header (magic, protocol, known kind, payload size equal to what arrived) and splits it off.
Message parse_message(const uint8_t* bytes, size_t size);
// The same checks, the payload left in place after the header (a band's rows are decoded there).
Header parse_header(const uint8_t* bytes, size_t size);

// ---- Payloads. Each encode_* has a decode_* that throws WireError naming what is wrong. ----

struct Hello {
  std::string cohort_version;
  uint32_t protocol = kProtocolVersion;
  std::string host;
  std::string tracers;           // the node's tracers, as named on its command line
  uint64_t scene_fingerprint = 0;  // of the scene it loaded; 0: none loaded (it needs the whole scene)
  std::string scene_name;
};
std::vector<uint8_t> encode_hello(const Hello& hello);
Hello decode_hello(const std::vector<uint8_t>& payload);

// load_failed, refuse: one text.
std::vector<uint8_t> encode_text(const std::string& text);
std::string decode_text(const std::vector<uint8_t>& payload);

// A commit buffer, every record; a full resync carries the whole scene, then the records folded in
// after it (a channel that took a full resync and then more frames' records before its tracer's job).
std::vector<uint8_t> encode_commit(const commit::CommitBuffer& commit);
commit::CommitBuffer decode_commit(const std::vector<uint8_t>& payload);

// A full resync to the scene the node loaded itself (same fingerprint): the scene's camera and
// version, and the records on top; the node's own scene fills in the rest.
std::vector<uint8_t> encode_full_local(const commit::CommitBuffer& full);
commit::CommitBuffer decode_full_local(const std::vector<uint8_t>& payload,
                                       std::shared_ptr<const commit::TracerScene> own_scene);

struct BandRequest {
  core::BandJob job;
  core::BandFormat format = core::BandFormat::rgb16f;
  bool aux = false;  // send the auxiliary planes too (kernel/aux_outputs.h)
};
std::vector<uint8_t> encode_band_request(const BandRequest& request);
BandRequest decode_band_request(const std::vector<uint8_t>& payload);

// A band's rows in the band format (6 bytes a pixel as rgb16f), and its aux planes when asked for.
struct BandRows {
  uint32_t row_begin = 0, row_end = 0, width = 0;
  core::BandFormat format = core::BandFormat::rgb16f;
  double device_ms = 0.0;
  std::vector<float> row_work;
  std::vector<uint8_t> pixels;
  std::vector<uint8_t> aux;
};
// Encodes rows [row_begin, row_end) of `source` straight from its storage.
std::vector<uint8_t> encode_band_rows(const core::BandBuffer& source, uint32_t row_begin, uint32_t row_end,
                                      double device_ms, const std::vector<float>& row_work);
BandRows decode_band_rows(const std::vector<uint8_t>& payload);
// The same, pixels and aux texels left where they lie in `payload` (valid while it is): the remote tracer
// copies them once, into its target.
struct BandRowsView {
  uint32_t row_begin = 0, row_end = 0, width = 0;
  core::BandFormat format = core::BandFormat::rgb16f;
  double device_ms = 0.0;
  std::vector<float> row_work;
  const uint8_t* pixels = nullptr;
  uint64_t pixel_bytes = 0;
  const uint8_t* aux = nullptr;
  uint64_t aux_bytes = 0;
};
BandRowsView decode_band_rows_view(const std::vector<uint8_t>& payload);
BandRowsView decode_band_rows_view(const uint8_t* payload, size_t size);
// A whole band_rows message (header included) built in one buffer: what the node sends.
std::vector<uint8_t> band_rows_message(uint64_t sequence, const core::BandBuffer& source, uint32_t row_begin,
                                       uint32_t row_end, double device_ms, const std::vector<float>& row_work);

struct BandFailure {
  bool needs_full_resync = false;  // the node's scene is behind or diverged: the next commit must be whole
  std::string reason;
};
std::vector<uint8_t> encode_band_failure(const BandFailure& failure);
BandFailure decode_band_failure(const std::vector<uint8_t>& payload);

// A 64-bit fingerprint of a scene's content (every array; not the camera nor the frame number), so
// that rank 0 can tell whether a node loaded the same scene and needs no copy of it.
uint64_t scene_fingerprint(const commit::TracerScene& scene);

// This build's version, as the handshake compares it.
std::string cohort_version();

}  // namespace cohort::tracers::wire
