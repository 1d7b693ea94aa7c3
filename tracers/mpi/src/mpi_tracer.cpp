#include "cohort/tracers/mpi_tracer.h"

#include <algorithm>
#include <atomic>
#include <cstring>
#include <functional>
#include <map>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "cohort/tracers/mpi_link.h"
#include "cohort/tracers/mpi_node_port.h"
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
  int peer = -1;
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

// The pieces of the current band: each one checked against the band (its tag names a job of this band,
// a piece and plane it asked for, its size that of its rows) and received straight into its rows of the
// target; anything else is dropped, and a piece of this band that does not fit makes the band fail when
// its band_rows comes. A band that adopts a job ahead takes that job's pieces (its rows, over the
// target's) and its own beyond them.
class BandPieces : public PieceSink {
 public:
  BandPieces(core::BandBuffer& target) : target_(target) {}
  // Pieces of job `job` over `rows`, in order, named 0, 1, ... on their tags.
  void expect(uint64_t job, const std::vector<wire::RowRange>& rows) {
    for (uint32_t i = 0; i < rows.size(); ++i) expected_.push_back({job, i, uint32_t(rows.size()), rows[i]});
    landed_.resize(expected_.size() * 2, false);
  }

  void* place(int tag, size_t size) override {
    bytes += size;
    if (first_matched == MpiClock::time_point{}) first_matched = MpiClock::now();
    wire::PieceTag piece;
    if (!wire::decode_piece_tag(tag, piece)) {
      ++refused;
      refuse(fmt::format("a message on tag {}, which is neither the control tag nor a piece's", tag));
      return nullptr;
    }
    const bool ours = std::any_of(expected_.begin(), expected_.end(), [&](const Expected& e) { return piece.of_job(e.job); });
    if (!ours) {
      ++stale;  // a piece of an earlier job's late answer, or of a job ahead that was dropped
      return nullptr;
    }
    const bool aux = piece.plane == wire::Plane::aux;
    const auto found = std::find_if(expected_.begin(), expected_.end(),
                                    [&](const Expected& e) { return piece.of_job(e.job) && piece.piece == e.piece; });
    if (found == expected_.end() || (aux && !target_.has_aux())) {
      ++refused;
      refuse(fmt::format("piece {}{} was not asked for", piece.piece, aux ? " (aux planes)" : ""));
      return nullptr;
    }
    const wire::RowRange rows = found->rows;
    const uint64_t expected = wire::piece_bytes(rows.end - rows.begin, uint32_t(target_.width()), target_.format(),
                                                piece.plane);
    if (size != expected) {
      ++refused;
      refuse(fmt::format("piece {} of {} ({}rows [{}, {})) has {} bytes; they are {}", piece.piece, found->of,
                         aux ? "aux texels of " : "", rows.begin, rows.end, size, expected));
      return nullptr;
    }
    const size_t bit = size_t(found - expected_.begin()) * 2 + uint32_t(piece.plane);
    if (landed_[bit]) {
      ++refused;
      refuse(fmt::format("piece {} of {}{} came twice", piece.piece, found->of, aux ? " (aux planes)" : ""));
      return nullptr;
    }
    landed_[bit] = true;
    if (aux) return target_.aux_row(int(rows.begin));
    return target_.row(int(rows.begin));
  }

  // Why the rows of job `job` cannot be taken (a piece refused, or one of its pieces missing), or empty.
  std::string problem(uint64_t job) const {
    if (!problem_.empty()) return problem_;
    for (size_t i = 0; i < expected_.size(); ++i) {
      if (expected_[i].job != job) continue;
      for (uint32_t plane = 0; plane < (target_.has_aux() ? 2u : 1u); ++plane)
        if (!landed_[i * 2 + plane])
          return fmt::format("piece {} of {}{} never came", expected_[i].piece, expected_[i].of,
                             plane == 1 ? " (aux planes)" : "");
    }
    return {};
  }

  uint64_t bytes = 0, refused = 0, stale = 0;
  MpiClock::time_point first_matched{};

 private:
  struct Expected {
    uint64_t job;
    uint32_t piece, of;
    wire::RowRange rows;
  };
  void refuse(std::string why) {
    if (problem_.empty()) problem_ = std::move(why);
  }
  core::BandBuffer& target_;
  std::vector<Expected> expected_;
  std::vector<bool> landed_;
  std::string problem_;
};

