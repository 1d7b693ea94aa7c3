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
// 2: vertex colours in scenes and BLAS uploads; 3: BandJob::keep_on_device; 4: a band's rows travel in
// pieces, raw, on tags of their own (band_job names the piece count, band_rows closes the band);
// 5: KMaterial carries an environment cube (128 bytes); 6: NodeTiming tells commits applied before the
// job came from those in its way (commits travel ahead of their job, docs/cluster.md); 7: jobs ahead
// (band_job says whether it is one, or which one it takes the rows of; band_rows too; NodeTiming tells
// the node's idle time and the time it rendered before the job came); 8: band format 2, RGB9E5 rows
// (4 bytes a pixel); 9: join (a node that connects through rank 0's port names the slot it serves first);
// 10: warm and ready (a node that joined a running session takes its full resync on the side and says when
// it can render: docs/cluster.md, "Joining a running session").
constexpr uint16_t kProtocolVersion = 10;

enum class Kind : uint16_t {
  hello = 1,        // node -> 0: versions, what scene it loaded, its tracers
  load_failed = 2,  // node -> 0: it could not load its scene (file:line) or open its tracers, and leaves
  welcome = 3,      // 0 -> node: versions agree, serve bands
  refuse = 4,       // 0 -> node: versions disagree (the reason), leave
  commit = 5,       // 0 -> node: a commit buffer (records, or a whole scene)
  full_local = 6,   // 0 -> node: a full resync to the scene the node loaded itself (same fingerprint)
  band_job = 7,     // 0 -> node: render these rows
  band_rows = 8,    // node -> 0: the band is done (its rows went ahead as pieces): row work and timing
  band_failed = 9,  // node -> 0: the band could not be rendered (the reason)
  shutdown = 10,    // 0 -> node: leave cleanly
  join = 11,        // node -> 0, first through rank 0's port: the slot (mpi:N) it asks to serve, 0 for any free one
  warm = 12,        // 0 -> node: once what came before is applied (its full resync), warm up and say ready
  ready = 13,       // node -> 0: the answer to warm: it can render (or why not), and what its warm-up took
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

// join: the slot asked for (0: the first free one).
std::vector<uint8_t> encode_join(uint32_t slot);
uint32_t decode_join(const std::vector<uint8_t>& payload);

// Why rank 0 cannot take this node's hello (Cohort version or protocol differ from this build's: both
// named), or empty.
std::string version_mismatch(const Hello& hello, int slot);

// load_failed, refuse, welcome (the slot, for a node that joined): one text.
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

// A band's rows travel as pieces: runs of whole rows, each sent as soon as the node has it on the host
// while it renders the next, raw (no header) on an MPI tag of its own that names the band job, the
// piece and the plane, so that rank 0 receives each straight into its target rows. The band_rows
// message that follows the pieces closes the band. Tags of the control messages and of the pieces do
// not overlap, and all of them fit the 32767 that every MPI library offers (MPI_TAG_UB).
constexpr int kControlTag = 0x434f;
constexpr int kPieceTagBase = 0x4400;
constexpr uint32_t kMaxPieces = 32;
// Piece tags tell apart the jobs of the last kPieceJobSlots to a node; a node has at most one band in
// flight (a remote tracer sends it no other while it has not answered), so a late piece is never
// taken for the current job's.
constexpr uint32_t kPieceJobSlots = 64;
enum class Plane : uint32_t { colour = 0, aux = 1 };
int piece_tag(uint64_t job, uint32_t piece, Plane plane);
struct PieceTag {
  uint32_t job_slot = 0, piece = 0;
  Plane plane = Plane::colour;
  bool of_job(uint64_t job) const { return job_slot == job % kPieceJobSlots; }
};
// False for a tag that is no piece's (the control tag, or out of the range).
bool decode_piece_tag(int tag, PieceTag& out);
// Rows [begin, end) of piece `index` of `pieces` over rows [row_begin, row_end): as even as whole rows
// allow, in order, none empty while there are at least as many rows as pieces.
struct RowRange {
  uint32_t begin = 0, end = 0;
};
RowRange piece_rows(uint32_t row_begin, uint32_t row_end, uint32_t pieces, uint32_t index);
// How many pieces a band of `rows` rows travels in when `wanted` are asked for: 1 to kMaxPieces, never
// more than its rows.
uint32_t band_pieces(uint32_t rows, uint32_t wanted);

// Jobs ahead (docs/cluster.md): rank 0 sends the next frame's job as soon as the core announces it,
// with the rows of the band in flight (`ahead`), so that the node renders it right after that band;
// the frame's real job then names it (`adopt`): the node takes its rows where they are the band's and
// renders only the band's rows beyond them, each run of them in one piece (at most two: below and
// above). No overlap, another frame or a commit in between: rank 0 adopts nothing, and the rows
// rendered ahead are dropped.
constexpr uint32_t kMaxBeyondPieces = 2;
// The rows of `band` outside `ahead`, in order (empty when ahead covers band).
std::vector<RowRange> rows_beyond(RowRange ahead, RowRange band);
bool rows_overlap(RowRange a, RowRange b);

struct BandRequest {
  core::BandJob job;
  core::BandFormat format = core::BandFormat::rgb16f;
  bool aux = false;  // send the auxiliary planes too (kernel/aux_outputs.h)
  // The rows travel in this many pieces (band_pieces of the band's rows); when adopting, one piece per
  // run of rows_beyond (0 to kMaxBeyondPieces).
  uint32_t pieces = 1;
  bool ahead = false;  // a job ahead: render it after the band in flight; its rows are rank 0's guess
  uint64_t adopt = 0;  // the job ahead whose rows this band takes (0: none)
};
std::vector<uint8_t> encode_band_request(const BandRequest& request);
BandRequest decode_band_request(const std::vector<uint8_t>& payload);

// Where a node's time on a band went, for rank 0's log and `cohort bench devices`.
struct NodeTiming {
  double total_ms = 0.0;   // job taken -> band_rows sent (commit applied before it is not counted)
  double render_ms = 0.0;  // in its tracers' render_band calls, wall (GPU: kernel, download and waits)
  double device_ms = 0.0;  // what the tracers measured themselves (GPU: kernel time; summed over pieces)
  // In MPI calls: posting the pieces, moving them while the next piece renders (so overlapping
  // render_ms), and the wait for the last band's pieces to have left.
  double send_ms = 0.0;
  double first_piece_ms = 0.0;  // job taken -> first piece posted
  // Decoding and applying the commits that came since the last band (before this job, on the same
  // ordered stream; not in total_ms): those after which this job was already waiting (so in the round
  // trip's way, at most by their time), and those applied before it came (hidden while rank 0 waited).
  double commit_ms = 0.0;
  double commit_ahead_ms = 0.0;
  // Protocol 7. The node waited this long with nothing to render before this band (its previous band
  // was done, and neither this job nor a job ahead had come): what jobs ahead take away.
  double idle_ms = 0.0;
  // Of total_ms, the time it rendered the band (as a job ahead) before its job came.
  double ahead_ms = 0.0;
};
static_assert(sizeof(NodeTiming) == 72, "NodeTiming travels as it lies: nine doubles");

// The band_rows message: the band is done. Its pieces went ahead on their own tags: `pieces` of colour
// rows in the band format (6 bytes a pixel as rgb16f, 4 as rgb9e5), and as many of aux texels when `aux`.
struct BandRows {
  uint32_t row_begin = 0, row_end = 0, width = 0;
  core::BandFormat format = core::BandFormat::rgb16f;
  uint32_t pieces = 1;  // as in its band_job
  bool aux = false;
  uint64_t adopted = 0;  // the job ahead whose rows it took (BandRequest::adopt)
  double device_ms = 0.0;  // the node's time for the band, as the balancer takes it
  NodeTiming timing;
  std::vector<float> row_work;
};
std::vector<uint8_t> encode_band_rows(const BandRows& rows);
BandRows decode_band_rows(const std::vector<uint8_t>& payload);
BandRows decode_band_rows(const uint8_t* payload, size_t size);
// The bytes of one piece's plane: its rows of colour in `format`, or of aux texels.
uint64_t piece_bytes(uint32_t rows, uint32_t width, core::BandFormat format, Plane plane);

// warm (protocol 10): sent to a node that joined a running session right behind its full resync; the node
// answers ready once everything before it is applied. With a job (the last band its slot was sent, when
// there was one), the node renders that band once, for nothing, before it answers, so that its first real
// band finds its kernels loaded and its buffers made; the rows are not sent.
struct Warm {
  bool has_job = false;
  BandRequest request;  // when has_job; pieces and ahead/adopt are not used
};
std::vector<uint8_t> encode_warm(const Warm& warm);
Warm decode_warm(const std::vector<uint8_t>& payload);

// ready: the node can render (failure empty), or why not (its scene is behind: rank 0 sends another full
// resync). Its times: applying the last full resync (decoding it included) and the warm-up band.
struct Ready {
  double resync_ms = 0.0;
  double warm_ms = 0.0;
  std::string failure;
};
std::vector<uint8_t> encode_ready(const Ready& ready);
Ready decode_ready(const std::vector<uint8_t>& payload);

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
