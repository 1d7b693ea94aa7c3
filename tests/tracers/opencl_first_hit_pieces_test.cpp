// The OpenCL tracer renders a band whose aux planes come from its paths' first hits in pieces of rows
// (OpenCLTracer::Options::first_hit_pieces), each piece's aux finishing, reads and host copy overlapping
// the next piece's rendering. The pieces must give exactly the band of one piece (the serial order), and
// planes that agree with Embree's, for bands that start mid-frame, are narrower than their target, or
// hold one row.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <memory>
#include <string>
#include <utility>

#include "test_scenes.h"
#include "test_tracers.h"

#ifdef COHORT_HAVE_OPENCL
#include "cohort/tracers/opencl_tracer.h"
#endif

using namespace cohort;
using namespace cohort::test;

#ifdef COHORT_HAVE_OPENCL

namespace {

constexpr int kW = 40, kH = 48;

TEST(OpenCLFirstHitPieces, PiecesCoverTheBandInWholeWorkGroups) {
  using tracers::OpenCLTracer;
  EXPECT_EQ(OpenCLTracer::piece_starts(432, 4, 8), (std::vector<size_t>{0, 112, 224, 336, 432}));
  EXPECT_EQ(OpenCLTracer::piece_starts(36, 4, 8), (std::vector<size_t>{0, 16, 32, 36}));
  EXPECT_EQ(OpenCLTracer::piece_starts(15, 4, 8), (std::vector<size_t>{0, 8, 15}));
  EXPECT_EQ(OpenCLTracer::piece_starts(1, 4, 8), (std::vector<size_t>{0, 1}));
  EXPECT_EQ(OpenCLTracer::piece_starts(0, 4, 8), (std::vector<size_t>{0}));
  EXPECT_EQ(OpenCLTracer::piece_starts(100, 1, 8), (std::vector<size_t>{0, 100}));
  for (size_t rows = 1; rows <= 200; ++rows)
    for (int pieces = 1; pieces <= OpenCLTracer::kMaxFirstHitPieces; ++pieces) {
      const std::vector<size_t> starts = OpenCLTracer::piece_starts(rows, pieces, 8);
      SCOPED_TRACE(std::to_string(rows) + " rows in " + std::to_string(pieces) + " pieces");
      ASSERT_GE(starts.size(), 2u);
      ASSERT_LE(starts.size(), size_t(pieces) + 1);
      ASSERT_EQ(starts.front(), 0u);
      ASSERT_EQ(starts.back(), rows);
      for (size_t i = 1; i < starts.size(); ++i) {
        ASSERT_GT(starts[i], starts[i - 1]) << "an empty piece";
        if (i + 1 < starts.size()) {
          ASSERT_EQ(starts[i] % 8, 0u) << "a piece ends inside a work group";
        }
      }
    }
}

TEST(OpenCLFirstHitPieces, TheTracerRefusesAPieceCountOutOfRange) {
  if (!tracer_runs_here("opencl")) GTEST_SKIP() << "no OpenCL device here";
  for (int pieces : {0, tracers::OpenCLTracer::kMaxFirstHitPieces + 1}) {
    tracers::OpenCLTracer::Options options;
    options.first_hit_pieces = pieces;
    EXPECT_THROW(tracers::OpenCLTracer{options}, std::invalid_argument) << pieces;
  }
}

// COHORT_OPENCL_FIRST_HIT_PIECES and COHORT_OPENCL_AUX_INTO_TARGET (A/B runs) are read before any device
// is asked: a bad value is named.
TEST(OpenCLFirstHitPieces, ABadValueInTheEnvironmentIsNamed) {
  const std::pair<const char*, const char*> bad_values[] = {{"COHORT_OPENCL_FIRST_HIT_PIECES", "0"},
                                                            {"COHORT_OPENCL_FIRST_HIT_PIECES", "9"},
                                                            {"COHORT_OPENCL_FIRST_HIT_PIECES", "four"},
                                                            {"COHORT_OPENCL_FIRST_HIT_PIECES", "2x"},
                                                            {"COHORT_OPENCL_AUX_INTO_TARGET", "yes"}};
  for (const auto& [variable, bad] : bad_values) {
    const std::string message = registry_error_with(variable, bad, "opencl:0");
    EXPECT_NE(message.find(std::string(variable) + "='" + bad + "'"), std::string::npos) << bad << ": " << message;
  }
}

std::unique_ptr<tracers::OpenCLTracer> opencl_in_pieces(int pieces, bool aux_into_target = false) {
  tracers::OpenCLTracer::Options options;
  options.device = test_opencl_device();
  options.first_hit_pieces = pieces;
  options.aux_into_target = aux_into_target;
  return std::make_unique<tracers::OpenCLTracer>(options);
}

struct Band {
  int begin, end, target_width;
  const char* what;
};

struct Rendered {
  std::unique_ptr<core::BandBuffer> buffer;
  core::BandResult result;
};

Rendered render_band(core::Tracer& tracer, const Band& band, core::BandFormat format) {
  Rendered out;
  out.buffer = std::make_unique<core::BandBuffer>(band.target_width, kH, format);
  out.buffer->enable_aux(true);
  core::BandJob job;
  job.params = frame_params(K_MODE_PATH, 1, 1, kH);
  job.params.row_begin = kuint(band.begin);
  job.params.row_end = kuint(band.end);
  job.params.aux_outputs = K_AUX_PATH_FIRST_HIT;
  job.camera = test_room_camera(kW, kH);
  job.previous_camera = core::make_camera({-180, -130, 125}, {33.0f, 21.0f}, 90.0f, kW, kH);
  out.result = tracer.render_band(job, *out.buffer);
  return out;
}

core::GBuffer planes_of(const core::BandBuffer& buffer, const Band& band) {
  core::GBuffer g;
  g.resize(buffer.width(), buffer.height());
  buffer.copy_aux_rows_to(g, band.begin, band.end);
  return g;
}

const Band kBands[] = {
    {9, 45, kW, "a band from row 9, in three pieces (16, 16 and 4 rows)"},
    {13, 42, kW + 16, "a band narrower than its target (float records, stored row by row)"},
    {17, 18, kW, "a one-row band"},
};

}  // namespace