std::vector<wire::RowRange> band_piece_rows(uint32_t row_begin, uint32_t row_end, uint32_t pieces) {
  std::vector<wire::RowRange> rows;
  for (uint32_t i = 0; i < pieces; ++i) rows.push_back(wire::piece_rows(row_begin, row_end, pieces, i));
  return rows;
}

// Band job ids are unique over the run, so that a late answer to an earlier tracer's job is never
// taken for the current one.
std::atomic<uint64_t> next_band_job{1};

// A new job id whose piece tags differ from those of `other` (a job ahead whose pieces are still coming).
uint64_t new_band_job(uint64_t other = 0) {
  for (;;) {
    const uint64_t id = next_band_job++;
    if (other == 0 || id % wire::kPieceJobSlots != other % wire::kPieceJobSlots) return id;
  }
}

// Whether two jobs render the same frame: all but their rows (and where the core takes them from).
bool same_frame(const core::BandJob& a, const core::BandJob& b) {
  KFrameParams pa = a.params, pb = b.params;
  pa.row_begin = pb.row_begin = pa.row_end = pb.row_end = 0;
  return std::memcmp(&pa, &pb, sizeof pa) == 0 && std::memcmp(&a.camera, &b.camera, sizeof a.camera) == 0 &&
         std::memcmp(&a.previous_camera, &b.previous_camera, sizeof a.previous_camera) == 0;
}
}  // namespace

MpiTracer::MpiTracer(MpiTracerOptions options) : options_(options) {
  MpiSession& mpi = MpiSession::get();
  mpi.set_farewell(wire::frame_message(wire::Kind::shutdown, 0, {}));
  if (mpi.rank() != 0)
    throw NodeUnavailable(fmt::format("mpi:{}: remote tracers are driven from rank 0; this process is rank {}",
                                      options_.rank, mpi.rank()));
  port_ = NodePort::get();
  if (options_.rank < 1 || (options_.rank >= mpi.size() && !port_))
    throw NodeUnavailable(fmt::format("mpi:{}: no such rank: the MPI world has {} rank(s) (launch under mpirun, "
                                      "with `cohort node` on ranks 1 and up, or open a port for nodes to join: "
                                      "--node-port; docs/cluster.md)",
                                      options_.rank, mpi.size()));
  if (port_) port_->serve_slot(options_.rank);
  {
    std::lock_guard lock(joined_mutex);
    auto known = joined_nodes().find(options_.rank);
    if (known != joined_nodes().end()) {
      peer_ = known->second.peer;
      adopt(known->second.hello);
      if (port_) port_->set_busy(options_.rank, true);
      return;
    }
  }
  if (options_.rank < mpi.size()) {
    greet_world_rank();
    if (port_) port_->set_busy(options_.rank, true);
    return;
  }
  // A slot served through the port: its node may be joining still (at most until the port's first wait).
  if (std::optional<JoiningNode> node = port_->wait_for(options_.rank, port_->first_deadline())) {
    take_node(*node, false);  // before the first frame: its first band comes with the session's first resync
  } else {
    away_.store(true);
    spdlog::info("mpi:{}: no node has joined yet; its rows go to the others until one does (cohort node MAP --join {} "
                 "--as {})", options_.rank, port_->path(), options_.rank);
  }
}

void MpiTracer::greet_world_rank() {
  MpiSession& mpi = MpiSession::get();
  const int peer = options_.rank;
  const auto deadline = MpiClock::now() + options_.hello_timeout;
  for (;;) {
    std::optional<std::vector<uint8_t>> bytes = mpi.receive(peer, deadline);
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
      mpi.released(peer);  // it has left
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
      mpi.released(peer);
      mpi.send(peer, wire::frame_message(wire::Kind::refuse, 0, wire::encode_text(std::string("malformed hello: ") + e.what())));
      throw NodeUnavailable(fmt::format("mpi:{}: refused the node's malformed hello: {}", options_.rank, e.what()));
    }
    if (const std::string why = wire::version_mismatch(hello, options_.rank); !why.empty()) {
      mpi.send(peer, wire::frame_message(wire::Kind::refuse, 0, wire::encode_text(why)));
      mpi.released(peer);
      mpi.flush_sends(peer, MpiClock::now() + std::chrono::seconds(1));
      throw NodeUnavailable("mpi:" + std::to_string(options_.rank) + ": " + why);
    }
    peer_ = peer;
    send(int(wire::Kind::welcome), 0, {});
    adopt(hello);
    {
      std::lock_guard lock(joined_mutex);
      joined_nodes()[options_.rank] = {hello, peer};
    }
    spdlog::info("mpi:{}: node joined ({})", options_.rank, description_);
    return;
  }
}

