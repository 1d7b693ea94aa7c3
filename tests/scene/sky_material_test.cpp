// Sky materials as idTech 4 reads them (doom3-content.md section 8): cubeMap / cameraCubeMap stages,
// texgen skybox / wobbleSky, the six faces loaded in GL order (camera faces turned as
// R_LoadCubeImages turns them), a broken cube a warning naming the material's file:line; and the
// noSelfShadow material flag.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "cohort/scene/image_library.h"
#include "cohort/scene/material_build.h"
#include "cohort/scene/material_file.h"
#include "cohort/scene/material_registers.h"

using namespace cohort::scene;
namespace fs = std::filesystem;

namespace {

const MaterialDecl* find(const MaterialFile& f, const std::string& name) {
  for (const auto& m : f.materials)
    if (m.name == name) return &m;
  return nullptr;
}

bool has_warning(const std::vector<std::string>& warnings, const std::string& part) {
  for (const auto& w : warnings)
    if (w.find(part) != std::string::npos) return true;
  return false;
}

// An uncompressed 24-bit top-down TGA whose texel (x, y) is colour(x, y).
template <class Colour>
void write_tga(const fs::path& path, int w, int h, Colour colour) {
  std::string bytes(18, '\0');
  bytes[2] = 2;
  bytes[12] = char(w);
  bytes[14] = char(h);
  bytes[16] = 24;
  bytes[17] = 0x20;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      glm::u8vec3 c = colour(x, y);
      bytes += char(c.b);
      bytes += char(c.g);
      bytes += char(c.r);
    }
  fs::create_directories(path.parent_path());
  std::ofstream(path, std::ios::binary) << bytes;
}

// Face `face` of a test cube: texel (x, y) holds (face, x, y) so that every move shows.
glm::u8vec3 marker(int face, int x, int y) { return {uint8_t(40 * face + 10), uint8_t(100 + x), uint8_t(150 + y)}; }

const uint8_t* texel(const Image& image, int x, int y) { return &image.rgba[(size_t(y) * image.width + x) * 4]; }

struct Fixture {
  fs::path base;
  Vfs vfs;
  std::vector<Image> images;
  std::vector<std::string> warnings;
  ImageLibrary library{vfs, images, warnings};
  explicit Fixture(const std::string& name) : base(fs::path(COHORT_BINARY_DIR) / "test_tmp" / name) {
    fs::remove_all(base);
    fs::create_directories(base);
  }
  // The VFS lists a folder when it is added: call once the files are written.
  void mount() { vfs.add_search_path(base); }
  void write_cube(const std::string& name, CubeMapKind kind, int size = 3) {
    for (int face = 0; face < 6; ++face)
      write_tga(base / (name + cube_face_suffix(kind, face) + ".tga"), size, size,
                [&](int x, int y) { return marker(face, x, y); });
  }
};

const char* kSkyMaterials = R"(
textures/sky/axis {
  noShadows
  {
    blend add
    cubeMap env/axis
    texgen skybox
    colored
  }
}
textures/sky/camera {
  { cameraCubeMap env/camera.tga texgen skybox }
}
textures/sky/wobble {
  { cameraCubeMap env/camera texgen wobbleSky 30 1 2 }
}
textures/sky/missing_face {
  { cubeMap env/missing
    texgen skybox }
}
textures/glass/reflective {
  diffusemap textures/glass/g
  { blend add cubeMap env/axis texgen reflect }
}
models/prop/leaves {
  noSelfShadow
  diffusemap models/prop/leaves
}
textures/sky/bad_texgen {
  { cubeMap env/axis texgen sphere }
}
)";

// Environment cube-map stages (glass and chrome): `texgen reflect` and `texgen normal`.
const char* kEnvironmentMaterials = R"(
textures/glass/clear {
  translucent
  { blend add cubeMap env/axis texgen reflect }
}
textures/metal/chrome {
  diffusemap textures/metal/chrome
  bumpmap textures/metal/chrome_local
  {
    blend gl_dst_alpha, gl_one
    cubeMap env/axis
    texgen reflect
    red 0.5 green 0.25 blue parm4
  }
}
textures/glass/tinted {
  { blend filter map textures/glass/tint }
  { blend add cameraCubeMap env/camera texgen normal rgb 0.5 + time }
}
textures/glass/filtered_reflection {
  { blend filter cubeMap env/axis texgen reflect }
}
textures/glass/reflection_under_tint {
  { blend add cubeMap env/axis texgen reflect }
  { blend filter map textures/glass/tint }
}
)";

}  // namespace

