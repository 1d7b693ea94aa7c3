// The Embree tracer's split BLASes (EmbreeTracer::set_split_filters): a BLAS whose own materials let rays pass
// on some triangles only becomes two Embree geometries, the filter function on the second alone. The image is
// the one-geometry BLASes' where the test map's glass, grate, decals, fog and noSelfShadow shrub are in view;
// switching rebuilds the scene; and a material that starts letting rays pass through triangles of the
// unfiltered geometry (a commit of materials alone) has the BLASes built again, so that surface lets rays
// through in both.
//
// "The image" within a margin, not bit for bit: over two geometries Embree builds another tree, and which of
// two surfaces a ray meets where they touch can change with it. With the world's triangles all in the second
// geometry (their own index buffer and table back to the scene's triangles, the filter on all) the image was
// the one-geometry image bit for bit (checked by hand while writing this); split in two, 1 pixel of 6,144
// differs from the player start and 72 in the atrium (the first hit of a strip of 15 pixels along the grate's
// row, depth 185-213 against 208-236; later rays of the others).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "cohort/commit/commit_buffer.h"
#include "cohort/core/view.h"
#include "band_frames.h"

#ifdef COHORT_HAVE_EMBREE
#include "cohort/tracers/embree_tracer.h"
#endif

using namespace cohort;
using namespace cohort::test;

#ifdef COHORT_HAVE_EMBREE