void MpiTracer::take_node(const JoiningNode& node, bool warm_up) {
  MpiSession& mpi = MpiSession::get();
  if (peer_ >= 0) {
    // The node it replaces stalled or died: nothing of it is read or sent again (a send to a dead process
    // crashes MPICH 5.0 under UCX); one that only stalled leaves after its --idle-timeout.
    mpi.abandon(peer_);
  }
  peer_ = node.peer;
  adopt(node.hello);
  {
    std::lock_guard lock(joined_mutex);
    joined_nodes()[options_.rank] = {node.hello, node.peer};
  }
  // A new node: nothing it had is known here. Its first commit must be a full resync, which the Renderer
  // sends with this tracer's next job (wants_full_resync).
  timed_out_job_ = 0;
  ahead_.reset();
  back_unannounced_ = commits_ahead_of_band_ = false;
  after_full_resync_ = false;
  node_needs_resync_ = true;
  node_failure_ = "a new node joined";
  wants_resync_.store(true);
  joined_at_ = node.connected;
  first_band_after_join_ = true;
  // Joining a running session, the node takes its full resync on the side and stays away until it says
  // it is ready: its first band would otherwise hold the frame while it applies the whole scene and builds
  // its BVHs (66 ms at 1080p on the large map, docs/cluster.md).
  warm_pending_ = warm_up;
  warming_.store(false);
  warm_deadline_ = {};
  away_.store(warm_up);
  {
    std::lock_guard lock(stats_mutex_);
    ++stats_.nodes_joined;
  }
  spdlog::info("mpi:{}: node joined through the port ({}); {}", options_.rank, description_,
               warm_up ? "it takes its full resync on the side and rows once it says it is ready"
                       : "it renders after a full resync");
}

void MpiTracer::send_warm() {
  wire::Warm warm;
  if (last_request_) {
    warm.has_job = true;
    warm.request = *last_request_;
    warm.request.pieces = 1;
    warm.request.ahead = false;
    warm.request.adopt = 0;
  }
  warm_id_ = new_band_job();
  send(int(wire::Kind::warm), warm_id_, wire::encode_warm(warm));
  warm_pending_ = false;
  if (warm_deadline_ == MpiClock::time_point{}) warm_deadline_ = MpiClock::now() + options_.band_timeout * 10;
  warming_.store(true);
}

bool MpiTracer::take_ready(MpiClock::time_point deadline) {
  MpiSession& mpi = MpiSession::get();
  while (warming_.load()) {
    DropPieces dropped;
    std::optional<std::vector<uint8_t>> bytes = mpi.receive(peer_, deadline, &dropped);
    std::lock_guard lock(stats_mutex_);
    stats_.bytes_received += dropped.bytes;
    if (!bytes) return false;
    stats_.bytes_received += bytes->size();
    wire::Ready ready;
    try {
      const wire::Message m = wire::parse_message(bytes->data(), bytes->size());
      if (m.kind != wire::Kind::ready || m.sequence != warm_id_) {
        spdlog::warn("mpi:{}: ignored a {} message from the node warming up", options_.rank, wire::to_string(m.kind));
        continue;
      }
      ready = wire::decode_ready(m.payload);
    } catch (const wire::WireError& e) {
      ++stats_.refused_messages;
      spdlog::warn("mpi:{}: refused a message: {}", options_.rank, e.what());
      continue;
    }
    warming_.store(false);
    if (!ready.failure.empty()) {
      // Its scene is behind (the resync was refused, or failed to apply): the whole scene goes again, with
      // another warm, under the same deadline.
      node_needs_resync_ = warm_pending_ = true;
      node_failure_ = ready.failure;
      node_fingerprint_ = 0;
      wants_resync_.store(true);
      spdlog::warn("mpi:{}: the node that joined is not ready: {}; sending it the whole scene again", options_.rank,
                   ready.failure);
      return false;
    }
    const double since_connect = ms_since(joined_at_);
    stats_.last_join_to_ready_ms = since_connect;
    stats_.last_ready_resync_ms = ready.resync_ms;
    stats_.last_ready_warm_ms = ready.warm_ms;
    after_full_resync_ = false;  // applied and warmed: its first band is an ordinary one
    away_.store(false);
    spdlog::info("mpi:{}: the node that joined is ready {:.0f} ms after it connected (full resync applied in {:.1f} ms, "
                 "warm-up band {:.1f} ms); it takes rows from the next frame", options_.rank, since_connect,
                 ready.resync_ms, ready.warm_ms);
    return true;
  }
  return !away_.load();
}

