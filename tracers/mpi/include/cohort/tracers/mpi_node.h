// The node side of a remote tracer (`cohort node`, docs/cluster.md): a rank above 0 that holds its own
// tracers, each with its own TracerScene, applies the commits rank 0 forwards and renders the bands it
// is sent. A node with several tracers splits its band among them in proportion to the speed each
// showed (smoothed over bands), in the balancer module's 4-row units (balance::bands_from_shares).
// Every message is checked before use: a malformed one is refused with a logged reason and, for a
// commit, the node asks for a full resync instead of rendering a stale scene.
#pragma once

#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include "cohort/commit/tracer_scene.h"
#include "cohort/core/tracer.h"

namespace cohort::tracers {

struct NodeOptions {
  std::string tracers_text;  // as named on the command line, for rank 0's log
  // The scene this node loaded itself (a full resync to it costs rank 0 only the camera), or null.
  std::shared_ptr<const commit::TracerScene> scene;
  std::string scene_name;
  // Non-empty: the node could not load its scene (file:line: problem) or open its tracers; it reports
  // this to rank 0 and leaves.
  std::string load_error;
  // Tests: the version announced in the hello instead of this build's.
  std::string announced_version;
  // Tests: before rendering the band of this frame index, sleep stall_ms once (a stalled node).
  int stall_frame = -1;
  int stall_ms = 0;
  // Tests: every band takes this much longer, counted in the node's time (a slow node: rank 0's next
  // commits are submitted while it renders, so they travel ahead of their job).
  int band_delay_ms = 0;
  // Tests: every row rendered takes this much longer (a node whose time grows with its rows, so that
  // rank 0's balancer moves rows between nodes of different speeds; or a CPU node timed like a GPU one),
  // each piece before it is rendered, so that the pieces still leave one by one.
  double row_delay_ms = 0.0;
  // Tests: before rendering the band of this frame index, the process kills itself (a lost node).
  int die_frame = -1;
  // Tests: applying a full resync takes this much longer (a large scene's upload and BVH build, on the
  // tests' small map).
  int resync_delay_ms = 0;
  // Tests: piece 0 of this frame index's band goes out a byte short (a malformed piece).
  int short_piece_frame = -1;
  // Rank 0 silent this long: the node leaves.
  std::chrono::seconds idle_timeout{600};
};

// A node started on its own (its own mpiexec, any host) joins rank 0's running session through the port
// rank 0 wrote to `port_file` (`cohort render --node-port FILE`: "HOST PORT"): waits for the file,
// connects, and joins (MPI_Comm_join over that connection). Every wait is bounded by `timeout`: past it
// an error says which (a join that never returns cannot be cancelled: the process ends). run_node() then
// asks for `slot` (mpi:N; 0: the first free one) before its hello. Call before any other MPI use.
void join_session(const std::string& port_file, int slot, std::chrono::seconds timeout);

// Serves rank 0 until it says shutdown; returns the process's exit code (0 after a clean shutdown).
// Call on a rank above 0; MPI stays initialized (MpiSession::finalize ends it).
int run_node(std::vector<std::unique_ptr<core::Tracer>> tracers, const NodeOptions& options);

}  // namespace cohort::tracers
