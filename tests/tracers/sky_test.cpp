// Sky surfaces and noSelfShadow on every tracer the build has (docs/sky.md): a camera ray that reaches a
// sky sees the cube map along its direction (checked against the six camera views a cameraCubeMap
// is made of, so face choice and orientation both count), sky surfaces block shadow rays unless
// noShadows, camera misses stay black, noSelfShadow surfaces do not shadow each other but do shadow
// ordinary ones; and the Embree and OpenCL tracers agree on a scene lit through a sky.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include "cohort/scene/cube_map.h"
#include "test_scenes.h"
#include "test_tracers.h"

using namespace cohort;
using namespace cohort::test;

namespace {

class Sky : public EachTracer {};

// The six images of a cameraCubeMap, in the file order _forward _back _left _right _up _down, and
// the views they are (doom3-content.md section 8): forward, back, left and right look along +X, -X,
// +Y, -Y with image-up +Z; up and down are the forward view pitched up and down.
struct CameraView {
  glm::vec3 forward, right, up;
};
const CameraView kCameraViews[6] = {
    {{1, 0, 0}, {0, -1, 0}, {0, 0, 1}},  {{-1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, {{0, 1, 0}, {1, 0, 0}, {0, 0, 1}},
    {{0, -1, 0}, {-1, 0, 0}, {0, 0, 1}}, {{0, 0, 1}, {0, -1, 0}, {-1, 0, 0}}, {{0, 0, -1}, {0, -1, 0}, {1, 0, 0}},
};

// Colours with channels 0 or 255 only: sRGB decoding leaves them exact, so pixels compare exactly.
glm::u8vec4 quadrant_colour(int image, int quadrant) {
  static const glm::u8vec4 palette[7] = {{255, 0, 0, 255},   {0, 255, 0, 255},   {0, 0, 255, 255},  {255, 255, 0, 255},
                                         {255, 0, 255, 255}, {0, 255, 255, 255}, {255, 255, 255, 255}};
  return palette[(image + 2 * quadrant) % 7];
}

// Camera image `image`, 4x4 texels: each 2x2 quadrant (0 top-left, 1 top-right, 2 bottom-left,
// 3 bottom-right) one colour.
scene::Image camera_image(int image) {
  scene::Image img;
  img.name = std::string("env/test") + scene::cube_face_suffix(scene::CubeMapKind::Camera, image);
  img.width = img.height = 4;
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x) {
      glm::u8vec4 c = quadrant_colour(image, (y / 2) * 2 + x / 2);
      img.rgba.insert(img.rgba.end(), {c.r, c.g, c.b, c.a});
    }
  return img;
}

// A sky material over the camera images turned into GL faces as the loader turns them.
int add_sky_material(scene::Scene& s, bool no_shadows = false) {
  scene::Material m;
  m.name = "textures/test/sky";
  m.blend = scene::BlendClass::Sky;
  m.no_shadows = no_shadows;
  m.emissive_color = glm::vec4(1.0f);
  m.diffuse_color = glm::vec4(0.0f, 0.0f, 0.0f, 1.0f);
  m.sky_cube_image = int(s.images.size());
  for (int face = 0; face < 6; ++face) s.images.push_back(scene::camera_image_to_cube_face(camera_image(face), face));
  s.materials.push_back(m);
  return int(s.materials.size() - 1);
}

KCamera camera_along(glm::vec3 origin, const CameraView& v, float tan_half_fov, int n) {
  KCamera c{};
  for (int i = 0; i < 3; ++i) {
    c.origin[i] = origin[i];
    c.forward[i] = v.forward[i];
    c.right[i] = v.right[i];
    c.up[i] = v.up[i];
  }
  c.width = c.height = uint32_t(n);
  c.tan_half_fov_x = c.tan_half_fov_y = tan_half_fov;
  return c;
}

glm::vec3 linear(glm::u8vec4 c) { return glm::vec3(c) / 255.0f; }

// Direct light only, every light with one hard shadow ray: pixels are exact.
KFrameParams direct_params(int n) {
  KFrameParams p = frame_params(K_MODE_DIRECT, 4, 0, n);
  p.light_sampling = K_LIGHTS_EVERY;
  p.emissive_samples = 0;
  return p;
}

}  // namespace

// Standing inside a sky box and looking through each of the six camera views at 90 degrees, the
// tracer draws that camera image: each quadrant's colour where the image has it. With the sky box an
// entity turned a quarter turn about Z, the cube turns with it (the lookup is in model space).
TEST_P(Sky, CameraRaysSeeTheCubeAlongTheirDirection) {
  for (bool turned : {false, true}) {
    scene::Scene s;
    s.name = "sky";
    int sky = add_sky_material(s);
    scene::Mesh box = box_mesh("sky_box", glm::vec3(100.0f), sky);
    const glm::mat3 quarter_turn(glm::vec3(0, 1, 0), glm::vec3(-1, 0, 0), glm::vec3(0, 0, 1));
    if (turned) {
      s.meshes.push_back(box);
      scene::Entity e;
      e.name = e.classname = "func_static";
      e.mesh = 0;
      e.axis = quarter_turn;
      s.entities.push_back(e);
    } else {
      add_world_mesh(s, box);
    }
    const int n = 8;
    for (int image = 0; image < 6; ++image) {
      CameraView v = kCameraViews[image];
      if (turned) v = {quarter_turn * v.forward, quarter_turn * v.right, quarter_turn * v.up};
      core::FrameBuffer fb = render(*tracer_, s, camera_along(glm::vec3(10, -20, 5), v, 1.0f, n),
                                    frame_params(K_MODE_PATH, 4, 2, n));
      for (int quadrant = 0; quadrant < 4; ++quadrant) {
        // Pixels 2 and 5 of 8 see only texels of one quadrant, whatever the jitter.
        int x = quadrant % 2 ? 5 : 2, y = quadrant / 2 ? 5 : 2;
        glm::vec3 want = linear(quadrant_colour(image, quadrant)), got = pixel(fb, x, y);
        for (int c = 0; c < 3; ++c)
          EXPECT_NEAR(got[c], want[c], 1e-4f) << GetParam() << (turned ? " turned" : "") << " image "
                                              << scene::cube_face_suffix(scene::CubeMapKind::Camera, image)
                                              << " quadrant " << quadrant << " channel " << c;
      }
    }
  }
}

// A lit floor under a sky ceiling that covers its left half: the left half is in the sky's shadow
// (a sky is no light and blocks light like any opaque surface), the right half is lit, and with a
// noShadows sky both halves are lit. The camera sits under the ceiling; its rays that leave the
// floor's edge miss everything and stay black.
TEST_P(Sky, SkySurfacesBlockShadowRaysAndMissesStayBlack) {
  auto make = [](bool sky_no_shadows) {
    scene::Scene s = floor_scene(50.0f, glm::vec3(0.5f));
    int sky = add_sky_material(s, sky_no_shadows);
    scene::Mesh ceiling;
    ceiling.name = "ceiling";
    add_quad(ceiling, sky, {-60, -60, 80}, {0, -60, 80}, {0, 60, 80}, {-60, 60, 80}, {0, 0, -1});
    s.meshes.push_back(ceiling);
    scene::Entity e;
    e.name = e.classname = "func_static";
    e.mesh = int(s.meshes.size() - 1);
    s.entities.push_back(e);
    s.lights.push_back(point_light({0, 0, 150}, {400, 400, 400}));
    return s;
  };
  const int n = 20;
  // From z = 60 (under the ceiling at 80) looking down over [-60, 60]: the outer pixels miss the floor.
  KCamera cam = camera_looking_down({0, 0, 60}, 1.0f, n, n);
  core::FrameBuffer shadowed = render(*tracer_, make(false), cam, direct_params(n));
  core::FrameBuffer lit = render(*tracer_, make(true), cam, direct_params(n));
  glm::vec3 left = pixel(shadowed, 6, 10), right = pixel(shadowed, 13, 10);
  EXPECT_GT(right.x, 0.05f) << "the uncovered half is lit";
  EXPECT_EQ(left.x, 0.0f) << "the sky shadows the covered half";
  EXPECT_NEAR(pixel(lit, 6, 10).x, pixel(lit, 13, 10).x, 0.02f * right.x) << "a noShadows sky lets light through";
  EXPECT_EQ(pixel(shadowed, 0, 10), glm::vec3(0.0f)) << "a camera miss is black";
  EXPECT_EQ(pixel(shadowed, 19, 0), glm::vec3(0.0f)) << "a camera miss is black";
}

// A floor and a slab hanging between it and the light, each with or without noSelfShadow: the floor
// under the slab is shadowed unless both are noSelfShadow (the engine's RB_ARB2_DrawInteractions:
// noSelfShadow surfaces do not shadow each other, whichever entity they belong to, but shadow others).
TEST_P(Sky, NoSelfShadowSurfacesDoNotShadowEachOther) {
  auto centre = [&](bool floor_nss, bool slab_nss) {
    scene::Scene s;
    s.name = "no_self_shadow";
    int floor_mat = add_diffuse_material(s, "floor", glm::vec3(0.5f));
    int slab_mat = add_diffuse_material(s, "slab", glm::vec3(0.5f));
    s.materials[size_t(floor_mat)].no_self_shadow = floor_nss;
    s.materials[size_t(slab_mat)].no_self_shadow = slab_nss;
    scene::Mesh mesh;
    mesh.name = "_area0";
    add_quad(mesh, floor_mat, {-50, -50, 0}, {50, -50, 0}, {50, 50, 0}, {-50, 50, 0}, {0, 0, 1});
    add_world_mesh(s, std::move(mesh));
    s.meshes.push_back(box_mesh("slab", glm::vec3(20, 20, 2), slab_mat));
    scene::Entity e;
    e.name = e.classname = "func_static";
    e.mesh = int(s.meshes.size() - 1);
    e.origin = {0, 0, 70};
    s.entities.push_back(e);
    s.lights.push_back(point_light({0, 0, 150}, {400, 400, 400}));
    const int n = 9;
    KCamera cam = camera_looking_down({0, 0, 40}, 0.2f, n, n);   // under the slab
    return pixel(render(*tracer_, s, cam, direct_params(n)), n / 2, n / 2).x;
  };
  const float unshadowed = centre(true, true);
  EXPECT_GT(unshadowed, 0.05f) << "noSelfShadow floor under a noSelfShadow slab: lit";
  EXPECT_EQ(centre(false, false), 0.0f) << "ordinary floor, ordinary slab: shadowed";
  EXPECT_EQ(centre(false, true), 0.0f) << "a noSelfShadow slab still shadows an ordinary floor";
  EXPECT_EQ(centre(true, false), 0.0f) << "an ordinary slab shadows a noSelfShadow floor";
}

INSTANTIATE_TEST_SUITE_P(Tracers, Sky, ::testing::ValuesIn(built_tracers()),
                         [](const ::testing::TestParamInfo<std::string>& info) { return info.param; });

// A room whose ceiling is sky, lit by a light and by bounces off the sky, with a noSelfShadow prop:
// the Embree and OpenCL tracers draw the same image (the agreement tests' bound: RMSE under 0.5% of
// the mean at 16 spp).
TEST(SkyAgreement, EmbreeAndOpenCLImagesMatch) {
  std::vector<std::string> names = built_tracers();
  if (names.size() < 2 || !tracer_runs_here("opencl")) GTEST_SKIP() << "needs both the Embree and the OpenCL tracer";
  scene::Scene s = floor_scene(100.0f, glm::vec3(0.6f));
  int sky = add_sky_material(s);
  int prop_mat = add_diffuse_material(s, "prop", glm::vec3(0.7f, 0.5f, 0.3f));
  s.materials[size_t(prop_mat)].no_self_shadow = true;
  scene::Mesh ceiling;
  ceiling.name = "ceiling";
  add_quad(ceiling, sky, {-100, -100, 120}, {100, -100, 120}, {100, 100, 120}, {-100, 100, 120}, {0, 0, -1});
  s.meshes.push_back(ceiling);
  s.meshes.push_back(box_mesh("prop", glm::vec3(20, 20, 20), prop_mat));
  for (int i = 0; i < 2; ++i) {
    scene::Entity e;
    e.name = e.classname = "func_static";
    e.mesh = int(s.meshes.size()) - 2 + i;
    if (i == 1) e.origin = {10, 0, 20};
    s.entities.push_back(e);
  }
  s.lights.push_back(point_light({-40, 30, 100}, {300, 300, 300}));
  expect_embree_and_opencl_agree(s, core::make_camera({-90, -90, 60}, {45.0f, 10.0f}, 90.0f, 48, 36), "sky room");
}