void MpiTracer::give_up_warming() {
  spdlog::warn("mpi:{}: the node that joined did not say it is ready within {} ms of its full resync (ten times the "
               "band timeout; {}); it is let go and the slot is free for another", options_.rank,
               options_.band_timeout.count() * 10,
               warm_pending_ ? "it said it was not: " + node_failure_ : "no answer to its warm");
  // As for a dead node: nothing of it is read or sent again; one that only stalled leaves after its --idle-timeout.
  MpiSession::get().abandon(peer_);
  peer_ = -1;
  {
    std::lock_guard lock(joined_mutex);
    joined_nodes().erase(options_.rank);
  }
  warming_.store(false);
  warm_pending_ = false;
  wants_resync_.store(false);
  node_needs_resync_ = false;
  first_band_after_join_ = false;
  away_.store(true);
  if (port_) port_->set_busy(options_.rank, false);
  std::lock_guard lock(stats_mutex_);
  ++stats_.nodes_never_ready;
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
    // Jobs ahead: the node's time includes what it rendered before the band's job came (ahead_ms), so
    // what lies beyond the node's time is the round trip less the part of it after the job came.
    spdlog::info("mpi:{}: the node idled {:.2f} ms a band waiting for a job; jobs ahead: {} sent, {} adopted by their "
                 "frame's band, {} dropped; {} row(s) rendered ahead for nothing, {} rendered after their job came "
                 "beyond the rows adopted; the node rendered {:.2f} ms a band before the band's job came, so {:.2f} ms "
                 "of the round trip lie beyond the node's time after it",
                 options_.rank, s.total_node_idle_ms / n, s.jobs_ahead, s.adopted, s.dropped_ahead,
                 s.rows_ahead_unused, s.rows_beyond_ahead, s.total_node_ahead_ms / n,
                 round_trip - (node - s.total_node_ahead_ms / n));
    if (s.jobs_ahead > 0)  // not where nothing is announced (`bench devices` renders without the pipeline)
      spdlog::info("mpi:{}: a job ahead left {:.2f} ms a band after its band's job (when the core announced the next "
                   "frame); {} band(s) came back before the next frame was announced, so that frame's job did not go ahead",
                   options_.rank, s.total_ahead_sent_after_ms / double(s.jobs_ahead),
                   s.bands_back_before_announcement);
  }
  if (s.nodes_joined > 0)
    spdlog::info("mpi:{}: {} node(s) joined through the port; the last delivered its first band {:.0f} ms after its "
                 "connect{}; {} let go for not saying ready in time", options_.rank, s.nodes_joined,
                 s.last_join_to_first_band_ms,
                 s.last_join_to_ready_ms > 0.0
                     ? fmt::format(" (ready after {:.0f} ms: full resync {:.1f} ms, warm-up band {:.1f} ms)",
                                   s.last_join_to_ready_ms, s.last_ready_resync_ms, s.last_ready_warm_ms)
                     : "",
                 s.nodes_never_ready);
  // The node stays for later tracers of this run; the session's end tells every node to leave.
  try {
    MpiSession& mpi = MpiSession::get();
    if (!mpi.finalized() && peer_ >= 0) mpi.flush_sends(peer_, MpiClock::now() + std::chrono::seconds(1));
  } catch (const std::exception& e) {
    spdlog::warn("mpi:{}: {}", options_.rank, e.what());
  }
}

std::string MpiTracer::name() const { return "mpi:" + std::to_string(options_.rank); }

bool MpiTracer::wants_full_resync() const {
  return wants_resync_.load() || (away_.load() && port_ && port_->waiting(options_.rank));
}

void MpiTracer::while_away() {
  // Asked for no band while away, it still gets its commits on its own thread: whether its node has answered
  // since, or the node that joined says it is ready, is read here, so that it takes rows again from the next frame.
  if (peer_ >= 0 && timed_out_job_ != 0) take_late_answers();
  if (peer_ >= 0 && (warming_.load() || warm_pending_)) {
    if (warming_.load()) take_ready(MpiClock::now());
    if ((warming_.load() || warm_pending_) && warm_deadline_ != MpiClock::time_point{} &&
        MpiClock::now() >= warm_deadline_)
      give_up_warming();
  }
}

bool MpiTracer::available() const { return !away_.load(); }

