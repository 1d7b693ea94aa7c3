// `cohort node`: one MPI rank above 0 serving rank 0's remote tracer mpi:RANK (docs/cluster.md). It
// loads the same map or scene pack as rank 0, so that the first full resync costs only a camera, holds
// its own tracers and renders the bands it is sent. Started by mpirun next to `cohort render` on rank 0:
//
//   mpirun -np 1 cohort render MAP --tracers embree,mpi:1 : -np 1 cohort node MAP --tracers embree
//
// or on its own, joining a running rank 0 through its port (docs/cluster.md, "Joining a running session"):
//
//   mpiexec -np 1 cohort render MAP --tracers embree,mpi:1 --node-port PORT_FILE
//   mpiexec -np 1 cohort node MAP --join PORT_FILE --as 1
#include <iostream>

#include <spdlog/spdlog.h>

#include "cohort/core/world_sync.h"
#include "cohort/tracers/tracer_registry.h"
#include "commands.h"
#include "default_map.h"
#include "render_scene_source.h"
#ifdef COHORT_HAVE_MPI
#include "cohort/tracers/mpi_link.h"
#include "cohort/tracers/mpi_node.h"
#endif

namespace cohort::app {

namespace {

struct NodeArgs {
  std::string map;
  std::vector<std::string> bases;
  std::string tracers = "embree";
  int width = 0, height = 0;
  double time = 0.0;
  std::string announced_version;
  int stall_frame = -1, stall_ms = 0, die_frame = -1, short_piece_frame = -1, band_delay_ms = 0, resync_delay_ms = 0;
  double row_delay_ms = 0.0;
  int idle_timeout_s = 600;
  std::string join;  // rank 0's port file: join its running session instead of being one of mpirun's ranks
  int join_as = 0;
  int join_timeout_s = 60;
};

#ifdef COHORT_HAVE_MPI
int run_node_command(const NodeArgs& a) {
  tracers::NodeOptions options;
  options.tracers_text = a.tracers;
  options.announced_version = a.announced_version;
  options.stall_frame = a.stall_frame;
  options.stall_ms = a.stall_ms;
  options.die_frame = a.die_frame;
  options.short_piece_frame = a.short_piece_frame;
  options.band_delay_ms = a.band_delay_ms;
  options.row_delay_ms = a.row_delay_ms;
  options.resync_delay_ms = a.resync_delay_ms;
  options.idle_timeout = std::chrono::seconds(a.idle_timeout_s);
  std::vector<std::unique_ptr<core::Tracer>> tracers;
  try {
    if (!a.map.empty()) {
      // The scene as rank 0's first full resync has it: a pack's compiled scene, or the map compiled by
      // WorldSync at --time (the camera is not compared).
      RenderScene scene = load_render_scene(a.map, bases_or_test_map(a.bases));
      options.scene_name = scene.name;
      if (scene.world) {
        core::WorldSyncOptions sync_options;
        if (a.width > 0) sync_options.width = uint32_t(a.width);
        if (a.height > 0) sync_options.height = uint32_t(a.height);
        core::WorldSync sync(*scene.world, sync_options);
        sync.set_time(a.time);
        options.scene = sync.snapshot();
      } else {
        options.scene = scene.tracer_scene;
      }
    }
    tracers = tracers::make_tracers(a.tracers);
  } catch (const std::exception& e) {
    options.load_error = e.what();
  }
  if (!a.join.empty()) {
    try {
      tracers::join_session(a.join, a.join_as, std::chrono::seconds(a.join_timeout_s));
    } catch (const std::exception& e) {
      spdlog::error("node: {}", e.what());
      tracers::MpiSession::get().finalize();
      return 1;
    }
  }
  int code = tracers::run_node(std::move(tracers), options);
  tracers::MpiSession::get().finalize();
  return code;
}
#endif

}  // namespace

void add_node_command(CLI::App& app, int& exit_code) {
  auto* cmd = app.add_subcommand("node", "Serve rank 0's remote tracer mpi:RANK on this MPI rank (start under mpirun "
                                         "with `cohort render` on rank 0; docs/cluster.md)");
  auto a = std::make_shared<NodeArgs>();
  cmd->add_option("map", a->map, "the map or scene pack rank 0 renders (loaded here so that it need not travel; "
                                 "without one, rank 0 sends the whole scene)");
  cmd->add_option("--base", a->bases, "extra game folder(s) to search (loose files and .pk4s)");
  cmd->add_option("--tracers", a->tracers, "this node's tracers: embree, opencl[:N], cuda[:N], all; several split "
                                           "the node's band by their speed (`cohort devices` lists them)")
      ->capture_default_str();
  cmd->add_option("--time", a->time, "game time rank 0 renders frame 0 at (its --time), for the materials")
      ->capture_default_str();
  cmd->add_option("--idle-timeout", a->idle_timeout_s, "leave when rank 0 has been silent this many seconds")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  cmd->add_option("--join", a->join, "join rank 0's running session through the port named in this file (rank 0's "
                                     "--node-port), started on its own instead of under rank 0's mpirun")
      ->check(CLI::NonexistentPath | CLI::ExistingFile);
  cmd->add_option("--as", a->join_as, "with --join: the slot to serve, mpi:N (0: the first free one)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--join-timeout", a->join_timeout_s, "with --join: leave when the port file has not appeared or "
                                                       "the connection has not been made within this many seconds")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  // Test hooks, hidden from the help.
  cmd->add_option("--announce-version", a->announced_version, "")->group("");
  cmd->add_option("--stall-frame", a->stall_frame, "")->group("");
  cmd->add_option("--stall-ms", a->stall_ms, "")->group("");
  cmd->add_option("--die-frame", a->die_frame, "")->group("");
  cmd->add_option("--short-piece-frame", a->short_piece_frame, "")->group("");
  cmd->add_option("--band-delay-ms", a->band_delay_ms, "")->group("");
  cmd->add_option("--row-delay-ms", a->row_delay_ms, "")->group("");
  cmd->add_option("--resync-delay-ms", a->resync_delay_ms, "")->group("");
  cmd->callback([a, &exit_code] {
#ifdef COHORT_HAVE_MPI
    exit_code = run_node_command(*a);
#else
    std::cerr << "cohort node: this build has no MPI (install libopenmpi-dev and reconfigure; docs/cluster.md)\n";
    exit_code = kExitUnavailable;
#endif
  });
}

}  // namespace cohort::app