TEST(SkyMaterials, CubeMapStagesAndTexgensAreParsed) {
  MaterialTables tables;
  MaterialFile f = parse_materials(kSkyMaterials, "sky.mtr", tables);
  const MaterialDecl* axis = find(f, "textures/sky/axis");
  ASSERT_NE(axis, nullptr);
  ASSERT_EQ(axis->stages.size(), 1u);
  EXPECT_EQ(axis->stages[0].cube_kind, CubeMapKind::Axis);
  EXPECT_EQ(axis->stages[0].cube_map, "env/axis");
  EXPECT_EQ(axis->stages[0].texgen, TexGen::Skybox);
  EXPECT_EQ(axis->stages[0].blend, StageBlend::Add);
  const MaterialDecl* camera = find(f, "textures/sky/camera");
  ASSERT_NE(camera, nullptr);
  EXPECT_EQ(camera->stages.at(0).cube_kind, CubeMapKind::Camera);
  EXPECT_EQ(camera->stages.at(0).cube_map, "env/camera.tga");
  const MaterialDecl* wobble = find(f, "textures/sky/wobble");
  ASSERT_NE(wobble, nullptr);
  EXPECT_EQ(wobble->stages.at(0).texgen, TexGen::WobbleSky);
  EXPECT_FLOAT_EQ(wobble->stages.at(0).wobble_sky[0], 30.0f);
  EXPECT_FLOAT_EQ(wobble->stages.at(0).wobble_sky[2], 2.0f);
  EXPECT_EQ(find(f, "textures/glass/reflective")->stages.at(1).texgen, TexGen::Reflect);
  EXPECT_TRUE(find(f, "models/prop/leaves")->no_self_shadow);
  EXPECT_FALSE(axis->no_self_shadow);
  // An unknown texgen is a warning with file and line (line 30 of the text above), not a failure.
  EXPECT_TRUE(has_warning(f.warnings, "sky.mtr:30: material textures/sky/bad_texgen: unknown texgen 'sphere'"))
      << ::testing::PrintToString(f.warnings);
}

TEST(SkyMaterials, AxisCubeFacesLoadAsStoredInGlOrder) {
  Fixture fx("sky_axis_cube");
  fx.write_cube("env/axis", CubeMapKind::Axis);
  fx.mount();
  int first = fx.library.get_cube("env/axis", CubeMapKind::Axis, "m");
  EXPECT_TRUE(fx.warnings.empty()) << ::testing::PrintToString(fx.warnings);
  ASSERT_EQ(fx.images.size(), 6u);
  for (int face = 0; face < 6; ++face) {
    const Image& image = fx.images[size_t(first + face)];
    EXPECT_FALSE(image.is_placeholder);
    for (int y = 0; y < 3; ++y)
      for (int x = 0; x < 3; ++x) {
        glm::u8vec3 want = marker(face, x, y);
        EXPECT_EQ(texel(image, x, y)[0], want.r) << "face " << face;
        EXPECT_EQ(texel(image, x, y)[1], want.g) << "face " << face;
        EXPECT_EQ(texel(image, x, y)[2], want.b) << "face " << face;
      }
  }
  EXPECT_EQ(fx.library.get_cube("env/axis.tga", CubeMapKind::Axis, "m"), first) << "loaded once";
}

// R_LoadCubeImages: forward transposed; back transposed and flipped both ways; left flipped
// vertically; right flipped horizontally; up and down transposed.
TEST(SkyMaterials, CameraCubeFacesAreTurnedAsTheEngineTurnsThem) {
  Fixture fx("sky_camera_cube");
  fx.write_cube("env/camera", CubeMapKind::Camera);
  fx.mount();
  int first = fx.library.get_cube("env/camera", CubeMapKind::Camera, "m");
  EXPECT_TRUE(fx.warnings.empty()) << ::testing::PrintToString(fx.warnings);
  const int n = 3, last = n - 1;
  for (int face = 0; face < 6; ++face) {
    const Image& image = fx.images[size_t(first + face)];
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        int sx = x, sy = y;   // the camera image's texel that lands at (x, y)
        switch (face) {
          case 0: case 4: case 5: sx = y; sy = x; break;
          case 1: sx = last - y; sy = last - x; break;
          case 2: sy = last - y; break;
          case 3: sx = last - x; break;
        }
        glm::u8vec3 want = marker(face, sx, sy);
        EXPECT_EQ(texel(image, x, y)[1], want.g) << "face " << face << " at " << x << "," << y;
        EXPECT_EQ(texel(image, x, y)[2], want.b) << "face " << face << " at " << x << "," << y;
      }
  }
}

