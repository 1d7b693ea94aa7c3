// Tracer::render_band_in_pieces (what a remote node renders its band with, tracers/mpi): every tracer
// writes the same rows as one render_band of the whole band, and calls ready(i) in order, each piece's
// rows already in the target when it does (the node sends them from there at once). The CUDA tracer
// queues every piece at once and downloads each while the next renders; the others render piece by
// piece.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>

#include "test_scenes.h"
#include "test_tracers.h"

using namespace cohort;
using namespace cohort::test;

namespace {

constexpr int kWidth = 64, kHeight = 48, kBegin = 6, kEnd = 41;

core::BandJob band_job() {
  core::BandJob job;
  job.params = frame_params(K_MODE_PATH, 2, 1, kHeight);
  job.params.row_begin = kBegin;
  job.params.row_end = kEnd;
  job.camera = test_room_camera(kWidth, kHeight);
  return job;
}

bool same_rows(const core::BandBuffer& a, const core::BandBuffer& b, int begin, int end) {
  for (int y = begin; y < end; ++y)
    if (std::memcmp(a.row(y), b.row(y), a.row_bytes()) != 0) return false;
  return true;
}

// Renders the band whole and in pieces on `kind`; the checks above, for every band format.
void check_pieces(const std::string& kind) {
  auto tracer = make_test_tracer(kind);
  auto compiled = std::make_shared<commit::TracerScene>(core::compile_scene(test_room()).tracer_scene);
  tracer->apply(commit::CommitBuffer::full(compiled, 1));
  for (core::BandFormat format : {core::BandFormat::rgb16f, core::BandFormat::rgb9e5, core::BandFormat::rgba32f}) {
    core::BandBuffer whole(kWidth, kHeight, format), pieces(kWidth, kHeight, format), untouched(kWidth, kHeight, format);
    const core::BandResult expected = tracer->render_band(band_job(), whole);
    const std::vector<int> cuts = {kBegin, kBegin + 7, kBegin + 7, kBegin + 20, kEnd};  // one piece empty
    std::vector<size_t> handed;
    const core::BandResult got = tracer->render_band_in_pieces(band_job(), pieces, cuts, [&](size_t i) {
      EXPECT_TRUE(same_rows(pieces, whole, cuts[i], cuts[i + 1])) << kind << ": piece " << i << " not in place";
      handed.push_back(i);
    });
    EXPECT_EQ(handed, (std::vector<size_t>{0, 1, 2, 3})) << kind;
    EXPECT_TRUE(same_rows(pieces, whole, kBegin, kEnd)) << kind << " " << core::to_string(format);
    EXPECT_TRUE(same_rows(pieces, untouched, 0, kBegin) && same_rows(pieces, untouched, kEnd, kHeight))
        << kind << ": rows outside the band were written";
    EXPECT_EQ(got.row_work, expected.row_work) << kind;
  }
}

}  // namespace

TEST(BandPieces, EachHostTracerWritesTheWholeBandsRowsAndHandsEachPieceOverInOrder) {
  int ran = 0;
  for (const std::string& kind : built_tracers()) {
    if (kind == "cuda" || kind == "mpi" || !tracer_runs_here(kind)) continue;
    check_pieces(kind);
    ++ran;
  }
  if (ran == 0) GTEST_SKIP() << "no tracer runs here";
}

// Its own pipeline: every piece queued at once, each downloaded while the next renders.
TEST(BandPieces, CudaQueuesEveryPieceAndHandsEachOverAsItsDownloadLands) {
  const std::vector<std::string> kinds = built_tracers();
  if (std::find(kinds.begin(), kinds.end(), "cuda") == kinds.end() || !tracer_runs_here("cuda"))
    GTEST_SKIP() << "no CUDA device here";
  check_pieces("cuda");
}
