// The remote tracer against a real node over MPI, with messages a broken or hostile peer could send
// (run by run_cluster.py's `protocol` case under mpiexec with 2 ranks). Rank 1 is a node with an Embree
// tracer and no scene of its own; rank 0 drives an MpiTracer and checks, printing one line per step:
//  - a full scene travels and the node's rows equal a local Embree tracer's, byte for byte;
//  - garbage (bad magic) is refused by the node and the next band still renders;
//  - a well-framed commit with a corrupt payload is refused, never applied: the node's next band fails
//    asking for a full resync, records on top are refused, and a full resync brings it back, its
//    rows again equal to the local tracer's;
//  - a band asked of rows outside the frame is refused with the reason;
//  - a band that adopts a job ahead the node never rendered (protocol 7) is refused with the reason.
// Exit status 0 when every check holds.
#include <cstdio>
#include <cstring>
#include <functional>
#include <optional>
#include <string>

#include <spdlog/spdlog.h>

#include "cohort/core/gpu_scene.h"
#include "cohort/core/view.h"
#include "cohort/core/frame_defaults.h"
#include "cohort/test_support/test_scenes.h"
#include "cohort/tracers/mpi_link.h"
#include "cohort/tracers/mpi_node.h"
#include "cohort/tracers/mpi_tracer.h"
#include "cohort/tracers/mpi_wire.h"
#include "cohort/tracers/tracer_registry.h"

using namespace cohort;
namespace wire = cohort::tracers::wire;