namespace {

constexpr int kWidth = 96, kHeight = 64;

// The player start's hall, the atrium (glass screen, grate, the stairwell's fog) and the gallery (glass case,
// noSelfShadow shrub).
std::vector<View> map_views() {
  return {map_view(MapSpot::player_start, kWidth, kHeight), map_view(MapSpot::atrium, kWidth, kHeight),
          map_view(MapSpot::gallery, kWidth, kHeight)};
}

KFrameParams split_case_params() {
  return wave_case_params(K_MODE_PATH, 2, 2, kHeight, 2.0f, K_AUX_PATH_FIRST_HIT, 0u, K_LIGHTS_AUTO);
}

const std::vector<int> kCuts = {0, 24, kHeight};

// a is b within the margin: at most 2 % of the pixels differ and the mean brightness by at most 1 %.
void expect_same_image_but_for_grazing_rays(BandFrame& a, BandFrame& b, const std::string& what) {
  const float* fa = static_cast<const float*>(a.frame.data());
  const float* fb = static_cast<const float*>(b.frame.data());
  const size_t pixels = size_t(kWidth) * kHeight;
  size_t differing = 0;
  double sum_a = 0.0, sum_b = 0.0;
  for (size_t p = 0; p < pixels; ++p) {
    bool differs = false;
    for (int c = 0; c < 3; ++c) {
      ASSERT_TRUE(std::isfinite(fa[4 * p + c])) << what << ", pixel " << p;
      differs |= fa[4 * p + c] != fb[4 * p + c];
      sum_a += fa[4 * p + c];
      sum_b += fb[4 * p + c];
    }
    differing += differs;
  }
  EXPECT_GT(sum_b, 0.0) << what << ": the frame shows something";
  EXPECT_LE(double(differing), 0.02 * double(pixels)) << what << ": pixels that differ";
  EXPECT_NEAR(sum_a / sum_b, 1.0, 0.01) << what << ": mean brightness";
}

// Whether a material lets no ray pass (embree_filters.cpp's material_may_pass, negated).
bool never_passes(const KMaterial& m) {
  return (m.blend == K_BLEND_OPAQUE || m.blend == K_BLEND_SKY) &&
         (m.flags & (K_MAT_ALPHA_TEST | K_MAT_NO_SHADOWS | K_MAT_TRANSLUCENT | K_MAT_NO_SELF_SHADOW)) == 0u;
}

TEST(EmbreeSplitFilters, DrawTheImageOfOneGeometryABlas) {
  const KFrameParams params = split_case_params();
  for (const View& view : map_views()) {
    tracers::EmbreeTracer split, whole;
    split.set_split_filters(true);
    whole.set_split_filters(false);
    BandFrame a = render_in_bands(split, view, params, kCuts);
    BandFrame b = render_in_bands(whole, view, params, kCuts);
    EXPECT_GT(split.blases_split(), 0u) << "the test map's world mixes opaque and alpha-tested surfaces";
    EXPECT_EQ(whole.blases_split(), 0u);
    expect_same_image_but_for_grazing_rays(a, b, "split against one geometry a BLAS");
  }
}

TEST(EmbreeSplitFilters, SwitchingRebuildsTheAppliedScene) {
  const View view = map_view(kWidth, kHeight);
  tracers::EmbreeTracer tracer;
  tracer.set_split_filters(true);
  render_in_bands(tracer, view, split_case_params(), kCuts);
  const size_t split = tracer.blases_split();
  ASSERT_GT(split, 0u);
  tracer.set_split_filters(false);
  EXPECT_FALSE(tracer.split_filters());
  EXPECT_EQ(tracer.blases_split(), 0u);
  tracer.set_split_filters(true);
  EXPECT_EQ(tracer.blases_split(), split);
}

// A commit of materials alone turns the most common plain material of the largest split BLAS into one whose
// alpha test every hit fails (the surface lets every ray through): the split tracer builds its BLASes again
// and draws what the one-geometry tracer draws, and the image changed.
TEST(EmbreeSplitFilters, AMaterialThatStartsLettingRaysPassRebuildsTheSplit) {
  const View view = map_view(kWidth, kHeight);
  const commit::TracerScene& scene = *view.scene;
  const KFrameParams params = split_case_params();
  tracers::EmbreeTracer split, whole;
  split.set_split_filters(true);
  whole.set_split_filters(false);
  BandFrame before = render_in_bands(split, view, params, kCuts);
  render_in_bands(whole, view, params, kCuts);
  ASSERT_GT(split.blases_split(), 0u);
  // The material of most plain triangles in the largest BLAS.
  size_t largest = 0;
  for (size_t b = 0; b < scene.blases.size(); ++b)
    if (scene.blases[b].tri_count > scene.blases[largest].tri_count) largest = b;
  std::vector<size_t> uses(scene.materials.size(), 0);
  const KBlas& blas = scene.blases[largest];
  for (kuint t = blas.tri_offset; t < blas.tri_offset + blas.tri_count; ++t) {
    const kuint m = scene.triangles[t].material;
    if (m < scene.materials.size() && never_passes(scene.materials[m])) ++uses[m];
  }
  size_t chosen = 0;
  for (size_t m = 0; m < uses.size(); ++m)
    if (uses[m] > uses[chosen]) chosen = m;
  ASSERT_GT(uses[chosen], 0u);
  KMaterial see_through = scene.materials[chosen];
  see_through.flags |= K_MAT_ALPHA_TEST;
  see_through.alpha_ref = 2.0f;  // no coverage reaches it: every hit passes
  commit::CommitBuffer commit;
  commit.set_frame(2);
  commit.set_material(uint32_t(chosen), see_through);
  split.apply(commit);
  whole.apply(commit);
  BandFrame a = render_bands_of(split, view.camera, params, kCuts);
  BandFrame b = render_bands_of(whole, view.camera, params, kCuts);
  expect_same_image_but_for_grazing_rays(a, b, "split against one geometry a BLAS, after the commit");
  EXPECT_GT(differing_floats(before.frame, a.frame), 0.05 * kWidth * kHeight)
      << "the see-through material should change the image";
}

// COHORT_EMBREE_SPLIT_FILTERS: on unless 0; another value is named.
TEST(EmbreeSplitFilters, TheEnvironmentSetsItAndABadValueIsNamed) {
  ::unsetenv("COHORT_EMBREE_SPLIT_FILTERS");
  EXPECT_TRUE(tracers::EmbreeTracer().split_filters());
  ::setenv("COHORT_EMBREE_SPLIT_FILTERS", "0", 1);
  EXPECT_FALSE(tracers::EmbreeTracer().split_filters());
  ::setenv("COHORT_EMBREE_SPLIT_FILTERS", "yes", 1);
  try {
    tracers::EmbreeTracer tracer;
    ADD_FAILURE() << "COHORT_EMBREE_SPLIT_FILTERS=yes accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("COHORT_EMBREE_SPLIT_FILTERS='yes'"), std::string::npos) << e.what();
  }
  ::unsetenv("COHORT_EMBREE_SPLIT_FILTERS");
}

}  // namespace

#else

TEST(EmbreeSplitFilters, NeedsEmbree) { GTEST_SKIP() << "built without Embree (COHORT_WITH_EMBREE=OFF)"; }

#endif