TEST(SkyMaterials, ABrokenCubeIsAWarningNamingTheFaceAndSixPlaceholders) {
  Fixture fx("sky_broken_cube");
  fx.write_cube("env/missing", CubeMapKind::Axis);
  fs::remove(fx.base / "env/missing_py.tga");
  write_tga(fx.base / "env/wide_nz.tga", 4, 3, [](int, int) { return glm::u8vec3(1); });
  for (int face = 0; face < 5; ++face)
    write_tga(fx.base / (std::string("env/wide") + cube_face_suffix(CubeMapKind::Axis, face) + ".tga"), 3, 3,
              [](int, int) { return glm::u8vec3(1); });
  fx.write_cube("env/mixed", CubeMapKind::Axis);
  write_tga(fx.base / "env/mixed_pz.tga", 2, 2, [](int, int) { return glm::u8vec3(1); });
  fx.mount();
  int first = fx.library.get_cube("env/missing", CubeMapKind::Axis, "sky.mtr:12: material textures/sky/missing_face");
  ASSERT_EQ(fx.warnings.size(), 1u);
  EXPECT_NE(fx.warnings[0].find("sky.mtr:12: material textures/sky/missing_face: cube map 'env/missing': face "
                                "'env/missing_py'"),
            std::string::npos)
      << fx.warnings[0];
  for (int face = 0; face < 6; ++face) EXPECT_TRUE(fx.images.at(size_t(first + face)).is_placeholder);

  fx.library.get_cube("env/wide", CubeMapKind::Axis, "m");
  EXPECT_TRUE(has_warning(fx.warnings, "face 'env/wide_nz' is 4x3, not square")) << ::testing::PrintToString(fx.warnings);

  fx.library.get_cube("env/mixed", CubeMapKind::Axis, "m");
  EXPECT_TRUE(has_warning(fx.warnings, "face 'env/mixed_pz' is 2 wide, face 'env/mixed_px' 3"))
      << ::testing::PrintToString(fx.warnings);
}

TEST(SkyMaterials, SkyStagesMakeSkyMaterialsAndReflectionsDoNot) {
  Fixture fx("sky_build");
  fx.write_cube("env/axis", CubeMapKind::Axis);
  fx.write_cube("env/camera", CubeMapKind::Camera);
  fx.mount();
  MaterialTables tables;
  MaterialFile f = parse_materials(kSkyMaterials, "sky.mtr", tables);
  Material axis = build_material(*find(f, "textures/sky/axis"), fx.library, false);
  EXPECT_EQ(axis.blend, BlendClass::Sky);
  EXPECT_TRUE(axis.no_shadows);
  EXPECT_FALSE(axis.emitter);
  ASSERT_GE(axis.sky_cube_image, 0);
  EXPECT_EQ(fx.images.at(size_t(axis.sky_cube_image)).name, "env/axis_px");
  EXPECT_EQ(fx.images.at(size_t(axis.sky_cube_image + 5)).name, "env/axis_nz");
  EXPECT_FALSE(fx.images.at(size_t(axis.sky_cube_image)).is_placeholder);
  EXPECT_EQ(axis.sky_axis, glm::mat3(1.0f));

  // wobbleSky 30 1 2 at time 0: Z' tilted 30 degrees from +Z toward +X, Y' = +Y, X' = Y' x Z'.
  Material wobble = build_material(*find(f, "textures/sky/wobble"), fx.library, false);
  EXPECT_EQ(wobble.blend, BlendClass::Sky);
  const float s = std::sin(glm::radians(30.0f)), c = std::cos(glm::radians(30.0f));
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(wobble.sky_axis[2][k], glm::vec3(s, 0, c)[k], 1e-6f);
    EXPECT_NEAR(wobble.sky_axis[1][k], glm::vec3(0, 1, 0)[k], 1e-6f);
    EXPECT_NEAR(wobble.sky_axis[0][k], glm::vec3(c, 0, -s)[k], 1e-6f);
  }

  // The wobble follows the frame's time: the registers are kept and evaluate to the engine's axes.
  ASSERT_TRUE(wobble.registers);
  EXPECT_NE(wobble.registers->depends & kDependsTime, 0u);
  RegisterInputs at_ten;
  at_ten.time = 10.0f;
  Material wobble_at_ten;
  evaluate_material(wobble, at_ten, wobble_at_ten);
  const glm::mat3 want = wobble_sky_axes(30.0f, 1.0f, 2.0f, 10.0f);
  for (int col = 0; col < 3; ++col)
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(wobble_at_ten.sky_axis[col][k], want[col][k], 1e-6f);
  EXPECT_GT(glm::length(wobble_at_ten.sky_axis[2] - wobble.sky_axis[2]), 0.1f) << "Z' moved in 10 s at 1 turn/min";
  EXPECT_FALSE(build_material(*find(f, "textures/sky/camera"), fx.library, false).registers)
      << "a skybox with a constant colour does not animate";

  // A cube map with texgen reflect on a lit surface is an environment reflection, not a sky.
  Material glass = build_material(*find(f, "textures/glass/reflective"), fx.library, false);
  EXPECT_EQ(glass.blend, BlendClass::Opaque);
  EXPECT_EQ(glass.sky_cube_image, -1);

  Material leaves = build_material(*find(f, "models/prop/leaves"), fx.library, false);
  EXPECT_TRUE(leaves.no_self_shadow);

  // A missing cube: still a sky (of placeholder faces), and the warning names the stage's file:line.
  Material missing = build_material(*find(f, "textures/sky/missing_face"), fx.library, false);
  EXPECT_EQ(missing.blend, BlendClass::Sky);
  EXPECT_TRUE(has_warning(fx.warnings, "sky.mtr:18: material textures/sky/missing_face: cube map 'env/missing': face "
                                       "'env/missing_px'"))
      << ::testing::PrintToString(fx.warnings);
}

