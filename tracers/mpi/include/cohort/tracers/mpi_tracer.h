// A tracer on rank 0 whose bands render on another MPI rank, a `cohort node` (docs/cluster.md). To the
// Renderer and its balancer it is one device whose cost includes the network round trip.
//
// apply() forwards the commit (records, or a whole scene; a full resync to the scene the node loaded
// itself sends only the camera and the records on top) with a non-blocking send and returns at once.
// render_band() sends the band job and waits for the rows, at most the band timeout; a node that
// stalls, fails or sends a malformed answer makes it throw, so the Renderer's recovery re-renders the
// rows on the other tracers and the frame is delivered. A late answer is
// recognised by its job id and dropped; until it has come, the node is sent no band (its bands fail at
// once), so a stalled or lost node costs one late frame. A node joins once per run (its hello is
// remembered), so a later tracer for the same rank starts at once; the MPI session's end (program
// exit) tells every node to leave.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "cohort/core/tracer.h"
#include "cohort/tracers/mpi_link.h"
#include "cohort/tracers/mpi_node_port.h"
#include "cohort/tracers/mpi_wire.h"

namespace cohort::tracers {

struct MpiTracerOptions {
  // The slot, mpi:N: world rank N under `mpirun -np`, or a node that joins through rank 0's port (NodePort)
  // and asks for N. A slot whose world rank died is served by the next node that joins it, where a port is open.
  int rank = 1;
  // A band that has not come back after this long (plus four times the last round trip; ten times as long
  // for the first band after a full resync, which the node spends building its BVHs) fails. A late
  // answer still teaches the next deadline how long the node's bands take.
  std::chrono::milliseconds band_timeout{2000};
  // How long the constructor waits for the node's hello (it loads its scene first).
  std::chrono::milliseconds hello_timeout{120000};
  // A band's rows travel in this many pieces (fewer when it has fewer rows; at most wire::kMaxPieces):
  // the node sends each as soon as it is on its host while it renders the next, and this tracer
  // receives each straight into its target rows, so the round trip is the node's render plus one
  // piece's way back instead of the whole band's. With jobs ahead (below) that way back is off the node's
  // path and only the last piece's download is on it. 2 measured best with the CUDA megakernel; since the
  // wavefront every piece restarts its lanes (about 0.15 ms at 1080p on an H100), and one piece is best:
  // 96 % of the in-process two-GPU rate at 1080p against 89 % with 2 (docs/cluster.md).
  uint32_t pieces = 1;
  // Forward the commits the core submits while a band renders right after that band's job
  // (Tracer::takes_commits_ahead), so that the node applies them once its band is rendered, before the
  // next job comes, instead of with it. COHORT_MPI_COMMITS_AHEAD=0 turns it off (for comparison).
  bool commits_ahead = true;
  // Send the next frame's job to the node as soon as the core announces it (Tracer::takes_jobs_ahead),
  // with the rows of the band in flight, so that the node renders it right after that band instead of
  // idling until the frame's job comes; that job then adopts the rows rendered ahead where they are its
  // own (docs/cluster.md, "Jobs ahead"). COHORT_MPI_JOBS_AHEAD=0 turns it off (for comparison).
  bool jobs_ahead = true;
  // A node that joins a running session takes its full resync on the side: the slot stays away (no rows)
  // until the node has applied it, rendered a warm-up band and said it is ready (protocol 10), at most ten
  // times the band timeout, so that its first band is an ordinary one instead of a late frame
  // (docs/cluster.md, "Joining a running session"). COHORT_MPI_WARM_UP=0 turns it off (for comparison):
  // its first band then waits for the resync, as before.
  bool warm_up = true;
};

// What crossed the wire for this tracer, for `cohort bench devices` and the logs.
struct MpiLinkStats {
  uint64_t bands = 0;
  // The totals below are over the bands in steady state: the first band after a full resync (whose
  // round trip holds the node applying the whole scene and building its BVHs) is counted apart.
  uint64_t steady_bands = 0;
  uint64_t resync_bands = 0;
  double total_resync_round_trip_ms = 0.0;
  uint64_t bytes_sent = 0, bytes_received = 0;  // whole messages, headers included
  uint64_t last_band_bytes_sent = 0, last_band_bytes_received = 0;  // commit(s) and job since the last band, and its rows
  double last_round_trip_ms = 0.0;  // job sent -> rows received
  double last_node_ms = 0.0;        // the node's own time for the band (render, and sending the pieces)
  double total_round_trip_ms = 0.0;
  double total_node_ms = 0.0;
  // Where the round trip goes, summed over bands (divide by `bands`): on the node, its tracers'
  // render_band calls (GPU: kernel, download into its band buffer and waits), of that what the tracers
  // measured themselves (GPU: kernel time), and its MPI calls; on rank 0, job sent -> first piece
  // matched. round trip - node time is the commits' and job's way out, the node applying the commits,
  // and the last piece's and band_rows' way back.
  double total_node_render_ms = 0.0;
  double total_node_tracer_ms = 0.0;
  double total_node_send_ms = 0.0;
  // On the node, decoding and applying commits (not in node time): those it applied when the next job
  // was already waiting (in the round trip's way), and those applied before it came (hidden).
  double total_node_commit_ms = 0.0;
  double total_node_commit_ahead_ms = 0.0;
  uint64_t commits_ahead = 0;  // commits forwarded while a band rendered, after its job
  double total_first_piece_ms = 0.0;
  double total_node_first_piece_ms = 0.0;  // on the node: job taken -> first piece posted
  // Jobs ahead (protocol 7): sent, adopted by the frame's job, dropped (another frame came, a commit
  // came between, no rows in common, or the band before failed); rows rendered ahead that the frame's
  // job did not take; on the node, summed over the steady bands: its idle time waiting for a job, and of
  // its time the part it rendered before the job came.
  uint64_t jobs_ahead = 0, adopted = 0, dropped_ahead = 0;
  uint64_t rows_ahead_unused = 0;
  uint64_t rows_beyond_ahead = 0;  // rows of adopting bands that the job ahead had not covered (rendered after)
  double total_node_idle_ms = 0.0;
  double total_node_ahead_ms = 0.0;
  // On rank 0: how long after its band's job each job ahead left (the core's announcement of the next
  // frame: its turnaround of the frame before, e.g. merge and blend on the host, came first before
  // FramePipeline's prepare_next), summed over the jobs ahead; and the bands that came back before the
  // next frame was announced, so that no job went ahead of the next frame (its node then waited for the
  // frame's job; counted when that frame's band comes, so the run's last band is not).
  double total_ahead_sent_after_ms = 0.0;
  uint64_t bands_back_before_announcement = 0;
  uint32_t last_pieces = 0;
  uint64_t stale_answers = 0;       // late answers to jobs that had timed out, dropped
  uint64_t refused_messages = 0;    // malformed answers, refused
  // Nodes that took this slot through rank 0's port, and the last one's time from its connect to its
  // first band delivered (greeting, the full resync with its BVH build, the band).
  uint64_t nodes_joined = 0;
  double last_join_to_first_band_ms = 0.0;
  // Protocol 10: the last node that joined a running session took its full resync on the side: from its
  // connect to its ready, and what it said it took (applying the resync; its warm-up band). Nodes that did
  // not say ready in time (let go).
  double last_join_to_ready_ms = 0.0;
  double last_ready_resync_ms = 0.0, last_ready_warm_ms = 0.0;
  uint64_t nodes_never_ready = 0;
};

class MpiTracer : public core::Tracer {
 public:
  // Joins the MPI session, waits for the node's hello and checks its version against this build's.
  // Throws NodeUnavailable when the rank does not exist, the node could not load its scene (its
  // file:line reason), or runs another Cohort version (both named).
  explicit MpiTracer(MpiTracerOptions options);
  ~MpiTracer() override;