void MpiTracer::send(int kind, uint64_t sequence, const std::vector<uint8_t>& payload) {
  std::vector<uint8_t> message = wire::frame_message(wire::Kind(kind), sequence, payload);
  {
    std::lock_guard lock(stats_mutex_);
    stats_.bytes_sent += message.size();
    pending_sent_ += message.size();
  }
  MpiSession::get().send(peer_, std::move(message));
}

void MpiTracer::apply(const commit::CommitBuffer& commit) {
  if (!in_band_ && commit.is_full_resync() && port_) {
    // The resync asked for a node that joined an away slot (wants_full_resync): that node takes the slot
    // now and gets it, so that its next band is its first.
    if (std::optional<JoiningNode> node = port_->take(options_.rank)) take_node(*node, options_.warm_up);
  }
  if (peer_ < 0) return;  // no node yet: the one that joins gets a full resync
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
    ++commits_sent_;
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
  ++commits_sent_;
  node_needs_resync_ = false;
  wants_resync_.store(false);
  after_full_resync_ = true;
  ++full_resyncs_sent_;
  // Behind it, on the same ordered stream: the node answers once the resync is applied.
  if (warm_pending_) send_warm();
}

void MpiTracer::take_late_answers() {
  MpiSession& mpi = MpiSession::get();
  while (timed_out_job_ != 0) {
    DropPieces dropped;
    std::optional<std::vector<uint8_t>> bytes = mpi.receive(peer_, MpiClock::now(), &dropped);
    std::lock_guard lock(stats_mutex_);
    stats_.bytes_received += dropped.bytes;
    if (!bytes) return;
    stats_.bytes_received += bytes->size();
    try {
      const wire::Message m = wire::parse_message(bytes->data(), bytes->size());
      ++stats_.stale_answers;
      if ((m.kind == wire::Kind::band_rows || m.kind == wire::Kind::band_failed) && m.sequence == timed_out_job_) {
        node_answered_again();
        spdlog::info("mpi:{}: the node answered again, {:.0f} ms after its band was sent", options_.rank,
                     ms_since(timed_out_start_));
      }
    } catch (const wire::WireError& e) {
      ++stats_.refused_messages;
      spdlog::warn("mpi:{}: refused a message: {}", options_.rank, e.what());
    }
  }
}

void MpiTracer::node_answered_again() {
  stats_.last_round_trip_ms = std::max(stats_.last_round_trip_ms, ms_since(timed_out_start_));
  timed_out_job_ = 0;
  away_.store(false);
  if (port_) port_->set_busy(options_.rank, true);
}

void MpiTracer::fail_timed_out(uint64_t id, MpiClock::time_point start, const core::BandJob& job) {
  timed_out_job_ = id;
  timed_out_start_ = start;
  away_.store(true);  // asked for no band until it answers or a node takes its slot
  if (port_) port_->set_busy(options_.rank, false);  // a node may join this slot now
  // A piece matched before the deadline is being received into the target's rows, which the Renderer
  // now hands to the other tracers: let it land first (it is in flight; this takes microseconds).
  if (!MpiSession::get().settle_pieces(peer_, MpiClock::now() + std::chrono::milliseconds(500)))
    spdlog::warn("mpi:{}: a piece of rows [{}, {}) is still arriving after the band timed out", options_.rank,
                 job.params.row_begin, job.params.row_end);
  throw std::runtime_error(fmt::format("mpi:{}: no answer for rows [{}, {}) within {:.0f} ms (node stalled?)",
                                       options_.rank, job.params.row_begin, job.params.row_end, ms_since(start)));
}

std::string MpiTracer::why_not_adopt(const JobAhead& ahead, const core::BandJob& job,
                                     const core::BandBuffer& target) const {
  if (ahead.request.job.params.frame_index != job.params.frame_index) return "it was for another frame";
  if (!same_frame(ahead.request.job, job)) return "the frame's job differs from the one announced";
  if (ahead.commits_at != commits_sent_) return "a commit went to the node after it";
  if (ahead.request.format != target.format() || ahead.request.aux != target.has_aux() ||
      ahead.request.job.camera.width != uint32_t(target.width()))
    return "the band's format changed";
  if (!wire::rows_overlap({ahead.request.job.params.row_begin, ahead.request.job.params.row_end},
                          {job.params.row_begin, job.params.row_end}))
    return "it has no rows in common with the band";
  return {};
}