// The rotation the engine's R_WobbleskyTexGen builds is a rotation (orthonormal, right-handed) at
// every time, and turns with the rotate speed about Z'.
TEST(SkyMaterials, WobbleSkyAxesStayARotation) {
  for (float t : {0.0f, 1.7f, 12.0f, 45.5f}) {
    glm::mat3 m = wobble_sky_axes(20.0f, 3.0f, 0.5f, t);
    for (int i = 0; i < 3; ++i) {
      EXPECT_NEAR(glm::length(m[i]), 1.0f, 1e-5f);
      for (int j = i + 1; j < 3; ++j) EXPECT_NEAR(glm::dot(m[i], m[j]), 0.0f, 1e-5f);
    }
    EXPECT_NEAR(glm::determinant(m), 1.0f, 1e-5f);
  }
  // No wobble: only the rotation about Z, a quarter turn after 30 s at half a turn per minute.
  glm::mat3 quarter = wobble_sky_axes(0.0f, 0.0f, 0.5f, 30.0f);
  EXPECT_NEAR(quarter[0].y, 1.0f, 1e-5f);
  EXPECT_NEAR(quarter[1].x, -1.0f, 1e-5f);
}

TEST(SkyMaterials, EnvironmentStagesAreParsed) {
  MaterialTables tables;
  MaterialFile f = parse_materials(kEnvironmentMaterials, "env.mtr", tables);
  EXPECT_TRUE(f.warnings.empty()) << ::testing::PrintToString(f.warnings);
  const MaterialDecl* clear = find(f, "textures/glass/clear");
  ASSERT_NE(clear, nullptr);
  ASSERT_EQ(clear->stages.size(), 1u);
  EXPECT_EQ(clear->stages[0].cube_kind, CubeMapKind::Axis);
  EXPECT_EQ(clear->stages[0].cube_map, "env/axis");
  EXPECT_EQ(clear->stages[0].texgen, TexGen::Reflect);
  EXPECT_EQ(clear->stages[0].blend, StageBlend::Add);
  EXPECT_EQ(clear->stages[0].line, 4);
  const MaterialDecl* chrome = find(f, "textures/metal/chrome");
  ASSERT_NE(chrome, nullptr);
  ASSERT_EQ(chrome->stages.size(), 3u);
  EXPECT_EQ(chrome->stages[2].texgen, TexGen::Reflect);
  EXPECT_EQ(chrome->stages[2].blend, StageBlend::Add) << "gl_dst_alpha, gl_one adds";
  EXPECT_FLOAT_EQ(chrome->stages[2].color.r, 0.5f);
  EXPECT_FLOAT_EQ(chrome->stages[2].color.g, 0.25f);
  const MaterialDecl* tinted = find(f, "textures/glass/tinted");
  ASSERT_NE(tinted, nullptr);
  ASSERT_EQ(tinted->stages.size(), 2u);
  EXPECT_EQ(tinted->stages[1].cube_kind, CubeMapKind::Camera);
  EXPECT_EQ(tinted->stages[1].texgen, TexGen::Normal);
}