  std::string name() const override;
  bool renders_on_gpu() const override { return gpu_; }
  // Its apply() only sends the commit on; the node applies it after the band it renders.
  bool takes_commits_ahead() const override { return options_.commits_ahead; }
  // It sends the announced next job to its node while its band renders (MpiTracerOptions::jobs_ahead).
  bool takes_jobs_ahead() const override { return options_.jobs_ahead; }
  void apply(const commit::CommitBuffer& commit) override;
  // A node that joined the slot has no scene: it needs a full resync before its first band. Asked for as
  // soon as one waits in the port of an away slot, so that the job that brings it (the away tracer's
  // commits on the side) lets apply() take the node and resync it at once, with a warm behind it.
  bool wants_full_resync() const override;
  // Not while its node has not answered its last band (stalled or dead), no node serves the slot yet, or
  // the node that took the slot has not said it is ready (it applies its full resync and renders a
  // warm-up band on the side, so that its first band is an ordinary one: docs/cluster.md).
  bool available() const override;
  // Away: reads whether its node has answered since (the late answer to its last band), or whether the
  // node that joined says it is ready; drops a newcomer that has not within ten times the band timeout.
  void while_away() override;
  // While the node that joined warms up: every frame, so that it takes rows the frame after it is ready.
  bool checks_in_every_frame() const override { return warming_.load(); }
  using core::Tracer::render_band;
  core::BandResult render_band(const core::BandJob& job, core::BandBuffer& target) override;

  MpiLinkStats link_stats() const;
  // What the node said it runs: its host and tracers.
  const std::string& node_description() const { return description_; }