TEST(OpenCLFirstHitPieces, PiecedBandsEqualTheBandInOnePiece) {
  if (!tracer_runs_here("opencl")) GTEST_SKIP() << "no OpenCL device here";
  auto room = std::make_shared<commit::TracerScene>(core::compile_scene(test_room()).tracer_scene);
  auto whole = opencl_in_pieces(1);
  whole->apply(commit::CommitBuffer::full(room, 1));
  for (bool aux_into_target : {false, true}) {
    auto pieced = opencl_in_pieces(4, aux_into_target);
    pieced->apply(commit::CommitBuffer::full(room, 1));
    for (const Band& band : kBands)
      for (core::BandFormat format : {core::BandFormat::rgb16f, core::BandFormat::rgb9e5, core::BandFormat::rgba32f}) {
        SCOPED_TRACE(std::string(band.what) + ", " + core::to_string(format) +
                     (aux_into_target ? ", aux read into the target" : ", aux through page-locked staging"));
        const Rendered a = render_band(*whole, band, format);
        const Rendered b = render_band(*pieced, band, format);
        ASSERT_EQ(std::memcmp(a.buffer->data(), b.buffer->data(), a.buffer->bytes()), 0) << "the colours differ";
        ASSERT_EQ(std::memcmp(a.buffer->aux_data(), b.buffer->aux_data(), a.buffer->aux_bytes()), 0) << "the planes differ";
        EXPECT_EQ(b.result.row_work, a.result.row_work);
        ASSERT_EQ(b.result.row_work.size(), size_t(band.end - band.begin));
        for (float rays : b.result.row_work) EXPECT_GE(rays, float(kW)) << "every pixel traces its camera ray";
        EXPECT_GT(b.result.device_ms, 0.0);
        // The band's rows hold a picture and planes; the rows outside it are untouched (zero).
        const core::GBuffer g = planes_of(*b.buffer, band);
        size_t hits = 0, outside = 0;
        for (int y = 0; y < kH; ++y)
          for (int x = 0; x < band.target_width; ++x) {
            const bool inside = y >= band.begin && y < band.end && x < kW;
            const float depth = g.depth[size_t(y) * size_t(band.target_width) + size_t(x)];
            hits += inside && depth > 0.0f ? 1u : 0u;
            outside += !inside && depth != 0.0f ? 1u : 0u;
          }
        EXPECT_GT(hits, size_t(band.end - band.begin) * kW / 2) << "the planes are mostly empty";
        EXPECT_EQ(outside, 0u) << "planes written outside the band";
      }
  }
}

// Agreement with Embree's first-hit planes (the tolerance of AgreementAux): the pieces' rows land where
// Embree puts the same pixels.
TEST(OpenCLFirstHitPieces, PiecedPlanesAgreeWithEmbrees) {
  if (!tracer_runs_here("opencl")) GTEST_SKIP() << "no OpenCL device here";
  const std::vector<std::string> kinds = built_tracers();
  if (std::find(kinds.begin(), kinds.end(), "embree") == kinds.end()) GTEST_SKIP() << "built without Embree";
  auto room = std::make_shared<commit::TracerScene>(core::compile_scene(test_room()).tracer_scene);
  auto embree = make_test_tracer("embree");
  auto pieced = opencl_in_pieces(4);
  embree->apply(commit::CommitBuffer::full(room, 1));
  pieced->apply(commit::CommitBuffer::full(room, 1));
  for (const Band& band : kBands) {
    SCOPED_TRACE(band.what);
    const Rendered a = render_band(*embree, band, core::BandFormat::rgba32f);
    const Rendered b = render_band(*pieced, band, core::BandFormat::rgba32f);
    const core::GBuffer ga = planes_of(*a.buffer, band), gb = planes_of(*b.buffer, band);
    size_t compared = 0, id_mismatch = 0;
    for (int y = band.begin; y < band.end; ++y)
      for (int x = 0; x < kW; ++x) {
        const size_t p = size_t(y) * size_t(band.target_width) + size_t(x);
        ++compared;
        if (ga.id[p] != gb.id[p]) {  // a silhouette pixel may go either way
          ++id_mismatch;
          continue;
        }
        ASSERT_TRUE(aux_planes_agree(ga, gb, p)) << x << "," << y;
      }
    EXPECT_LE(id_mismatch, std::max<size_t>(1, compared / 100));
  }
}

#else

TEST(OpenCLFirstHitPieces, NeedsOpenCL) { GTEST_SKIP() << "built without OpenCL (COHORT_WITH_OPENCL=OFF)"; }

#endif