void MpiTracer::send_job_ahead(const core::BandJob& job, const core::BandBuffer& target,
                               MpiClock::time_point band_start) {
  if (ahead_ || job.params.row_end <= job.params.row_begin) return;
  const std::optional<core::BandJob> next = next_job_announced();
  if (!next || next->params.frame_index == job.params.frame_index) return;
  // What the core published before it announced the job belongs to that frame: it goes first.
  apply_commits_ahead();
  if (node_needs_resync_) return;
  JobAhead ahead;
  ahead.id = new_band_job();
  ahead.request.job = *next;
  ahead.request.job.keep_on_device = -1;
  ahead.request.job.params.row_begin = job.params.row_begin;  // the balancer's rows come with the frame's job
  ahead.request.job.params.row_end = job.params.row_end;
  ahead.request.format = target.format();
  ahead.request.aux = target.has_aux();
  ahead.request.pieces = wire::band_pieces(job.params.row_end - job.params.row_begin, options_.pieces);
  ahead.request.ahead = true;
  ahead.commits_at = commits_sent_;
  send(int(wire::Kind::band_job), ahead.id, wire::encode_band_request(ahead.request));
  ahead_ = std::move(ahead);
  std::lock_guard lock(stats_mutex_);
  ++stats_.jobs_ahead;
  stats_.total_ahead_sent_after_ms += ms_since(band_start);
}

