// Fog, blend and ambient lights as the engine draws them (doom3-content.md section 9), on every tracer
// the build has: fog along camera rays against the `_fog` table's closed form, a blend light's pixel
// ratio, an ambient light that an occluder does not shadow.
#include <gtest/gtest.h>

#include <cmath>

#include "test_scenes.h"
#include "test_tracers.h"

using namespace cohort;
using namespace cohort::test;

namespace {

class LightKinds : public EachTracer {};

int add_light_material(scene::Scene& s, const std::string& name, scene::LightKind kind) {
  scene::Material m;
  m.name = name;
  m.is_light_material = true;
  m.light_kind = kind;
  s.materials.push_back(m);
  return static_cast<int>(s.materials.size() - 1);
}

// Camera straight down from z = height over [-half_view, half_view]^2 at z = 0; world (x, y) -> pixel.
struct TopView {
  int n;
  float half_view;
  glm::ivec2 pixel_of(float x, float y) const {
    return {int((x / half_view * 0.5f + 0.5f) * float(n)), int((0.5f - y / half_view * 0.5f) * float(n))};
  }
};

double fog_opacity(double length, double distance) {
  if (length > distance) return 1.0;
  double b = std::min(255.0, 255.0 * (64.0 / 63.0) * length / distance);
  return 1.0 - std::pow(0.982, b);
}

}  // namespace

// Length of the ray eye + t d, 0 < t < tmax, inside the box |x|, |y| < half.xy, |z| < half.z.
double box_length(glm::dvec3 eye, glm::dvec3 d, glm::dvec3 half, double tmax) {
  double t0 = 0.0, t1 = tmax;
  for (int k = 0; k < 3; ++k) {
    if (std::fabs(d[k]) < 1e-12) {
      if (std::fabs(eye[k]) > half[k]) return 0.0;
      continue;
    }
    double a = (-half[k] - eye[k]) / d[k], b = (half[k] - eye[k]) / d[k];
    t0 = std::max(t0, std::min(a, b));
    t1 = std::min(t1, std::max(a, b));
  }
  return t1 > t0 ? t1 - t0 : 0.0;
}

// A black floor (no light) under a fog box reaching 100 units above and below it: each pixel is
// fog colour x (1 - 0.982^b) for the length its ray runs inside the box (to the floor, or through the
// box when it misses the floor); rays that pass beside the box stay black.
TEST_P(LightKinds, FogOpacityFollowsTheFogTable) {
  scene::Scene s = floor_scene(100.0f, glm::vec3(0.0f));
  const float distance = 300.0f;
  const glm::vec3 fog_colour(0.5f, 0.6f, 0.7f);
  const glm::dvec3 half(130, 130, 100);
  int mat = add_light_material(s, "lights/fog", scene::LightKind::Fog);
  s.materials[size_t(mat)].light_stage_alpha = distance;
  scene::Light fog = point_light({0, 0, 0}, glm::vec3(half), fog_colour);
  fog.material = mat;
  s.lights.push_back(fog);
  // Plain lights after the fog light, too far away to light anything here: the fog loop covers only the
  // range holding fog and blend lights (KFrameParams.volume_light_begin/end), which must still hold it.
  for (int i = 0; i < 2; ++i) s.lights.push_back(point_light({5000.0 + 100.0 * i, 5000, 0}, glm::vec3(10), glm::vec3(1)));

  const int n = 48;
  const glm::dvec3 eye(0, 0, 300);
  KCamera cam = camera_looking_down(glm::vec3(eye), 0.8f, n, n);  // [-240, 240] at z = 0: 10 units a pixel
  core::FrameBuffer fb = render(*tracer_, s, cam, frame_params(K_MODE_DIRECT, 16, 0, n));
  int floor_pixels = 0, miss_pixels = 0, clear_pixels = 0;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      // The expected opacity over the pixel's area, from a 4x4 grid of rays.
      double a = 0.0, a_min = 1.0, a_max = 0.0;
      bool hits_floor = false;
      const int sub = 4;
      for (int j = 0; j < sub; ++j)
        for (int i = 0; i < sub; ++i) {
          glm::dvec3 p(floor_point(cam, x + (i + 0.5f) / sub, y + (j + 0.5f) / sub));
          glm::dvec3 d = glm::normalize(p - eye);
          bool on_floor = std::fabs(p.x) < 100.0 && std::fabs(p.y) < 100.0;
          hits_floor = hits_floor || on_floor;
          double a_ray = fog_opacity(box_length(eye, d, half, on_floor ? glm::length(p - eye) : 1e30), distance);
          a += a_ray;
          a_min = std::min(a_min, a_ray);
          a_max = std::max(a_max, a_ray);
        }
      a /= sub * sub;
      // Pixels straddling an edge of the box or the floor average a step: noisy at 16 samples, skipped.
      if (a_max - a_min > 0.1 * a_max) continue;
      glm::vec3 got = pixel(fb, x, y);
      EXPECT_NEAR(got.x, fog_colour.x * a, 0.02 * a + 2e-3) << "pixel " << x << "," << y;
      EXPECT_NEAR(got.z, fog_colour.z * a, 0.02 * a + 2e-3) << "pixel " << x << "," << y;
      if (a == 0.0) {
        EXPECT_EQ(got.x, 0.0f) << "pixel " << x << "," << y << " passes beside the fog";
        ++clear_pixels;
      } else {
        (hits_floor ? floor_pixels : miss_pixels) += 1;
      }
    }
  EXPECT_GT(floor_pixels, 10);
  EXPECT_GT(miss_pixels, 10);
  EXPECT_GT(clear_pixels, 10);
}

