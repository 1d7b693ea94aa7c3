// Environment cube-map stages on every tracer the build has (docs/sky.md, "Environment cube maps"):
// chrome and glass with `texgen reflect` show the cube face the view reflects into, `texgen normal` the
// face of the vertex normal, times the stage colour, added over what the surface otherwise shows; and
// the Embree and OpenCL tracers agree on a lit room with chrome and glass.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include "cohort/scene/cube_map.h"
#include "test_scenes.h"
#include "test_tracers.h"

using namespace cohort;
using namespace cohort::test;

namespace {

class Environment : public EachTracer {};

// One colour per GL face +X, -X, +Y, -Y, +Z, -Z, channels 0 or 255 only (exact after sRGB decoding).
const glm::u8vec4 kFaceColours[6] = {{255, 0, 0, 255},   {0, 255, 255, 255}, {0, 255, 0, 255},
                                     {255, 0, 255, 255}, {0, 0, 255, 255},   {255, 255, 0, 255}};
enum Face { PosX, NegX, PosY, NegY, PosZ, NegZ };

glm::vec3 face_colour(int face) { return glm::vec3(kFaceColours[face]) / 255.0f; }

// A material with an environment stage over a six-colour cube; lit (black diffuse, no specular: only
// the stage shows) or glass (an additive layer of nothing but the stage).
int add_environment_material(scene::Scene& s, const std::string& name, bool glass, bool by_normal,
                             glm::vec3 colour) {
  const int first = int(s.images.size());
  for (int face = 0; face < 6; ++face)
    add_image(s, "env/six" + std::string(scene::cube_face_suffix(scene::CubeMapKind::Axis, face)), 2, 2,
              [face](int, int) { return kFaceColours[face]; });
  scene::Material m;
  m.name = name;
  m.blend = glass ? scene::BlendClass::Additive : scene::BlendClass::Opaque;
  m.translucent = glass;
  m.diffuse_color = glm::vec4(0.0f, 0.0f, 0.0f, 1.0f);
  m.specular_color = glm::vec4(0.0f, 0.0f, 0.0f, 1.0f);
  m.environment_cube_image = first;
  m.environment_by_normal = by_normal;
  m.environment_color = colour;
  s.materials.push_back(m);
  return int(s.materials.size() - 1);
}

// A 200 x 200 panel in the plane x = 0 facing +X.
void add_panel_facing_x(scene::Scene& s, int material) {
  scene::Mesh panel;
  panel.name = "_area0";
  add_quad(panel, material, {0, -100, -100}, {0, 100, -100}, {0, 100, 100}, {0, -100, 100}, {1, 0, 0});
  add_world_mesh(s, std::move(panel));
}

// A pane of `glass` in the plane x = 0 facing +X, and 50 units behind it a wall glowing (0, 0.25, 0).
void add_pane_over_glowing_wall(scene::Scene& s, int glass) {
  scene::Material wall;
  wall.name = "textures/test/glow";
  wall.emitter = true;
  wall.emissive_color = glm::vec4(0.0f, 0.25f, 0.0f, 1.0f);
  wall.diffuse_color = glm::vec4(0.0f, 0.0f, 0.0f, 1.0f);
  wall.specular_color = glm::vec4(0.0f, 0.0f, 0.0f, 1.0f);
  s.materials.push_back(wall);
  scene::Mesh mesh;
  mesh.name = "_area0";
  add_quad(mesh, glass, {0, -100, -100}, {0, 100, -100}, {0, 100, 100}, {0, -100, 100}, {1, 0, 0});
  add_quad(mesh, int(s.materials.size() - 1), {-50, -100, -100}, {-50, 100, -100}, {-50, 100, 100},
           {-50, -100, 100}, {1, 0, 0});
  add_world_mesh(s, std::move(mesh));
}

// A camera at `origin` looking at the world origin, image up +Z.
KCamera camera_at(glm::vec3 origin, int n) {
  glm::vec3 forward = glm::normalize(-origin), right = glm::normalize(glm::cross(forward, glm::vec3(0, 0, 1)));
  glm::vec3 up = glm::cross(right, forward);
  KCamera c{};
  for (int i = 0; i < 3; ++i) {
    c.origin[i] = origin[i];
    c.forward[i] = forward[i];
    c.right[i] = right[i];
    c.up[i] = up[i];
  }
  c.width = c.height = uint32_t(n);
  c.tan_half_fov_x = c.tan_half_fov_y = 0.05f;
  return c;
}

void expect_colour(glm::vec3 got, glm::vec3 want, const std::string& what) {
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], want[c], 1e-4f) << what << " channel " << c;
}

}  // namespace