// An environment stage gives the material its cube (six faces as a sky's), its texgen and its colour,
// drawn over the surface; the material keeps its class (lit chrome stays opaque, glass with nothing
// but a reflection is an additive layer, a filter under it keeps the filter), never a sky. Its colour
// follows the registers like any stage colour.
TEST(SkyMaterials, EnvironmentStagesGiveTheMaterialACubeAndKeepItsClass) {
  Fixture fx("environment_build");
  fx.write_cube("env/axis", CubeMapKind::Axis);
  fx.write_cube("env/camera", CubeMapKind::Camera);
  fx.mount();
  MaterialTables tables;
  MaterialFile f = parse_materials(kEnvironmentMaterials, "env.mtr", tables);

  Material clear = build_material(*find(f, "textures/glass/clear"), fx.library, false);
  EXPECT_EQ(clear.blend, BlendClass::Additive);
  EXPECT_TRUE(clear.translucent);
  EXPECT_FALSE(clear.emitter);
  EXPECT_EQ(clear.sky_cube_image, -1);
  ASSERT_GE(clear.environment_cube_image, 0);
  EXPECT_EQ(fx.images.at(size_t(clear.environment_cube_image)).name, "env/axis_px");
  EXPECT_EQ(fx.images.at(size_t(clear.environment_cube_image + 5)).name, "env/axis_nz");
  EXPECT_FALSE(clear.environment_by_normal);
  EXPECT_EQ(clear.environment_color, glm::vec3(1.0f));
  EXPECT_EQ(glm::vec3(clear.diffuse_color), glm::vec3(0.0f)) << "the layer itself adds nothing";
  EXPECT_FALSE(clear.registers);

  Material chrome = build_material(*find(f, "textures/metal/chrome"), fx.library, false);
  EXPECT_EQ(chrome.blend, BlendClass::Opaque);
  EXPECT_GE(chrome.normal_image, 0);
  EXPECT_EQ(chrome.environment_cube_image, clear.environment_cube_image) << "one cube, loaded once";
  EXPECT_EQ(chrome.environment_color, glm::vec3(0.5f, 0.25f, 0.0f));
  ASSERT_TRUE(chrome.registers) << "blue reads parm4";
  RegisterInputs parms;
  parms.parms[4] = 0.75f;
  Material chrome_tinted;
  evaluate_material(chrome, parms, chrome_tinted);
  EXPECT_EQ(chrome_tinted.environment_color, glm::vec3(0.5f, 0.25f, 0.75f));
  parms.parms[4] = 3.0f;
  evaluate_material(chrome, parms, chrome_tinted);
  EXPECT_EQ(chrome_tinted.environment_color.b, 1.0f) << "clamped as the fixed-function colour is";

  Material tinted = build_material(*find(f, "textures/glass/tinted"), fx.library, false);
  EXPECT_EQ(tinted.blend, BlendClass::Modulate);
  EXPECT_TRUE(tinted.environment_by_normal);
  EXPECT_FALSE(tinted.environment_under_layer) << "the filter is drawn first: the reflection goes over it";
  Material under = build_material(*find(f, "textures/glass/reflection_under_tint"), fx.library, false);
  EXPECT_EQ(under.blend, BlendClass::Modulate);
  EXPECT_GE(under.environment_cube_image, 0);
  EXPECT_TRUE(under.environment_under_layer) << "the reflection is drawn first: the filter darkens it";
  ASSERT_GE(tinted.environment_cube_image, 0);
  EXPECT_EQ(fx.images.at(size_t(tinted.environment_cube_image)).name, "env/camera_forward");
  ASSERT_TRUE(tinted.registers);
  EXPECT_NE(tinted.registers->depends & kDependsTime, 0u);
  RegisterInputs at_quarter;
  at_quarter.time = 0.25f;
  Material tinted_later;
  evaluate_material(tinted, at_quarter, tinted_later);
  EXPECT_NEAR(tinted_later.environment_color.r, 0.75f, 1e-6f);
  EXPECT_NEAR(tinted.environment_color.r, 0.5f, 1e-6f) << "time 0";

  // Only added reflections are drawn: another blend is a warning naming the stage's file:line.
  Material filtered = build_material(*find(f, "textures/glass/filtered_reflection"), fx.library, false);
  EXPECT_EQ(filtered.environment_cube_image, -1);
  EXPECT_EQ(filtered.blend, BlendClass::PassThrough);
  EXPECT_TRUE(has_warning(fx.warnings, "env.mtr:21: material textures/glass/filtered_reflection: environment cube "
                                       "map stage (texgen reflect) with a blend other than add is not drawn"))
      << ::testing::PrintToString(fx.warnings);
}
