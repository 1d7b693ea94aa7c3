// The Embree tracer's wavefront (EmbreeTracer::set_wavefront: each tile's paths shaded stage by stage, all
// the tile's shadow rays and then its bounce rays traced together in packets) draws the image of the tiles
// that run each path to its end with single rays, bit for bit: same integrator, same random numbers, same
// rays, same order of float additions. Every float of the band, every aux texel and the rays counted per
// row must match, on the test room, on the test map from the player start and where its glass, grate, fog
// volume, perforated (alpha-tested) and noSelfShadow surfaces are in view, over one and three bounces,
// roulette, several samples a pixel, bands that start mid-frame, both kinds of aux planes, the sparse
// pattern of dynamic resolution, the other lit and debug modes, and a floor of many lights whose shadow
// rays fill a vertex's slots or overflow them. The ray log (bench_tracers) sees the same rays by class.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <ostream>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include "cohort/core/view.h"
#include "cohort/scene/map_loader.h"
#include "band_frames.h"
#include "shadow_walk_cases.h"
#include "test_scenes.h"

#ifdef COHORT_HAVE_EMBREE
#include "cohort/tracers/embree_tracer.h"
#endif

using namespace cohort;
using namespace cohort::test;

#ifdef COHORT_HAVE_EMBREE

namespace {

// The frame rendered band by band (render_in_bands). x86_64_v3: the shading's x86-64-v3 build where this CPU has one, else the baseline build; packet_width: the
// wavefront's rays per packet (0: path by path).
BandFrame render_bands(int packet_width, bool x86_64_v3, const View& view, const KFrameParams& params,
                       const std::vector<int>& cuts) {
  tracers::EmbreeTracer tracer;
  tracer.set_wavefront(packet_width > 0);
  if (packet_width > 0) tracer.set_wave_packet_width(packet_width);
  tracer.prefer_x86_64_v3(x86_64_v3);
  return render_in_bands(tracer, view, params, cuts);
}

// The wavefront's frame (packets of packet_width rays) against the path-by-path tiles' in one build of the
// shading: every float, aux texel and row count the same.
void expect_the_path_tiles_frame_in_build(bool x86_64_v3, int packet_width, BandFrame& paths, const View& view,
                                          const KFrameParams& params, const std::vector<int>& cuts) {
  BandFrame wave = render_bands(packet_width, x86_64_v3, view, params, cuts);
  expect_same_band_frame(paths.frame, paths.row_work, wave.frame, wave.row_work, params.aux_outputs != 0u,
                         int(view.camera.height), "the path tiles'");
}

// The wavefront's frame against the path-by-path tiles': every float, aux texel and row count the same, in
// both builds of the shading (x86-64-v3 contracts multiply-adds into FMAs: the same ones in both renderers)
// and with packets of 8 and 16 rays.
void expect_the_path_tiles_frame(const View& view, const KFrameParams& params, const std::vector<int>& cuts,
                                 const std::string& what) {
  for (const bool x86_64_v3 : {true, false}) {
    BandFrame paths = render_bands(0, x86_64_v3, view, params, cuts);
    for (const int packet_width : {8, 16}) {
      SCOPED_TRACE(what + (x86_64_v3 ? ", x86-64-v3 build where the CPU has it" : ", baseline build") +
                   ", packets of " + std::to_string(packet_width));
      expect_the_path_tiles_frame_in_build(x86_64_v3, packet_width, paths, view, params, cuts);
    }
  }
}

struct SceneCase {
  const char* name;
  bool map;
  MapSpot spot;
  uint32_t bounces, spp;
  float rr_start = 2.0f;
  kuint aux = 0u;             // K_AUX_PATH_FIRST_HIT or K_AUX_CENTRE_RAY
  uint32_t path_pixels = 0u;  // dynamic resolution's sparse pattern: paths at this many of each 16 pixels
  uint32_t light_sampling = K_LIGHTS_AUTO;
  uint32_t mode = K_MODE_PATH;
  std::vector<int> cuts = {};  // the bands (default: two, the second from row 13)
};
void PrintTo(const SceneCase& c, std::ostream* os) { *os << c.name; }
class EmbreeWavefront : public ::testing::TestWithParam<SceneCase> {};

TEST_P(EmbreeWavefront, DrawsThePathTilesImage) {
  const SceneCase c = GetParam();
  const int w = 40, h = 32;  // a partial tile column (40 = 32 + 8) and rows that do not fill the last tile
  const View view = c.map ? map_view(c.spot, w, h) : room_view(w, h);
  const KFrameParams params =
      wave_case_params(c.mode, c.spp, c.bounces, h, c.rr_start, c.aux, c.path_pixels, c.light_sampling);
  const std::vector<int> cuts = c.cuts.empty() ? std::vector<int>{0, 13, h} : c.cuts;
  expect_the_path_tiles_frame(view, params, cuts, c.name);
}

INSTANTIATE_TEST_SUITE_P(
    Paths, EmbreeWavefront,
    ::testing::Values(
        SceneCase{"room_bounce1", false, MapSpot::player_start, 1, 1},
        SceneCase{"room_bounce3_spp2_roulette", false, MapSpot::player_start, 3, 2, 1.0f},
        SceneCase{"room_first_hits_bands_mid_frame", false, MapSpot::player_start, 2, 2, 2.0f, K_AUX_PATH_FIRST_HIT,
                  0u, K_LIGHTS_AUTO, K_MODE_PATH, {0, 5, 21, 32}},
        SceneCase{"room_sparse8_spp2", false, MapSpot::player_start, 2, 2, 2.0f, K_AUX_PATH_FIRST_HIT, 8u},
        SceneCase{"map_bounce1", true, MapSpot::player_start, 1, 1},
        SceneCase{"map_bounce3_spp4_first_hits", true, MapSpot::player_start, 3, 4, 1.0f, K_AUX_PATH_FIRST_HIT},
        SceneCase{"map_atrium_bounce1_centre_rays", true, MapSpot::atrium, 1, 2, 2.0f, K_AUX_CENTRE_RAY},
        SceneCase{"map_atrium_bounce3_roulette", true, MapSpot::atrium, 3, 2, 1.0f},
        SceneCase{"map_gallery_bounce1", true, MapSpot::gallery, 1, 2},
        SceneCase{"map_gallery_bounce3", true, MapSpot::gallery, 3, 1, 1.0f, K_AUX_PATH_FIRST_HIT},
        SceneCase{"map_sparse4_centre_rays", true, MapSpot::atrium, 1, 1, 2.0f, K_AUX_CENTRE_RAY, 4u},
        SceneCase{"map_every_light", true, MapSpot::atrium, 1, 2, 2.0f, 0u, 0u, K_LIGHTS_EVERY},
        SceneCase{"map_tree", true, MapSpot::gallery, 1, 2, 2.0f, 0u, 0u, K_LIGHTS_TREE},
        SceneCase{"map_direct", true, MapSpot::atrium, 0, 2, 2.0f, 0u, 0u, K_LIGHTS_AUTO, K_MODE_DIRECT},
        SceneCase{"map_path_no_bounce", true, MapSpot::atrium, 0, 2, 2.0f, 0u, 0u, K_LIGHTS_AUTO, K_MODE_PATH},
        SceneCase{"map_albedo", true, MapSpot::atrium, 1, 1, 2.0f, 0u, 0u, K_LIGHTS_AUTO, K_MODE_ALBEDO},
        SceneCase{"map_normals", true, MapSpot::gallery, 1, 1, 2.0f, 0u, 0u, K_LIGHTS_AUTO, K_MODE_NORMALS},
        SceneCase{"map_bvh_view", true, MapSpot::gallery, 1, 1, 2.0f, 0u, 0u, K_LIGHTS_AUTO, K_MODE_BVH}),
    [](const auto& info) { return std::string(info.param.name); });

// Next-event estimation's shadow rays on a floor of many lights and an emissive panel: gather choosing among
// more lights than its budget, light samples averaged with the shadow roulette, `every` with 6 lights (7 rays
// a vertex: the packets) and with 96 (more than a vertex's slots: traced one by one as it shades).
class EmbreeWavefrontShadows : public ::testing::TestWithParam<ShadowWalkCase> {};

TEST_P(EmbreeWavefrontShadows, DrawThePathTilesImage) {
  const ShadowWalkCase c = GetParam();
  const int w = 32, h = 24;
  const View view = many_lights_view(c.point_lights, c.projected_lights, w, h);
  expect_the_path_tiles_frame(view, shadow_walk_params(c, h), {0, 11, h}, c.name);
}

INSTANTIATE_TEST_SUITE_P(LightSampling, EmbreeWavefrontShadows, ::testing::ValuesIn(shadow_walk_cases()),
                         [](const auto& info) { return std::string(info.param.name); });

using RayKey = std::tuple<float, float, float, float, float, float, float, uint32_t>;

std::vector<RayKey> sorted(const std::vector<tracers::EmbreeRay>& rays) {
  std::vector<RayKey> keys;
  keys.reserve(rays.size());
  for (const tracers::EmbreeRay& r : rays)
    keys.emplace_back(r.org[0], r.org[1], r.org[2], r.dir[0], r.dir[1], r.dir[2], r.tmax, r.mask);
  std::sort(keys.begin(), keys.end());
  return keys;
}

// bench_tracers times the integrator's rays by class against raw Embree on the rays the tracer records: the
// wavefront records the same rays in each class as the path tiles (in another order).
TEST(EmbreeWavefrontRayLog, RecordsTheSameRaysByClass) {
  const View view = map_view(MapSpot::atrium, 48, 20);
  KFrameParams params = frame_params(K_MODE_PATH, 2, 3, 20);
  params.frame_index = 2;
  params.rr_start = 1.0f;
  params.shadow_rr = 0.03f;
  tracers::EmbreeTracer tracer;
  tracer.apply(commit::CommitBuffer::full(view.scene, 1));
  core::BandJob job;
  job.params = params;
  job.camera = view.camera;
  tracer.set_wavefront(false);
  const tracers::EmbreeRaySet paths = tracer.record_rays(job);
  tracer.set_wavefront(true);
  const tracers::EmbreeRaySet wave = tracer.record_rays(job);
  EXPECT_GE(paths.camera.size(), size_t(48 * 20 * 2)) << "every sample's camera ray, and layers behind glass";
  EXPECT_GT(paths.shadow.size(), 0u);
  EXPECT_GT(paths.bounce.size(), 0u);
  EXPECT_EQ(sorted(wave.camera), sorted(paths.camera)) << "camera rays";
  EXPECT_EQ(sorted(wave.shadow), sorted(paths.shadow)) << "shadow rays";
  EXPECT_EQ(sorted(wave.bounce), sorted(paths.bounce)) << "bounce rays";
}

// With `variable` set to `value`, building an Embree tracer throws std::invalid_argument naming both; unset after.
void expect_tracer_refuses(const char* variable, const char* value) {
  ::setenv(variable, value, 1);
  try {
    tracers::EmbreeTracer tracer;
    ADD_FAILURE() << variable << "=" << value << " accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(std::string(variable) + "='" + value + "'"), std::string::npos) << e.what();
  }
  ::unsetenv(variable);
}

// COHORT_EMBREE_WAVEFRONT: the wavefront unless it says 0; a value other than 0 or 1 is named. Packets of 8
// or 16 rays, nothing else, also through COHORT_EMBREE_PACKET_WIDTH.
TEST(EmbreeWavefrontSwitch, TheEnvironmentSetsItAndABadValueIsNamed) {
  {
    tracers::EmbreeTracer tracer;
    EXPECT_TRUE(tracer.wave_packet_width() == 8 || tracer.wave_packet_width() == 16);
    EXPECT_THROW(tracer.set_wave_packet_width(4), std::invalid_argument);
    tracer.set_wave_packet_width(8);
    EXPECT_EQ(tracer.wave_packet_width(), 8);
  }
  ::unsetenv("COHORT_EMBREE_WAVEFRONT");
  EXPECT_TRUE(tracers::EmbreeTracer().wavefront());
  ::setenv("COHORT_EMBREE_WAVEFRONT", "0", 1);
  EXPECT_FALSE(tracers::EmbreeTracer().wavefront());
  ::setenv("COHORT_EMBREE_WAVEFRONT", "1", 1);
  EXPECT_TRUE(tracers::EmbreeTracer().wavefront());
  expect_tracer_refuses("COHORT_EMBREE_WAVEFRONT", "yes");
  ::setenv("COHORT_EMBREE_PACKET_WIDTH", "8", 1);
  EXPECT_EQ(tracers::EmbreeTracer().wave_packet_width(), 8);
  ::setenv("COHORT_EMBREE_PACKET_WIDTH", "16", 1);
  EXPECT_EQ(tracers::EmbreeTracer().wave_packet_width(), 16);
  expect_tracer_refuses("COHORT_EMBREE_PACKET_WIDTH", "4");
}

}  // namespace

#else

TEST(EmbreeWavefront, NeedsEmbree) { GTEST_SKIP() << "built without Embree (COHORT_WITH_EMBREE=OFF)"; }

#endif