// A chrome panel facing +X: seen head-on it reflects the face behind the camera (+X); seen from the
// -Y side at an angle the reflected view leans to +Y (the world direction picks the face, GL rule).
// With `texgen normal` the panel shows the face of its normal (+X) from either side. The stage colour
// multiplies the cube.
TEST_P(Environment, ChromeShowsTheFaceOfTheReflectedViewAndTexgenNormalTheNormals) {
  const int n = 5;
  const glm::vec3 colour(0.5f, 1.0f, 0.25f);
  for (bool by_normal : {false, true}) {
    scene::Scene s;
    s.name = "chrome";
    add_panel_facing_x(s, add_environment_material(s, "textures/test/chrome", false, by_normal, colour));
    const KFrameParams params = frame_params(K_MODE_PATH, 2, 0, n);
    const std::string what = GetParam() + (by_normal ? " texgen normal" : " texgen reflect");
    const glm::vec3 head_on = pixel(render(*tracer_, s, camera_at({300, 0, 0}, n), params), n / 2, n / 2);
    expect_colour(head_on, colour * face_colour(PosX), what + ", head-on");
    // Along (-1, 2, 0): reflected about +X it is (1, 2, 0), major axis +Y.
    const glm::vec3 oblique = pixel(render(*tracer_, s, camera_at({150, -300, 0}, n), params), n / 2, n / 2);
    expect_colour(oblique, colour * face_colour(by_normal ? PosX : PosY), what + ", from -Y");
    // Along (-1, 0, -2) from above: reflected (1, 0, -2), major axis -Z.
    const glm::vec3 from_above = pixel(render(*tracer_, s, camera_at({150, 0, 300}, n), params), n / 2, n / 2);
    expect_colour(from_above, colour * face_colour(by_normal ? PosX : NegZ), what + ", from above");
  }
}

// With a bump stage the reflection is about the normal map's normal (the engine's bumpyEnvironment): a
// panel facing +X whose normal map tilts every normal 60 degrees toward its tangent (+Y) reflects a
// head-on view to (-1/2, sqrt(3)/2, 0), the +Y face, where the flat panel shows +X.
TEST_P(Environment, BumpMappedChromeReflectsAboutTheNormalMapsNormal) {
  const int n = 5;
  for (bool bumpy : {false, true}) {
    scene::Scene s;
    s.name = "bumpy_chrome";
    const int chrome = add_environment_material(s, "textures/test/chrome", false, false, glm::vec3(1.0f));
    if (bumpy) {
      // Tangent-space (sin 60, 0, cos 60), X in R, stored as (n + 1) / 2.
      const int normal_map = add_image(s, "textures/test/tilted_local", 2, 2,
                                       [](int, int) { return glm::u8vec4(238, 128, 191, 255); });
      s.images[size_t(normal_map)].is_normal_map = true;
      s.materials[size_t(chrome)].normal_image = normal_map;
    }
    add_panel_facing_x(s, chrome);
    const glm::vec3 got =
        pixel(render(*tracer_, s, camera_at({300, 0, 0}, n), frame_params(K_MODE_PATH, 2, 0, n)), n / 2, n / 2);
    expect_colour(got, face_colour(bumpy ? PosY : PosX), GetParam() + (bumpy ? " bump-mapped" : " flat") + " chrome");
  }
}

// The spaces: `texgen reflect` reads the cube by the world direction, `texgen normal` by the normal as
// the model stores it. A chrome panel facing +X in its model, turned a quarter turn about Z by its entity
// (so facing +Y in the world) and seen head-on from +Y, reflects the +Y face; by its normal it shows +X.
TEST_P(Environment, ReflectReadsTheWorldDirectionAndNormalTheModelsNormal) {
  const int n = 5;
  for (bool by_normal : {false, true}) {
    scene::Scene s;
    s.name = "turned_chrome";
    const int chrome = add_environment_material(s, "textures/test/chrome", false, by_normal, glm::vec3(1.0f));
    scene::Mesh panel;
    panel.name = "panel";
    add_quad(panel, chrome, {0, -100, -100}, {0, 100, -100}, {0, 100, 100}, {0, -100, 100}, {1, 0, 0});
    s.meshes.push_back(panel);
    scene::Entity e;
    e.name = e.classname = "func_static";
    e.mesh = int(s.meshes.size() - 1);
    e.axis = glm::mat3(glm::vec3(0, 1, 0), glm::vec3(-1, 0, 0), glm::vec3(0, 0, 1));   // model +X -> world +Y
    s.entities.push_back(e);
    const glm::vec3 got =
        pixel(render(*tracer_, s, camera_at({0, 300, 0}, n), frame_params(K_MODE_PATH, 2, 0, n)), n / 2, n / 2);
    expect_colour(got, face_colour(by_normal ? PosX : PosY),
                  GetParam() + (by_normal ? " texgen normal" : " texgen reflect") + ", turned panel");
  }
}

