// Vertex colours on every tracer the build has: a `vertexColor` material multiplies its colours by the
// interpolated vertex colour, an `inverseVertexColor` one by 1 - colour, any other ignores the colours
// (doom3-content.md 6.3). Four quads in a row seen from above, two in the static world and two in an
// entity's model (the two ways vertices reach a tracer: the world BLAS and a model's BLAS upload):
//   A x in [-200, -100]  world   vertexColor         red vertices          -> albedo x (1, 0, 0)
//   B x in [-100,    0]  world   inverseVertexColor  red vertices          -> albedo x (0, 1, 1)
//   C x in [   0,  100]  entity  vertexColor         black at x = 0, white at x = 100: a ramp
//   D x in [ 100,  200]  entity  plain               red vertices          -> albedo, colours ignored
#include <gtest/gtest.h>

#include <cmath>

#include "test_scenes.h"
#include "test_tracers.h"

using namespace cohort;
using namespace cohort::test;

namespace {

constexpr float kAlbedo = 0.8f;
constexpr uint32_t kRed = 0xFF0000FFu, kBlack = 0xFF000000u, kWhite = 0xFFFFFFFFu;

class VertexColors : public EachTracer {};

// A quad from x0 to x1 (|y| < 50, z = 0, facing up) whose corners at x0 get colour `left` and at x1 `right`.
void add_coloured_quad(scene::Mesh& mesh, int material, float x0, float x1, uint32_t left, uint32_t right) {
  add_quad(mesh, material, {x0, -50, 0}, {x1, -50, 0}, {x1, 50, 0}, {x0, 50, 0}, {0, 0, 1});
  for (uint32_t c : {left, right, right, left}) mesh.colors.push_back(c);
}

int add_material(scene::Scene& s, const std::string& name, bool vertex_color, bool inverse) {
  int m = add_diffuse_material(s, name, glm::vec3(kAlbedo));
  s.materials[size_t(m)].vertex_color = vertex_color;
  s.materials[size_t(m)].inverse_vertex_color = inverse;
  return m;
}

scene::Scene four_quads() {
  scene::Scene s;
  s.name = "vertex_colours";
  const int vc = add_material(s, "vc", true, false), inverse = add_material(s, "inverse", false, true),
            plain = add_material(s, "plain", false, false);
  scene::Mesh world;
  world.name = "_area0";
  add_coloured_quad(world, vc, -200, -100, kRed, kRed);
  add_coloured_quad(world, inverse, -100, 0, kRed, kRed);
  add_world_mesh(s, std::move(world));
  scene::Mesh model;
  model.name = "models/coloured";
  add_coloured_quad(model, vc, 0, 100, kBlack, kWhite);
  add_coloured_quad(model, plain, 100, 200, kRed, kRed);
  s.meshes.push_back(std::move(model));
  scene::Entity e;
  e.name = "coloured_prop";
  e.mesh = static_cast<int>(s.meshes.size() - 1);
  s.entities.push_back(e);
  s.lights.push_back(point_light({0, 0, 150}, {600, 600, 600}));
  return s;
}

constexpr int kSize = 64;
constexpr float kHalfView = 200.0f;   // camera at z = 400 with tan 0.5: x and y in [-200, 200]

glm::ivec2 pixel_of(float x, float y) {
  return {int((x / kHalfView * 0.5f + 0.5f) * float(kSize)), int((0.5f - y / kHalfView * 0.5f) * float(kSize))};
}

float pixel_centre_x(int px) { return ((float(px) + 0.5f) / float(kSize) - 0.5f) * 2.0f * kHalfView; }

core::FrameBuffer render_quads(core::Tracer& tracer, uint32_t mode) {
  return render(tracer, four_quads(), camera_looking_down({0, 0, 400}, 0.5f, kSize, kSize),
                frame_params(mode, 16, 0, kSize));
}

void expect_rgb(glm::vec3 got, glm::vec3 want, float tolerance, const char* where) {
  EXPECT_NEAR(got.x, want.x, tolerance) << where;
  EXPECT_NEAR(got.y, want.y, tolerance) << where;
  EXPECT_NEAR(got.z, want.z, tolerance) << where;
}

}  // namespace

TEST_P(VertexColors, AlbedoIsMultipliedByTheVertexColourOrItsInverse) {
  core::FrameBuffer fb = render_quads(*tracer_, K_MODE_ALBEDO);
  glm::ivec2 a = pixel_of(-150, 0), b = pixel_of(-50, 0), d = pixel_of(150, 0);
  expect_rgb(pixel(fb, a.x, a.y), {kAlbedo, 0, 0}, 1e-4f, "A: vertexColor, red vertices");
  expect_rgb(pixel(fb, b.x, b.y), {0, kAlbedo, kAlbedo}, 1e-4f, "B: inverseVertexColor, red vertices");
  expect_rgb(pixel(fb, d.x, d.y), {kAlbedo, kAlbedo, kAlbedo}, 1e-4f, "D: plain material, colours ignored");
  // C: the colour interpolates across the triangles from black to white; 16 jittered samples a pixel
  // average to the pixel centre's value (the ramp is linear inside a pixel).
  int ramp_pixels = 0;
  for (int px = pixel_of(5, 0).x; px <= pixel_of(95, 0).x; ++px) {
    const float x = pixel_centre_x(px);
    if (x < 4.0f || x > 96.0f) continue;   // pixels straddling the quad's edges
    const float want = kAlbedo * x / 100.0f;
    const glm::vec3 got = pixel(fb, px, kSize / 2);
    EXPECT_NEAR(got.x, want, 0.01f) << "C: ramp at x = " << x;
    EXPECT_NEAR(got.y, want, 0.01f) << "C: ramp at x = " << x;
    ++ramp_pixels;
  }
  EXPECT_GE(ramp_pixels, 12);
}