 private:
  void send(int kind, uint64_t sequence, const std::vector<uint8_t>& payload);
  void adopt(const wire::Hello& hello);
  // World rank N's hello, checked (NodeUnavailable when it cannot serve).
  void greet_world_rank();
  // From now on, `node` (greeted by the port) serves this slot; the one before, if any, is let go.
  // With `warm_up` (a node that joins a running session, not one there before the first frame) it stays
  // away until it says it is ready: its full resync goes with a warm (send_warm).
  void take_node(const JoiningNode& node, bool warm_up);
  // Right behind the full resync to a node that joined: the warm (with the slot's last band, when there
  // was one, to render once for nothing); the node answers ready.
  void send_warm();
  // Reads the node's ready, waiting at most until `deadline`; true once it is ready (no longer away). A
  // ready that says its scene is behind asks for another full resync (and warm).
  bool take_ready(MpiClock::time_point deadline);
  // The node that joined has not said it is ready by its deadline: it is let go like a dead node, and the
  // slot is free for the next one.
  void give_up_warming();
  // Reads, without waiting, what the node sent since a band timed out; clears timed_out_job_ once the
  // answer to that band is among it.
  void take_late_answers();
  // The answer to the band that timed out has come: the node is back (no longer away), its slot is its own
  // again (no newcomer may take it), and its round trip teaches the next deadline. With stats_mutex_ held.
  void node_answered_again();
  // The answer to the current job has not come: its pieces already matched get a moment to land (they
  // write the target's rows), and the node is sent no band until it answers this one.
  [[noreturn]] void fail_timed_out(uint64_t id, MpiClock::time_point start, const core::BandJob& job);
  // Between the polls of band `job`: once the core announces the next frame's job, sends it to the node
  // as a job ahead with this band's rows (the commits published before it go first).
  void send_job_ahead(const core::BandJob& job, const core::BandBuffer& target, MpiClock::time_point band_start);
  // A job sent ahead, until the next band adopts it or drops it.
  struct JobAhead {
    uint64_t id = 0;
    wire::BandRequest request;
    uint64_t commits_at = 0;  // commits_sent_ when it left: a commit after it changes the scene it saw
    uint64_t sent_in_band = 0;
  };
  // Whether `job` into `target` may take the rows `ahead` rendered, or why not.
  std::string why_not_adopt(const JobAhead& ahead, const core::BandJob& job, const core::BandBuffer& target) const;

  MpiTracerOptions options_;
  int peer_ = -1;                 // the session's peer of the node serving the slot; -1: none yet
  NodePort* port_ = nullptr;      // rank 0's port for joining nodes, when open
  std::atomic<bool> wants_resync_{false};
  // Set while the slot's node cannot take a band: its last band timed out and it has not answered since,
  // or no node has joined; read by available() on the core thread.
  std::atomic<bool> away_{false};
  // Set from the warm's send until the node that joined says it is ready (away_ all the while); read by
  // checks_in_every_frame() on the core thread. warm_pending_: the next full resync goes with a warm.
  std::atomic<bool> warming_{false};
  bool warm_pending_ = false;
  uint64_t warm_id_ = 0;                   // the warm's sequence, which its ready answers
  MpiClock::time_point warm_deadline_{};   // the first warm's send + ten times the band timeout
  std::optional<wire::BandRequest> last_request_;  // the last band sent to the slot: a newcomer's warm-up band
  MpiClock::time_point joined_at_{};
  bool first_band_after_join_ = false;
  std::string description_;
  bool gpu_ = false;
  uint64_t node_fingerprint_ = 0;  // of the scene the node holds from its own load; 0: none usable
  std::shared_ptr<const commit::TracerScene> hashed_scene_;  // kept alive, so the pointer means this scene
  uint64_t hashed_fingerprint_ = 0;
  bool node_needs_resync_ = false;
  bool after_full_resync_ = false;
  uint64_t full_resyncs_sent_ = 0;
  bool in_band_ = false;             // inside render_band, its job sent: apply() is a commit ahead
  uint32_t band_frame_ = 0;          // the frame index of the last band sent
  bool commits_ahead_of_band_ = false;  // commits went ahead of the node since the last band's job
  bool back_unannounced_ = false;       // the last band came back with no job ahead sent (none announced)
  uint64_t commits_sent_ = 0;         // commits (and full resyncs) sent to the node so far
  std::optional<JobAhead> ahead_;
  uint64_t timed_out_job_ = 0;
  MpiClock::time_point timed_out_start_{};
  std::string node_failure_;
  mutable std::mutex stats_mutex_;
  MpiLinkStats stats_;
  uint64_t pending_sent_ = 0;
};

class NodeUnavailable : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace cohort::tracers