namespace {

int failures = 0;

void check(bool ok, const std::string& what) {
  std::printf("%s: %s\n", ok ? "ok" : "FAILED", what.c_str());
  std::fflush(stdout);
  if (!ok) ++failures;
}

std::string thrown(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

core::BandJob band_job(int width, int height, uint32_t begin, uint32_t end) {
  core::BandJob job;
  job.camera = core::make_camera({-190, -130, 120}, {35.0f, 20.0f}, 90.0f, width, height);
  job.params = core::default_frame_params();
  job.params.spp = 2;
  job.params.frame_index = 3;
  job.params.row_begin = begin;
  job.params.row_end = end;
  return job;
}

bool same_rows(const core::BandBuffer& a, const core::BandBuffer& b, int begin, int end) {
  for (int y = begin; y < end; ++y)
    if (std::memcmp(a.row(y), b.row(y), a.row_bytes()) != 0) return false;
  return true;
}

int rank0() {
  const int w = 48, h = 32;
  auto scene = std::make_shared<commit::TracerScene>(core::compile_scene(test::test_room()).tracer_scene);
  const commit::CommitBuffer full = commit::CommitBuffer::full(scene, 1);
  auto local = tracers::make_tracers("embree");
  local.front()->apply(full);
  core::BandBuffer expected(w, h, core::BandFormat::rgb16f);
  local.front()->render_band(band_job(w, h, 0, h), expected);

  tracers::MpiTracerOptions options;
  options.rank = 1;
  options.band_timeout = std::chrono::milliseconds(5000);
  tracers::MpiTracer remote(options);
  core::BandBuffer got(w, h, core::BandFormat::rgb16f);
  remote.apply(full);
  remote.render_band(band_job(w, h, 8, 24), got);
  check(same_rows(got, expected, 8, 24), "a whole scene travels; rows [8, 24) equal the local Embree tracer's");

  tracers::MpiSession& mpi = tracers::MpiSession::get();
  std::vector<uint8_t> garbage(64, 0xab);
  mpi.send(1, garbage);
  core::BandBuffer after_garbage(w, h, core::BandFormat::rgb16f);
  const std::string garbage_error = thrown([&] { remote.render_band(band_job(w, h, 0, 16), after_garbage); });
  check(garbage_error.empty() && same_rows(after_garbage, expected, 0, 16),
        "garbage (bad magic) is refused by the node and the next band renders" +
            (garbage_error.empty() ? std::string() : ": " + garbage_error));

  // A commit whose payload is cut short: framed correctly, refused by the decoder.
  commit::CommitBuffer move;
  KInstance moved = scene->instances.back();
  moved.object_to_world[3] += 1000.0f;
  move.set_instance(uint32_t(scene->instances.size() - 1), moved);
  move.set_frame(2);
  std::vector<uint8_t> cut = wire::encode_commit(move);
  cut.resize(cut.size() / 2);
  mpi.send(1, wire::frame_message(wire::Kind::commit, 2, cut));
  core::BandBuffer stale(w, h, core::BandFormat::rgb16f);
  const std::string refused = thrown([&] { remote.render_band(band_job(w, h, 0, h), stale); });
  check(refused.find("needs a full resync") != std::string::npos || refused.find("behind") != std::string::npos,
        "a truncated commit is refused and the node's band asks for a full resync: " + refused);
  const std::string records_refused = thrown([&] { remote.apply(move); });
  check(!records_refused.empty(), "records on top of the refused commit are not sent: " + records_refused);

  remote.apply(full);
  core::BandBuffer recovered(w, h, core::BandFormat::rgb16f);
  const std::string recovery_error = thrown([&] { remote.render_band(band_job(w, h, 0, h), recovered); });
  check(recovery_error.empty() && same_rows(recovered, expected, 0, h),
        "a full resync brings the node back: its rows equal the local tracer's again" +
            (recovery_error.empty() ? std::string() : ": " + recovery_error));

  wire::BandRequest outside;
  outside.job = band_job(w, h, 0, h);
  outside.job.params.row_end = uint32_t(h + 5);
  mpi.send(1, wire::frame_message(wire::Kind::band_job, 1u << 30, wire::encode_band_request(outside)));
  // The node answers that job (id 2^30) with a failure; the remote tracer takes it for a stale answer
  // to some other job and drops it, and its own next band renders.
  core::BandBuffer next(w, h, core::BandFormat::rgb16f);
  const std::string next_error = thrown([&] { remote.render_band(band_job(w, h, 4, 12), next); });
  check(next_error.empty() && same_rows(next, expected, 4, 12) && remote.link_stats().stale_answers >= 1,
        "a band job outside the frame is refused by the node; its answer is dropped as another job's" +
            (next_error.empty() ? std::string() : ": " + next_error));

  wire::BandRequest adopting;
  adopting.job = band_job(w, h, 0, 16);
  adopting.format = core::BandFormat::rgb16f;
  adopting.adopt = 987654321;
  adopting.pieces = 0;
  const uint64_t adopting_id = (1u << 30) + 1;
  mpi.send(1, wire::frame_message(wire::Kind::band_job, adopting_id, wire::encode_band_request(adopting)));
  std::string adopt_reason;
  if (std::optional<std::vector<uint8_t>> answer = mpi.receive(1, tracers::MpiClock::now() + std::chrono::seconds(10))) {
    const wire::Message m = wire::parse_message(answer->data(), answer->size());
    if (m.kind == wire::Kind::band_failed && m.sequence == adopting_id) adopt_reason = wire::decode_band_failure(m.payload).reason;
  }
  check(adopt_reason.find("which this node did not render") != std::string::npos,
        "a band adopting a job ahead the node never rendered is refused: " + adopt_reason);
  core::BandBuffer after_adopt(w, h, core::BandFormat::rgb16f);
  const std::string after_adopt_error = thrown([&] { remote.render_band(band_job(w, h, 4, 12), after_adopt); });
  check(after_adopt_error.empty() && same_rows(after_adopt, expected, 4, 12),
        "and the next band renders" + (after_adopt_error.empty() ? std::string() : ": " + after_adopt_error));
  return failures == 0 ? 0 : 1;
}

}  // namespace

int main() {
  spdlog::set_pattern("[rank %P] [%l] %v");
  tracers::MpiSession& mpi = tracers::MpiSession::get();
  if (mpi.size() != 2) {
    std::fprintf(stderr, "protocol_check: run with 2 ranks (mpiexec -np 2)\n");
    return 2;
  }
  int code;
  if (mpi.rank() == 0) {
    code = rank0();
  } else {
    tracers::NodeOptions options;
    options.tracers_text = "embree";
    code = tracers::run_node(tracers::make_tracers("embree"), options);
  }
  mpi.finalize();
  return code;
}