// Glass that is nothing but its reflection adds the reflected face to what is seen through it: a pane
// in front of a glowing wall shows the wall plus the cube.
TEST_P(Environment, GlassAddsItsReflectionToWhatIsBehindIt) {
  const int n = 5;
  scene::Scene s;
  s.name = "glass";
  const int glass = add_environment_material(s, "textures/test/glass", true, false, glm::vec3(0.5f));
  add_pane_over_glowing_wall(s, glass);
  const glm::vec3 got = pixel(render(*tracer_, s, camera_at({300, 0, 0}, n), frame_params(K_MODE_PATH, 2, 0, n)),
                              n / 2, n / 2);
  expect_colour(got, 0.5f * face_colour(PosX) + glm::vec3(0.0f, 0.25f, 0.0f), GetParam() + ", glass over the wall");
}

// A filter glass (a modulate layer of half the light) with a reflection: written after the filter stage
// the reflection is added over the filtered wall; written before it, the filter darkens it too (the
// engine draws stages in order).
TEST_P(Environment, AReflectionWrittenBeforeTheFilterIsFiltered) {
  const int n = 5;
  for (bool under : {false, true}) {
    scene::Scene s;
    s.name = "filter_glass";
    const int glass = add_environment_material(s, "textures/test/filter_glass", true, false, glm::vec3(0.5f));
    scene::Material& g = s.materials[size_t(glass)];
    g.blend = scene::BlendClass::Modulate;
    g.diffuse_color = glm::vec4(0.5f, 0.5f, 0.5f, 1.0f);
    g.environment_under_layer = under;
    add_pane_over_glowing_wall(s, glass);
    const glm::vec3 got =
        pixel(render(*tracer_, s, camera_at({300, 0, 0}, n), frame_params(K_MODE_PATH, 2, 0, n)), n / 2, n / 2);
    const glm::vec3 reflection = 0.5f * face_colour(PosX), filtered_wall(0.0f, 0.125f, 0.0f);
    expect_colour(got, (under ? 0.5f : 1.0f) * reflection + filtered_wall,
                  GetParam() + (under ? ", reflection under the filter" : ", reflection over the filter"));
  }
}

INSTANTIATE_TEST_SUITE_P(Tracers, Environment, ::testing::ValuesIn(built_tracers()),
                         [](const ::testing::TestParamInfo<std::string>& info) { return info.param; });

// A lit room with a chrome box and a glass pane, bounces on: the Embree and OpenCL tracers draw the
// same image (the agreement tests' bound: RMSE under 0.5% of the mean at 16 spp).
TEST(EnvironmentAgreement, EmbreeAndOpenCLImagesMatch) {
  std::vector<std::string> names = built_tracers();
  if (names.size() < 2 || !tracer_runs_here("opencl")) GTEST_SKIP() << "needs both the Embree and the OpenCL tracer";
  scene::Scene s = floor_scene(100.0f, glm::vec3(0.6f));
  const int chrome = add_environment_material(s, "textures/test/chrome", false, false, glm::vec3(0.6f));
  s.materials[size_t(chrome)].diffuse_color = glm::vec4(0.2f, 0.2f, 0.2f, 1.0f);
  const int glass = add_environment_material(s, "textures/test/glass", true, false, glm::vec3(0.3f));
  const int frosted = add_environment_material(s, "textures/test/frosted", true, true, glm::vec3(0.2f));
  s.meshes.push_back(box_mesh("chrome_box", glm::vec3(20, 20, 20), chrome));
  scene::Mesh panes;
  panes.name = "panes";
  add_quad(panes, glass, {-30, 40, 0}, {30, 40, 0}, {30, 40, 60}, {-30, 40, 60}, {0, -1, 0});
  add_quad(panes, frosted, {40, -30, 0}, {40, 30, 0}, {40, 30, 60}, {40, -30, 60}, {-1, 0, 0});
  s.meshes.push_back(panes);
  for (int i = 0; i < 2; ++i) {
    scene::Entity e;
    e.name = e.classname = "func_static";
    e.mesh = int(s.meshes.size()) - 2 + i;
    if (i == 0) e.origin = {0, 0, 20};
    s.entities.push_back(e);
  }
  s.lights.push_back(point_light({-40, -30, 100}, {300, 300, 300}));
  expect_embree_and_opencl_agree(s, core::make_camera({-90, -90, 60}, {45.0f, 15.0f}, 90.0f, 48, 36), "environment room");
}