// Lit: the tint reaches the shaded colour. A and D lie symmetrically under the light, so their red
// channels agree while A has no green or blue at all.
TEST_P(VertexColors, LitSurfaceTakesTheVertexColour) {
  core::FrameBuffer fb = render_quads(*tracer_, K_MODE_DIRECT);
  glm::ivec2 a = pixel_of(-150, 0), d = pixel_of(150, 0);
  const glm::vec3 tinted = pixel(fb, a.x, a.y), plain = pixel(fb, d.x - 1, d.y);   // mirror pixel of a
  ASSERT_GT(plain.x, 0.02f);
  EXPECT_NEAR(tinted.x, plain.x, 0.03f * plain.x);
  EXPECT_EQ(tinted.y, 0.0f);
  EXPECT_EQ(tinted.z, 0.0f);
  EXPECT_NEAR(plain.y, plain.x, 1e-4f);
}

// A terrain blend: one quad whose vertex colour ramps from black (x = -100) to white (x = 100) under a
// material with a green `vertexColor` diffuse stage and a blue `inverseVertexColor` one: the albedo goes
// from blue to green, each weighed by its stage's vertex colour, and the two always sum to the albedo.
TEST_P(VertexColors, TerrainBlendShowsEachStageWhereItsVertexColourLeavesRoom) {
  scene::Scene s;
  s.name = "terrain_blend";
  const int material = add_material(s, "terrain", true, false);
  s.materials[size_t(material)].diffuse_image = add_image(s, "green", 4, 4, [](int, int) { return glm::u8vec4(0, 255, 0, 255); });
  s.materials[size_t(material)].blend_diffuse_image =
      add_image(s, "blue", 4, 4, [](int, int) { return glm::u8vec4(0, 0, 255, 255); });
  scene::Mesh world;
  world.name = "_area0";
  add_coloured_quad(world, material, -100, 100, kBlack, kWhite);
  add_world_mesh(s, std::move(world));
  s.lights.push_back(point_light({0, 0, 150}, {600, 600, 600}));
  const core::FrameBuffer fb =
      render(*tracer_, s, camera_looking_down({0, 0, 400}, 0.5f, kSize, kSize), frame_params(K_MODE_ALBEDO, 16, 0, kSize));
  int checked = 0;
  for (int px = pixel_of(-95, 0).x; px <= pixel_of(95, 0).x; ++px) {
    const float x = pixel_centre_x(px);
    if (x < -96.0f || x > 96.0f) continue;
    const float t = (x + 100.0f) / 200.0f;   // the vertex colour's value here
    const glm::vec3 got = pixel(fb, px, kSize / 2);
    EXPECT_NEAR(got.x, 0.0f, 1e-4f) << "x = " << x;
    EXPECT_NEAR(got.y, kAlbedo * t, 0.01f) << "green stage at x = " << x;
    EXPECT_NEAR(got.z, kAlbedo * (1.0f - t), 0.01f) << "blue stage at x = " << x;
    ++checked;
  }
  EXPECT_GE(checked, 20);
}

INSTANTIATE_TEST_SUITE_P(Tracers, VertexColors, ::testing::ValuesIn(built_tracers()),
                         [](const ::testing::TestParamInfo<std::string>& info) { return info.param; });

// The tracers agree on the path-traced image (bounces pick up the tinted floor too), with the bound of
// agreement_test.cpp: the same per-pixel random numbers, so RMSE below 0.5% of the mean, far below the
// noise between two frames.
TEST(VertexColorsAgreement, EveryTracerMatchesEmbree) {
  if (!tracer_runs_here("embree")) GTEST_SKIP() << "needs the Embree tracer";
  auto embree = make_test_tracer("embree");
  const KCamera cam = camera_looking_down({0, 0, 400}, 0.5f, kSize, kSize);
  KFrameParams params = frame_params(K_MODE_PATH, 16, 2, kSize);
  params.frame_index = 7;
  const core::FrameBuffer reference = render(*embree, four_quads(), cam, params);
  KFrameParams other = params;
  other.frame_index = 8;
  double noise_mean = 0.0;
  const double noise = rgb_rmse(reference, render(*embree, four_quads(), cam, other), &noise_mean);
  int checked = 0;
  for (const std::string& kind : built_tracers()) {
    if (kind == "embree" || !tracer_runs_here(kind)) continue;
    SCOPED_TRACE(kind);
    auto tracer = make_test_tracer(kind);
    double mean = 0.0;
    const double error = rgb_rmse(reference, render(*tracer, four_quads(), cam, params), &mean);
    EXPECT_GT(mean, 0.01) << "the quads should be lit";
    EXPECT_LT(error, 0.005 * mean) << "RMSE " << error << " vs mean " << mean;
    EXPECT_GT(noise, 2.0 * error) << "frame-to-frame noise " << noise;
    ++checked;
  }
  if (checked == 0) GTEST_SKIP() << "no tracer besides Embree runs here";
}