core::BandResult MpiTracer::render_band(const core::BandJob& job, core::BandBuffer& target) {
  MpiSession& mpi = MpiSession::get();
  // The job ahead sent during the last band: this band adopts it, or it is dropped (its answer, when it
  // comes, is a stale one).
  std::optional<JobAhead> ahead = std::move(ahead_);
  ahead_.reset();
  auto drop_ahead = [&](const std::string& why) {
    if (!ahead) return;
    spdlog::debug("mpi:{}: dropped the job ahead {} (rows [{}, {}) of frame {}): {}", options_.rank, ahead->id,
                  ahead->request.job.params.row_begin, ahead->request.job.params.row_end,
                  ahead->request.job.params.frame_index, why);
    std::lock_guard lock(stats_mutex_);
    ++stats_.dropped_ahead;
    stats_.rows_ahead_unused += ahead->request.job.params.row_end - ahead->request.job.params.row_begin;
    ahead.reset();
  };
  if (port_) {
    // A node that joined this slot (free: its node had not answered, left, or never came) takes it over.
    if (std::optional<JoiningNode> node = port_->take(options_.rank)) {
      drop_ahead("a new node took the slot");
      take_node(*node, options_.warm_up);
    }
  }
  if (peer_ < 0)
    throw std::runtime_error(fmt::format("mpi:{}: no node serves this slot yet; its rows go to the others until one "
                                         "joins", options_.rank));
  if (wants_resync_.load())
    throw std::runtime_error(fmt::format("mpi:{}: the node that joined waits for its full resync (with the next "
                                         "frame); its rows go to the others", options_.rank));
  if (warming_.load()) {
    // Asked while it warms up: nobody else could take the rows (or it would be left out, away). It may
    // still say it is ready before its deadline; past that it is let go.
    take_ready(warm_deadline_);
    if (warming_.load()) {
      give_up_warming();
      throw std::runtime_error(fmt::format("mpi:{}: the node that joined did not say it is ready in time; its rows "
                                           "go to the others", options_.rank));
    }
  }
  if (warm_pending_)
    throw std::runtime_error(fmt::format("mpi:{}: the node that joined is not ready ({}); it gets the whole scene "
                                         "again", options_.rank, node_failure_));
  if (timed_out_job_ != 0) {
    // A node that has not answered its last band yet (stalled, or gone) is not sent another: its band
    // fails at once, so it costs one late frame, not one per frame, and it is back when it answers.
    take_late_answers();
    if (timed_out_job_ != 0) {
      drop_ahead("the node has not answered");
      throw std::runtime_error(fmt::format("mpi:{}: the node has not answered the band it was sent {:.0f} ms ago "
                                           "(stalled or gone); its rows go to the others", options_.rank,
                                           ms_since(timed_out_start_)));
    }
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
  if (back_unannounced_ && job.params.frame_index > band_frame_) {
    std::lock_guard lock(stats_mutex_);
    ++stats_.bands_back_before_announcement;
  }
  back_unannounced_ = false;
  commits_ahead_of_band_ = false;
  band_frame_ = job.params.frame_index;
  if (ahead) {
    if (const std::string why = why_not_adopt(*ahead, job, target); !why.empty()) drop_ahead(why);
  }
  const uint64_t resyncs_before = full_resyncs_sent_;
  const bool first_after_resync = after_full_resync_;
  const uint64_t id = new_band_job(ahead ? ahead->id : 0);
  wire::BandRequest request;
  request.job = job;
  request.job.keep_on_device = -1;  // rank 0's GPUs are not the node's: the rows travel
  request.format = target.format();
  request.aux = target.has_aux();
  // The rows travel as pieces, each received straight into its rows of the target. Adopting a job ahead,
  // its pieces (over its rows) and then one piece per run of the band's rows beyond them.
  BandPieces pieces(target);
  if (ahead) {
    const wire::RowRange ahead_rows{ahead->request.job.params.row_begin, ahead->request.job.params.row_end};
    const std::vector<wire::RowRange> beyond = wire::rows_beyond(ahead_rows, {job.params.row_begin, job.params.row_end});
    request.adopt = ahead->id;
    request.pieces = uint32_t(beyond.size());
    pieces.expect(ahead->id, band_piece_rows(ahead_rows.begin, ahead_rows.end, ahead->request.pieces));
    pieces.expect(id, beyond);
    std::lock_guard lock(stats_mutex_);
    for (const wire::RowRange& r : beyond) stats_.rows_beyond_ahead += r.end - r.begin;
    stats_.rows_ahead_unused += (ahead_rows.end - ahead_rows.begin) -
                                (std::min(ahead_rows.end, job.params.row_end) - std::max(ahead_rows.begin, job.params.row_begin));
  } else {
    request.pieces = wire::band_pieces(job.params.row_end - job.params.row_begin, options_.pieces);
    pieces.expect(id, band_piece_rows(job.params.row_begin, job.params.row_end, request.pieces));
  }
  const auto start = MpiClock::now();
  send(int(wire::Kind::band_job), id, wire::encode_band_request(request));
  last_request_ = request;
  // From here on, what the core submits goes to the node behind this job (Tracer::apply_commits_ahead,
  // between polls): the node applies it once this band is rendered, while rank 0 waits for the frame.
  // Once the core announces the next frame's job, that goes too (a job ahead, after its commits).
  in_band_ = true;
  struct LeaveBand {
    MpiTracer& tracer;
    uint64_t band;
    bool done = false;
    ~LeaveBand() {
      tracer.in_band_ = false;
      // A band that fails takes its job ahead with it (the node may have stalled, or failed under it).
      if (!done && tracer.ahead_ && tracer.ahead_->sent_in_band == band) {
        std::lock_guard lock(tracer.stats_mutex_);
        ++tracer.stats_.dropped_ahead;
        tracer.ahead_.reset();
      }
    }
  } leave_band{*this, id};
  const std::function<void()> between_polls = [&] {
    apply_commits_ahead();
    if (options_.jobs_ahead && !ahead_) {
      send_job_ahead(job, target, start);
      if (ahead_) ahead_->sent_in_band = id;
    }
  };
  double expected_ms;
  {
    std::lock_guard lock(stats_mutex_);
    expected_ms = stats_.last_round_trip_ms;
  }
  // The first band after a full resync also waits for the node to build its acceleration structures.
  const auto allowance = options_.band_timeout * (after_full_resync_ ? 10 : 1);
  const auto deadline = start + allowance + std::chrono::microseconds(int64_t(4000.0 * expected_ms));
  uint64_t counted_piece_bytes = 0;
  auto count_pieces = [&] {
    std::lock_guard lock(stats_mutex_);
    stats_.bytes_received += pieces.bytes - counted_piece_bytes;
    stats_.refused_messages += pieces.refused;
    stats_.stale_answers += pieces.stale;
    counted_piece_bytes = pieces.bytes;
    pieces.refused = pieces.stale = 0;
  };
  auto refuse = [&](const std::string& why) {
    std::lock_guard lock(stats_mutex_);
    ++stats_.refused_messages;
    return std::runtime_error(fmt::format("mpi:{}: refused the band's rows: {}", options_.rank, why));
  };
  bool ahead_closed = false;  // the adopted job ahead's band_rows has come, its pieces in place
  for (;;) {
    std::optional<std::vector<uint8_t>> bytes = mpi.receive(peer_, deadline, &pieces, between_polls);
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
    const bool of_ahead = ahead && header.sequence == ahead->id && !ahead_closed;
    if (header.sequence != id && !of_ahead) {  // the answer to a job that timed out before, or was dropped
      std::lock_guard lock(stats_mutex_);
      ++stats_.stale_answers;
      // A band that merely took longer than the timeout teaches the next deadline how long bands take.
      if (header.sequence == timed_out_job_) node_answered_again();
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
      if (of_ahead) {
        // The node answers this band too (it has nothing to adopt): that answer is dropped when it comes.
        throw std::runtime_error(fmt::format("mpi:{}: {} (rendering ahead)", options_.rank, failure.reason));
      }
      throw std::runtime_error(fmt::format("mpi:{}: {}", options_.rank, failure.reason));
    }
    wire::BandRows rows;
    try {
      rows = wire::decode_band_rows(payload, payload_size);
    } catch (const wire::WireError& e) {
      throw refuse(e.what());
    }
    const wire::BandRequest& asked = of_ahead ? ahead->request : request;
    if (rows.row_begin != asked.job.params.row_begin || rows.row_end != asked.job.params.row_end ||
        int(rows.width) != target.width() || rows.format != target.format() || rows.pieces != asked.pieces ||
        rows.aux != target.has_aux() || rows.adopted != asked.adopt)
      throw refuse(fmt::format("rows [{}, {}) of {} {} pixels in {} pieces{}{}, asked for [{}, {}) of {} {} in {}{}{}",
                               rows.row_begin, rows.row_end, rows.width, core::to_string(rows.format), rows.pieces,
                               rows.aux ? " with aux planes" : "",
                               rows.adopted ? fmt::format(" adopting job {}", rows.adopted) : "",
                               asked.job.params.row_begin, asked.job.params.row_end, target.width(),
                               core::to_string(target.format()), asked.pieces, target.has_aux() ? " with aux planes" : "",
                               asked.adopt ? fmt::format(" adopting job {}", asked.adopt) : ""));
    // Every piece matched before band_rows has landed (MpiSession::receive); one that was refused or
    // never came leaves rows unwritten: the band fails and the Renderer re-renders them elsewhere.
    if (const std::string problem = pieces.problem(header.sequence); !problem.empty())  // counted as it was refused
      throw std::runtime_error(fmt::format("mpi:{}: refused the band's rows: {}", options_.rank, problem));
    if (of_ahead) {
      ahead_closed = true;
      continue;
    }
    if (ahead && !ahead_closed) throw refuse(fmt::format("the band closed before the job ahead {} it adopts", ahead->id));
    const double round_trip = ms_since(start);
    if (full_resyncs_sent_ == resyncs_before) after_full_resync_ = false;  // not when one went ahead of the next band
    leave_band.done = true;
    if (first_band_after_join_) {
      first_band_after_join_ = false;
      const double since_connect = std::chrono::duration<double, std::milli>(MpiClock::now() - joined_at_).count();
      spdlog::info("mpi:{}: the node that joined delivered its first band (frame {}) {:.0f} ms after it connected",
                   options_.rank, job.params.frame_index, since_connect);
      std::lock_guard lock(stats_mutex_);
      stats_.last_join_to_first_band_ms = since_connect;
    }
    {
      std::lock_guard lock(stats_mutex_);
      ++stats_.bands;
      if (ahead) ++stats_.adopted;
      stats_.last_round_trip_ms = round_trip;
      stats_.last_node_ms = rows.timing.total_ms;
      stats_.last_pieces = ahead ? ahead->request.pieces : request.pieces;
      stats_.last_band_bytes_sent = pending_sent_;
      stats_.last_band_bytes_received = pieces.bytes + bytes->size();
      pending_sent_ = 0;
    }
    // The band is back: the next frame's job, when announced by now, still goes ahead of it.
    if (options_.jobs_ahead && !ahead_) {
      send_job_ahead(job, target, start);
      if (ahead_) ahead_->sent_in_band = id;
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
      stats_.total_node_idle_ms += rows.timing.idle_ms;
      stats_.total_node_ahead_ms += rows.timing.ahead_ms;
      back_unannounced_ = options_.jobs_ahead && !ahead_;  // counted when a later frame's band comes
      stats_.total_first_piece_ms +=
          std::chrono::duration<double, std::milli>(pieces.first_matched - start).count();
    }
    core::BandResult result;
    result.device_ms = rows.device_ms;
    result.row_work = std::move(rows.row_work);
    // Begun ahead of its job, the band cost the node its head start too: the balancer divides rows by the
    // round trip as if the node had begun at the job, not by the shorter wait rank 0 saw.
    if (ahead) result.balance_ms = round_trip + rows.timing.ahead_ms;
    return result;
  }
}

MpiLinkStats MpiTracer::link_stats() const {
  std::lock_guard lock(stats_mutex_);
  return stats_;
}

}  // namespace cohort::tracers
