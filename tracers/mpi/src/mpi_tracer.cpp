#include "cohort/tracers/mpi_tracer.h"

#include <algorithm>
#include <atomic>
#include <cstring>
#include <functional>
#include <map>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "cohort/tracers/mpi_link.h"
#include "cohort/tracers/mpi_wire.h"

namespace cohort::tracers {

namespace {
double ms_since(MpiClock::time_point start) {
  return std::chrono::duration<double, std::milli>(MpiClock::now() - start).count();
}

// A node says hello once per run; tracers made for it later (`cohort bench devices` makes one per mix)
// find it here and start with a full resync like any tracer.
struct JoinedNode {
  wire::Hello hello;
};
std::mutex joined_mutex;
std::map<int, JoinedNode>& joined_nodes() {
  static std::map<int, JoinedNode> nodes;
  return nodes;
}

// Pieces that belong to no band this tracer waits for (the late answer to a band that timed out):
// received into scratch and dropped.
struct DropPieces : PieceSink {
  void* place(int, size_t size) override {
    bytes += size;
    return nullptr;
  }
  uint64_t bytes = 0;
};

// The pieces of the current band: each one checked against the band (its tag names this job, a piece
// and plane that exist, its size that of its rows) and received straight into its rows of the target;
// anything else is dropped, and a piece of this band that does not fit makes the band fail when its
// band_rows comes.
class BandPieces : public PieceSink {
 public:
  BandPieces(uint64_t job, uint32_t row_begin, uint32_t row_end, uint32_t pieces, core::BandBuffer& target)
      : job_(job), row_begin_(row_begin), row_end_(row_end), pieces_(pieces), target_(target) {}

  void* place(int tag, size_t size) override {
    bytes += size;
    if (first_matched == MpiClock::time_point{}) first_matched = MpiClock::now();
    wire::PieceTag piece;
    if (!wire::decode_piece_tag(tag, piece)) {
      ++refused;
      refuse(fmt::format("a message on tag {}, which is neither the control tag nor a piece's", tag));
      return nullptr;
    }
    if (!piece.of_job(job_)) {
      ++stale;  // a piece of an earlier job's late answer
      return nullptr;
    }
    const bool aux = piece.plane == wire::Plane::aux;
    if (piece.piece >= pieces_ || (aux && !target_.has_aux())) {
      ++refused;
      refuse(fmt::format("piece {} of {}{} was not asked for", piece.piece, pieces_, aux ? " (aux planes)" : ""));
      return nullptr;
    }
    const wire::RowRange rows = wire::piece_rows(row_begin_, row_end_, pieces_, piece.piece);
    const uint64_t expected = wire::piece_bytes(rows.end - rows.begin, uint32_t(target_.width()), target_.format(),
                                                piece.plane);
    if (size != expected) {
      ++refused;
      refuse(fmt::format("piece {} of {} ({}rows [{}, {})) has {} bytes; they are {}", piece.piece, pieces_,
                         aux ? "aux texels of " : "", rows.begin, rows.end, size, expected));
      return nullptr;
    }
    const uint64_t bit = uint64_t(1) << (piece.piece * 2 + uint32_t(piece.plane));
    if (landed_ & bit) {
      ++refused;
      refuse(fmt::format("piece {} of {}{} came twice", piece.piece, pieces_, aux ? " (aux planes)" : ""));
      return nullptr;
    }
    landed_ |= bit;
    if (aux) return target_.aux_row(int(rows.begin));
    return target_.row(int(rows.begin));
  }

  // Why the band's rows cannot be taken (a piece refused or missing), or empty.
  std::string problem() const {
    if (!problem_.empty()) return problem_;
    for (uint32_t i = 0; i < pieces_; ++i)
      for (uint32_t plane = 0; plane < (target_.has_aux() ? 2u : 1u); ++plane)
        if (!(landed_ & (uint64_t(1) << (i * 2 + plane))))
          return fmt::format("piece {} of {}{} never came", i, pieces_, plane == 1 ? " (aux planes)" : "");
    return {};
  }