// A `blend filter` light multiplies the lit floor inside its volume by its colour (a white falloff
// image: no fade) and leaves it alone outside; it casts no light of its own.
TEST_P(LightKinds, BlendLightMultipliesInsideItsVolume) {
  auto make = [](bool with_blend) {
    scene::Scene s = floor_scene(300.0f, glm::vec3(0.5f));
    s.lights.push_back(point_light({0, 0, 200}, {600, 600, 600}));
    if (with_blend) {
      int mat = add_light_material(s, "lights/blend", scene::LightKind::Blend);
      s.materials[size_t(mat)].falloff_image =
          add_image(s, "white", 1, 1, [](int, int) { return glm::u8vec4(255, 255, 255, 255); });
      scene::Light blend = point_light({60, 0, 0}, {40, 40, 40}, {0.5f, 0.25f, 1.0f});
      blend.material = mat;
      s.lights.push_back(blend);
    }
    return s;
  };
  const int n = 60;
  TopView view{n, 150.0f};
  KCamera cam = camera_looking_down({0, 0, 300}, 0.5f, n, n);
  core::FrameBuffer plain = render(*tracer_, make(false), cam, frame_params(K_MODE_DIRECT, 4, 0, n));
  core::FrameBuffer blended = render(*tracer_, make(true), cam, frame_params(K_MODE_DIRECT, 4, 0, n));
  glm::ivec2 in = view.pixel_of(62.5f, 2.5f), out = view.pixel_of(-62.5f, 2.5f);
  glm::vec3 base_in = pixel(plain, in.x, in.y), got_in = pixel(blended, in.x, in.y);
  ASSERT_GT(base_in.x, 0.05f);
  EXPECT_NEAR(got_in.x / base_in.x, 0.5f, 0.01f);
  EXPECT_NEAR(got_in.y / base_in.y, 0.25f, 0.01f);
  EXPECT_NEAR(got_in.z / base_in.z, 1.0f, 0.01f);
  EXPECT_EQ(pixel(blended, out.x, out.y), pixel(plain, out.x, out.y)) << "outside the blend volume";
}

// An ambient light lights the floor under an occluder as if it were not there, with no N.L falloff
// toward the light: albedo x 2 (r_lightScale) x window x 0.78 (the `_ambient` vector's N.L on a flat
// surface). The same light as a normal light is shadowed.
TEST_P(LightKinds, AmbientLightIsNotShadowed) {
  auto make = [](bool occluder, scene::LightKind kind) {
    scene::Scene s = floor_scene(200.0f, glm::vec3(0.5f));
    scene::Light l = point_light({0, 0, 100}, {400, 400, 400});
    l.material = add_light_material(s, "lights/kind", kind);
    s.lights.push_back(l);
    if (occluder) add_occluder(s, add_diffuse_material(s, "occluder", glm::vec3(0.5f)));
    return s;
  };
  // A narrow camera grazing the floor from (0, -300, 10) sees the origin below the occluder.
  const int n = 16;
  KCamera cam = camera_looking_at({0, -300, 10}, {0, 0, 0}, 0.01f, n, n);
  auto centre = [&](const scene::Scene& s) {
    core::FrameBuffer fb = render(*tracer_, s, cam, frame_params(K_MODE_DIRECT, 4, 0, n));
    return pixel(fb, n / 2, n / 2).x;
  };
  const float window = (1.0f - 0.25f * 0.25f) * (1.0f - 0.25f * 0.25f);
  const float expected = 0.5f * 2.0f * window * 0.78f;
  EXPECT_NEAR(centre(make(false, scene::LightKind::Ambient)), expected, 0.02f * expected);
  EXPECT_NEAR(centre(make(true, scene::LightKind::Ambient)), expected, 0.02f * expected);
  EXPECT_LT(centre(make(true, scene::LightKind::Normal)), 0.01f * expected);
}

INSTANTIATE_TEST_SUITE_P(Tracers, LightKinds, ::testing::ValuesIn(built_tracers()),
                         [](const ::testing::TestParamInfo<std::string>& info) { return info.param; });