  uint64_t bytes = 0, refused = 0, stale = 0;
  MpiClock::time_point first_matched{};

 private:
  void refuse(std::string why) {
    if (problem_.empty()) problem_ = std::move(why);
  }
  uint64_t job_;
  uint32_t row_begin_, row_end_, pieces_;
  core::BandBuffer& target_;
  uint64_t landed_ = 0;
  std::string problem_;
};

// Band job ids are unique over the run, so that a late answer to an earlier tracer's job is never
// taken for the current one.
std::atomic<uint64_t> next_band_job{1};
}  // namespace

MpiTracer::MpiTracer(MpiTracerOptions options) : options_(options) {
  MpiSession& mpi = MpiSession::get();
  mpi.set_farewell(wire::frame_message(wire::Kind::shutdown, 0, {}));
  if (mpi.rank() != 0)
    throw NodeUnavailable(fmt::format("mpi:{}: remote tracers are driven from rank 0; this process is rank {}",
                                      options_.rank, mpi.rank()));
  if (options_.rank < 1 || options_.rank >= mpi.size())
    throw NodeUnavailable(fmt::format("mpi:{}: no such rank: the MPI world has {} rank(s) (launch under mpirun, "
                                      "with `cohort node` on ranks 1 and up; docs/cluster.md)",
                                      options_.rank, mpi.size()));
  {
    std::lock_guard lock(joined_mutex);
    auto known = joined_nodes().find(options_.rank);
    if (known != joined_nodes().end()) {
      adopt(known->second.hello);
      return;
    }
  }
  const auto deadline = MpiClock::now() + options_.hello_timeout;
  for (;;) {
    std::optional<std::vector<uint8_t>> bytes = mpi.receive(options_.rank, deadline);
    if (!bytes)
      throw NodeUnavailable(fmt::format("mpi:{}: the node sent no hello within {} ms (is `cohort node` running on "
                                        "that rank?)", options_.rank, options_.hello_timeout.count()));
    wire::Message m;
    try {
      m = wire::parse_message(bytes->data(), bytes->size());
    } catch (const wire::WireError& e) {
      spdlog::warn("mpi:{}: refused a message before the hello: {}", options_.rank, e.what());
      continue;
    }
    if (m.kind == wire::Kind::load_failed) {
      mpi.released(options_.rank);  // it has left
      std::string reason;
      try {
        reason = wire::decode_text(m.payload);
      } catch (const wire::WireError& e) {
        reason = std::string("(unreadable reason: ") + e.what() + ")";
      }
      throw NodeUnavailable(fmt::format("mpi:{}: the node could not start (its scene or its tracers) and leaves: {}",
                                        options_.rank, reason));
    }
    if (m.kind != wire::Kind::hello) {
      spdlog::warn("mpi:{}: ignored a {} message before the hello", options_.rank, wire::to_string(m.kind));
      continue;
    }
    wire::Hello hello;
    try {
      hello = wire::decode_hello(m.payload);
    } catch (const wire::WireError& e) {
      mpi.released(options_.rank);
      send(int(wire::Kind::refuse), 0, wire::encode_text(std::string("malformed hello: ") + e.what()));
      throw NodeUnavailable(fmt::format("mpi:{}: refused the node's malformed hello: {}", options_.rank, e.what()));
    }
    const std::string mine = wire::cohort_version();
    if (hello.cohort_version != mine || hello.protocol != wire::kProtocolVersion) {
      const std::string why = fmt::format(
          "version mismatch: rank 0 runs Cohort {} (protocol {}), rank {} on {} runs Cohort {} (protocol {}); run the "
          "same build on every rank", mine, wire::kProtocolVersion, options_.rank, hello.host, hello.cohort_version,
          hello.protocol);
      send(int(wire::Kind::refuse), 0, wire::encode_text(why));
      mpi.released(options_.rank);
      mpi.flush_sends(options_.rank, MpiClock::now() + std::chrono::seconds(1));
      throw NodeUnavailable("mpi:" + std::to_string(options_.rank) + ": " + why);
    }
    send(int(wire::Kind::welcome), 0, {});
    adopt(hello);
    {
      std::lock_guard lock(joined_mutex);
      joined_nodes()[options_.rank] = {hello};
    }
    spdlog::info("mpi:{}: node joined ({})", options_.rank, description_);
    return;
  }
}

void MpiTracer::adopt(const wire::Hello& hello) {
  node_fingerprint_ = hello.scene_fingerprint;
  gpu_ = hello.tracers.find("cuda") != std::string::npos || hello.tracers.find("opencl") != std::string::npos;
  description_ = fmt::format("rank {} on {}: {}{}", options_.rank, hello.host, hello.tracers,
                             hello.scene_name.empty() ? "" : ", scene " + hello.scene_name);
}

MpiTracer::~MpiTracer() {
  const MpiLinkStats s = link_stats();
  if (s.resync_bands > 0)
    spdlog::info("mpi:{}: {} band(s) right after a full resync (the node applying the scene and building its BVHs), "
                 "round trip {:.2f} ms each; the figures below leave them out", options_.rank, s.resync_bands,
                 s.total_resync_round_trip_ms / double(s.resync_bands));
  if (s.steady_bands > 0) {
    const double n = double(s.steady_bands);
    const double round_trip = s.total_round_trip_ms / n, node = s.total_node_ms / n;
    spdlog::info("mpi:{}: {} band(s), {:.1f} KiB sent and {:.1f} KiB received a band ({} pieces), round trip {:.2f} ms "
                 "a band: on the node {:.2f} ms (its tracers' render_band {:.2f} ms, of it their own {:.2f} ms; MPI "
                 "calls {:.2f} ms; first piece sent after {:.2f} ms), rank 0 matched it after {:.2f} ms; {:.2f} ms "
                 "beyond the node's time, "
                 "of it {:.2f} ms applying commits with the job waiting (the rest: the job out, the last piece and "
                 "band_rows back); {:.2f} ms a band applying commits before the job came ({} commit(s) sent ahead of "
                 "their job)",
                 options_.rank, s.steady_bands, double(s.bytes_sent) / double(s.bands) / 1024.0,
                 double(s.bytes_received) / double(s.bands) / 1024.0,
                 s.last_pieces, round_trip, node, s.total_node_render_ms / n, s.total_node_tracer_ms / n,
                 s.total_node_send_ms / n, s.total_node_first_piece_ms / n, s.total_first_piece_ms / n, round_trip - node,
                 s.total_node_commit_ms / n, s.total_node_commit_ahead_ms / n, s.commits_ahead);
  }
  // The node stays for later tracers of this run; the session's end tells every node to leave.
  try {
    MpiSession& mpi = MpiSession::get();
    if (!mpi.finalized()) mpi.flush_sends(options_.rank, MpiClock::now() + std::chrono::seconds(1));
  } catch (const std::exception& e) {
    spdlog::warn("mpi:{}: {}", options_.rank, e.what());
  }
}

std::string MpiTracer::name() const { return "mpi:" + std::to_string(options_.rank); }

void MpiTracer::send(int kind, uint64_t sequence, const std::vector<uint8_t>& payload) {
  std::vector<uint8_t> message = wire::frame_message(wire::Kind(kind), sequence, payload);
  {
    std::lock_guard lock(stats_mutex_);
    stats_.bytes_sent += message.size();
    pending_sent_ += message.size();
  }
  MpiSession::get().send(options_.rank, std::move(message));
}

void MpiTracer::apply(const commit::CommitBuffer& commit) {
  if (in_band_) {
    // Taken ahead (from inside render_band, after the band's job): the node applies it once that band
    // is rendered, before the next job comes.
    commits_ahead_of_band_ = true;
    std::lock_guard lock(stats_mutex_);
    ++stats_.commits_ahead;
  }
  if (!commit.is_full_resync()) {
    if (node_needs_resync_)
      throw std::runtime_error(fmt::format("mpi:{}: {}; it needs a full resync", options_.rank, node_failure_));
    send(int(wire::Kind::commit), commit.frame(), wire::encode_commit(commit));
    return;
  }
  const commit::TracerScene& scene = *commit.full_scene();
  if (hashed_scene_ != commit.shared_full_scene()) {
    hashed_fingerprint_ = wire::scene_fingerprint(scene);
    hashed_scene_ = commit.shared_full_scene();
  }
  if (node_fingerprint_ != 0 && hashed_fingerprint_ == node_fingerprint_) {
    // The node loaded this very scene: only the frame and camera travel.
    send(int(wire::Kind::full_local), commit.frame(), wire::encode_full_local(commit));
  } else {
    spdlog::info("mpi:{}: sending the whole scene (the node's own load differs or is gone)", options_.rank);
    send(int(wire::Kind::commit), commit.frame(), wire::encode_commit(commit));
  }
  node_needs_resync_ = false;
  after_full_resync_ = true;
  ++full_resyncs_sent_;
}

void MpiTracer::take_late_answers() {
  MpiSession& mpi = MpiSession::get();
  while (timed_out_job_ != 0) {
    DropPieces dropped;
    std::optional<std::vector<uint8_t>> bytes = mpi.receive(options_.rank, MpiClock::now(), &dropped);
    std::lock_guard lock(stats_mutex_);
    stats_.bytes_received += dropped.bytes;
    if (!bytes) return;
    stats_.bytes_received += bytes->size();
    try {
      const wire::Message m = wire::parse_message(bytes->data(), bytes->size());
      ++stats_.stale_answers;
      if ((m.kind == wire::Kind::band_rows || m.kind == wire::Kind::band_failed) && m.sequence == timed_out_job_) {
        stats_.last_round_trip_ms = std::max(stats_.last_round_trip_ms, ms_since(timed_out_start_));
        timed_out_job_ = 0;
        spdlog::info("mpi:{}: the node answered again, {:.0f} ms after its band was sent", options_.rank,
                     ms_since(timed_out_start_));
      }
    } catch (const wire::WireError& e) {
      ++stats_.refused_messages;
      spdlog::warn("mpi:{}: refused a message: {}", options_.rank, e.what());
    }
  }
}

void MpiTracer::fail_timed_out(uint64_t id, MpiClock::time_point start, const core::BandJob& job) {
  timed_out_job_ = id;
  timed_out_start_ = start;
  // A piece matched before the deadline is being received into the target's rows, which the Renderer
  // now hands to the other tracers: let it land first (it is in flight; this takes microseconds).
  if (!MpiSession::get().settle_pieces(options_.rank, MpiClock::now() + std::chrono::milliseconds(500)))
    spdlog::warn("mpi:{}: a piece of rows [{}, {}) is still arriving after the band timed out", options_.rank,
                 job.params.row_begin, job.params.row_end);
  throw std::runtime_error(fmt::format("mpi:{}: no answer for rows [{}, {}) within {:.0f} ms (node stalled?)",
                                       options_.rank, job.params.row_begin, job.params.row_end, ms_since(start)));
}

core::BandResult MpiTracer::render_band(const core::BandJob& job, core::BandBuffer& target) {
  MpiSession& mpi = MpiSession::get();
  if (timed_out_job_ != 0) {
    // A node that has not answered its last band yet (stalled, or gone) is not sent another: its band
    // fails at once, so it costs one late frame, not one per frame, and it is back when it answers.
    take_late_answers();
    if (timed_out_job_ != 0)
      throw std::runtime_error(fmt::format("mpi:{}: the node has not answered the band it was sent {:.0f} ms ago "
                                           "(stalled or gone); its rows go to the others", options_.rank,
                                           ms_since(timed_out_start_)));
  }
  if (job.params.row_end > uint32_t(target.height()) || job.params.row_begin > job.params.row_end ||
      job.camera.width != uint32_t(target.width()))
    throw std::invalid_argument(fmt::format("mpi:{}: rows [{}, {}) of a {}-wide frame do not fit the {}x{} target",
                                            options_.rank, job.params.row_begin, job.params.row_end, job.camera.width,
                                            target.width(), target.height()));
  if (commits_ahead_of_band_ && job.params.frame_index == band_frame_)
    spdlog::warn("mpi:{}: rows [{}, {}) of frame {} again (re-rendering another tracer's rows), but the node has "
                 "already applied the commits that came after its band of that frame: they show the next frame's "
                 "world (the camera is this frame's)", options_.rank, job.params.row_begin, job.params.row_end,
                 job.params.frame_index);
  commits_ahead_of_band_ = false;
  band_frame_ = job.params.frame_index;
  const uint64_t resyncs_before = full_resyncs_sent_;
  const bool first_after_resync = after_full_resync_;
  const uint64_t id = next_band_job++;
  wire::BandRequest request;
  request.job = job;
  request.job.keep_on_device = -1;  // rank 0's GPUs are not the node's: the rows travel
  request.format = target.format();
  request.aux = target.has_aux();
  request.pieces = wire::band_pieces(job.params.row_end - job.params.row_begin, options_.pieces);
  const auto start = MpiClock::now();
  send(int(wire::Kind::band_job), id, wire::encode_band_request(request));
  // From here on, what the core submits goes to the node behind this job (Tracer::apply_commits_ahead,
  // between polls): the node applies it once this band is rendered, while rank 0 waits for the frame.
  in_band_ = true;
  struct LeaveBand {
    bool& in_band;
    ~LeaveBand() { in_band = false; }
  } leave_band{in_band_};
  const std::function<void()> between_polls = [this] { apply_commits_ahead(); };
  double expected_ms;
  {
    std::lock_guard lock(stats_mutex_);
    expected_ms = stats_.last_round_trip_ms;
  }
  // The first band after a full resync also waits for the node to build its acceleration structures.
  const auto allowance = options_.band_timeout * (after_full_resync_ ? 10 : 1);
  const auto deadline = start + allowance + std::chrono::microseconds(int64_t(4000.0 * expected_ms));
  // The rows arrive as pieces, each received straight into its rows of the target; band_rows closes
  // the band once every piece has landed.
  BandPieces pieces(id, job.params.row_begin, job.params.row_end, request.pieces, target);
  uint64_t counted_piece_bytes = 0;
  auto count_pieces = [&] {
    std::lock_guard lock(stats_mutex_);
    stats_.bytes_received += pieces.bytes - counted_piece_bytes;
    stats_.refused_messages += pieces.refused;
    stats_.stale_answers += pieces.stale;
    counted_piece_bytes = pieces.bytes;
    pieces.refused = pieces.stale = 0;
  };
  for (;;) {
    std::optional<std::vector<uint8_t>> bytes = mpi.receive(options_.rank, deadline, &pieces, between_polls);
    count_pieces();
    if (!bytes) fail_timed_out(id, start, job);
    {
      std::lock_guard lock(stats_mutex_);
      stats_.bytes_received += bytes->size();
    }
    wire::Header header;
    try {
      header = wire::parse_header(bytes->data(), bytes->size());
    } catch (const wire::WireError& e) {
      std::lock_guard lock(stats_mutex_);
      ++stats_.refused_messages;
      spdlog::warn("mpi:{}: refused a message: {}", options_.rank, e.what());
      continue;
    }
    const wire::Kind kind = wire::Kind(header.kind);
    const uint8_t* payload = bytes->data() + sizeof(wire::Header);
    const size_t payload_size = bytes->size() - sizeof(wire::Header);
    if (kind != wire::Kind::band_rows && kind != wire::Kind::band_failed) {
      spdlog::warn("mpi:{}: ignored an unexpected {} message", options_.rank, wire::to_string(kind));
      continue;
    }
    if (header.sequence != id) {  // the answer to a job that timed out before
      std::lock_guard lock(stats_mutex_);
      ++stats_.stale_answers;
      // A band that merely took longer than the timeout teaches the next deadline how long bands take.
      if (header.sequence == timed_out_job_) {
        stats_.last_round_trip_ms = std::max(stats_.last_round_trip_ms, ms_since(timed_out_start_));
        timed_out_job_ = 0;
      }
      spdlog::debug("mpi:{}: dropped the late answer to job {}", options_.rank, header.sequence);
      continue;
    }
    if (kind == wire::Kind::band_failed) {
      wire::BandFailure failure;
      try {
        failure = wire::decode_band_failure(std::vector<uint8_t>(payload, payload + payload_size));
      } catch (const wire::WireError& e) {
        failure.reason = std::string("(unreadable reason: ") + e.what() + ")";
      }
      if (failure.needs_full_resync) {
        node_needs_resync_ = true;
        node_failure_ = failure.reason;
        node_fingerprint_ = 0;  // whatever it loaded, send the whole scene next time
      }
      throw std::runtime_error(fmt::format("mpi:{}: {}", options_.rank, failure.reason));
    }
    wire::BandRows rows;
    try {
      rows = wire::decode_band_rows(payload, payload_size);
    } catch (const wire::WireError& e) {
      std::lock_guard lock(stats_mutex_);
      ++stats_.refused_messages;
      throw std::runtime_error(fmt::format("mpi:{}: refused the band's rows: {}", options_.rank, e.what()));
    }
    if (rows.row_begin != job.params.row_begin || rows.row_end != job.params.row_end ||
        int(rows.width) != target.width() || rows.format != target.format() || rows.pieces != request.pieces ||
        rows.aux != target.has_aux())
      throw std::runtime_error(fmt::format("mpi:{}: refused the band's rows: rows [{}, {}) of {} {} pixels in {} "
                                           "pieces{}, asked for [{}, {}) of {} {} in {}{}", options_.rank,
                                           rows.row_begin, rows.row_end, rows.width, core::to_string(rows.format),
                                           rows.pieces, rows.aux ? " with aux planes" : "", job.params.row_begin,
                                           job.params.row_end, target.width(), core::to_string(target.format()),
                                           request.pieces, target.has_aux() ? " with aux planes" : ""));
    // Every piece matched before band_rows has landed (MpiSession::receive); one that was refused or
    // never came leaves rows unwritten: the band fails and the Renderer re-renders them elsewhere.
    if (const std::string problem = pieces.problem(); !problem.empty())
      throw std::runtime_error(fmt::format("mpi:{}: refused the band's rows: {}", options_.rank, problem));
    const double round_trip = ms_since(start);
    if (full_resyncs_sent_ == resyncs_before) after_full_resync_ = false;  // not when one went ahead of the next band
    {
      std::lock_guard lock(stats_mutex_);
      ++stats_.bands;
      stats_.last_round_trip_ms = round_trip;
      stats_.last_node_ms = rows.timing.total_ms;
      stats_.last_pieces = request.pieces;
      stats_.last_band_bytes_sent = pending_sent_;
      stats_.last_band_bytes_received = pieces.bytes + bytes->size();
      pending_sent_ = 0;
    }
    if (first_after_resync) {
      std::lock_guard lock(stats_mutex_);
      ++stats_.resync_bands;
      stats_.total_resync_round_trip_ms += round_trip;
    } else {
      std::lock_guard lock(stats_mutex_);
      ++stats_.steady_bands;
      stats_.total_round_trip_ms += round_trip;
      stats_.total_node_ms += rows.timing.total_ms;
      stats_.total_node_render_ms += rows.timing.render_ms;
      stats_.total_node_tracer_ms += rows.timing.device_ms;
      stats_.total_node_send_ms += rows.timing.send_ms;
      stats_.total_node_commit_ms += rows.timing.commit_ms;
      stats_.total_node_commit_ahead_ms += rows.timing.commit_ahead_ms;
      stats_.total_node_first_piece_ms += rows.timing.first_piece_ms;
      stats_.total_first_piece_ms +=
          std::chrono::duration<double, std::milli>(pieces.first_matched - start).count();
    }
    core::BandResult result;
    result.device_ms = rows.device_ms;
    result.row_work = std::move(rows.row_work);
    return result;
  }
}

MpiLinkStats MpiTracer::link_stats() const {
  std::lock_guard lock(stats_mutex_);
  return stats_;
}

}  // namespace cohort::tracers
