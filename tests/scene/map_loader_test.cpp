#include <gtest/gtest.h>
#include <zip.h>

#include <fstream>

#include "cohort/scene/map_loader.h"
#include "test_files.h"

using namespace cohort::scene;
using cohort::scene::test::data_dir;
namespace fs = std::filesystem;

namespace {

const Material& material(const Scene& s, const std::string& name) {
  int i = s.find_material(name);
  EXPECT_GE(i, 0) << name;
  return s.materials.at(static_cast<size_t>(i));
}

const uint8_t* texel(const Image& image, int x, int y) { return &image.rgba[(static_cast<size_t>(y) * image.width + x) * 4]; }

bool has_warning(const Scene& s, const std::string& part) {
  for (const auto& w : s.warnings)
    if (w.find(part) != std::string::npos) return true;
  return false;
}

Scene load_two_rooms(LoadReport* report) {
  Vfs vfs;
  vfs.add_search_path(data_dir() / "base");
  return load_map(vfs, "two_rooms", report);
}

}  // namespace

TEST(MapLoader, CountsOfTheHandWrittenMap) {
  LoadReport report;
  Scene s = load_two_rooms(&report);
  EXPECT_EQ(s.name, "two_rooms");
  EXPECT_EQ(report.areas, 2);
  ASSERT_EQ(s.area_meshes.size(), 2u);
  EXPECT_EQ(s.meshes[static_cast<size_t>(s.area_meshes[1])].name, "_area1");
  EXPECT_EQ(s.world_triangle_count(), 4u);
  EXPECT_EQ(report.world_triangles, 4u);
  EXPECT_EQ(report.inline_models, 1);
  EXPECT_EQ(report.material_files, 1);
  EXPECT_EQ(report.materials_used, 4);  // floor, wall, the undefined crate material, the light's gel
  EXPECT_EQ(report.materials_missing, 1);
  EXPECT_EQ(report.lights_point, 1);
  EXPECT_EQ(report.lights_projected, 1);
  EXPECT_EQ(report.lights_parallel, 1);
  EXPECT_EQ(report.entities_by_class.at("func_static"), 1);
  EXPECT_EQ(report.entities_by_class.at("info_player_start"), 1);
  EXPECT_EQ(s.portals.size(), 1u);
  EXPECT_EQ(s.nodes.size(), 1u);
  EXPECT_EQ(s.player_start, glm::vec3(32, 32, 8));
  EXPECT_FLOAT_EQ(s.player_yaw, 90.0f);
  EXPECT_EQ(report.warnings, s.warnings);
}

TEST(MapLoader, EntityMeshesAndSurfaceMaterials) {
  Scene s = load_two_rooms(nullptr);
  ASSERT_EQ(s.entities.size(), 2u);
  const Entity& crate = s.entities[1];
  EXPECT_EQ(crate.name, "func_static_crate");
  ASSERT_GE(crate.mesh, 0);
  EXPECT_EQ(s.meshes[static_cast<size_t>(crate.mesh)].name, "func_static_crate");
  EXPECT_EQ(s.entities[0].mesh, -1);
  const Mesh& area1 = s.meshes[static_cast<size_t>(s.area_meshes[1])];
  EXPECT_EQ(s.materials[static_cast<size_t>(area1.surfaces[1].material)].name, "textures/test/wall");
}

TEST(MapLoader, LitMaterialImagesAndPrograms) {
  Scene s = load_two_rooms(nullptr);
  const Material& floor = material(s, "textures/test/floor");
  EXPECT_EQ(floor.blend, BlendClass::Opaque);
  EXPECT_FALSE(floor.emitter);
  const Image& diffuse = s.images.at(static_cast<size_t>(floor.diffuse_image));
  ASSERT_EQ(diffuse.width, 2);
  EXPECT_EQ(diffuse.name, "textures/test/floor");
  EXPECT_EQ(texel(diffuse, 0, 0)[0], 255);  // top-left red, though the file stores rows bottom up
  EXPECT_EQ(texel(diffuse, 1, 1)[2], 255);
  const Image& normals = s.images.at(static_cast<size_t>(floor.normal_image));
  EXPECT_TRUE(normals.is_normal_map);
  EXPECT_NEAR(texel(normals, 0, 0)[0], 128, 2);
  EXPECT_NEAR(texel(normals, 0, 0)[2], 255, 2);
  const Image& specular = s.images.at(static_cast<size_t>(floor.specular_image));
  EXPECT_EQ(texel(specular, 0, 0)[0], 64);  // run-length-encoded file

  const Material& wall = material(s, "textures/test/wall");
  EXPECT_EQ(wall.diffuse_color, glm::vec4(0.5f, 0.5f, 0.5f, 1.0f));
  EXPECT_FLOAT_EQ(wall.tex_transform[0], 2.0f);
  EXPECT_EQ(wall.specular_color, glm::vec4(0, 0, 0, 1));  // no specular stage: none
  const Image& bumps = s.images.at(static_cast<size_t>(wall.normal_image));
  EXPECT_LT(texel(bumps, 1, 0)[0], 120);  // height rising along +x tilts the normal towards -x
  EXPECT_TRUE(wall.emitter);              // GL_ONE, GL_ONE stage over a lit surface
  EXPECT_FLOAT_EQ(wall.emissive_color.r, 0.25f);
  EXPECT_EQ(s.images.at(static_cast<size_t>(wall.emissive_image)).name, "textures/test/panel");
}

TEST(MapLoader, MissingMaterialAndImageGetVisibleDefaultsAndWarnings) {
  Scene s = load_two_rooms(nullptr);
  const Material& crate = material(s, "textures/test/undefined_crate");
  EXPECT_TRUE(crate.is_default);
  const Image& checker = s.images.at(static_cast<size_t>(crate.diffuse_image));
  EXPECT_EQ(checker.width, 8);
  EXPECT_NE(texel(checker, 0, 0)[0], texel(checker, 4, 0)[0]);
  EXPECT_TRUE(has_warning(s, "textures/test/undefined_crate"));
}

TEST(MapLoader, LightMaterialWithFalloff) {
  Scene s = load_two_rooms(nullptr);
  const Light* spot = nullptr;
  for (const Light& l : s.lights)
    if (l.name == "light_spot") spot = &l;
  ASSERT_NE(spot, nullptr);
  ASSERT_GE(spot->material, 0);
  const Material& gel = s.materials.at(static_cast<size_t>(spot->material));
  EXPECT_EQ(gel.name, "lights/test_gel");
  EXPECT_TRUE(gel.is_light_material);
  ASSERT_GE(gel.light_image, 0);
  ASSERT_GE(gel.falloff_image, 0);
  const Image& falloff = s.images.at(static_cast<size_t>(gel.falloff_image));
  EXPECT_EQ(falloff.width, 4);
  EXPECT_EQ(texel(falloff, 1, 0)[1], 170);  // makeIntensity: red copied into green
  EXPECT_EQ(texel(falloff, 1, 0)[3], 170);
}

TEST(MapLoader, DiskPathFindsTheBaseFolder) {
  Vfs vfs;
  LoadReport report;
  Scene s = load_map(vfs, (data_dir() / "base/maps/two_rooms.map").string(), &report);
  EXPECT_EQ(report.materials_missing, 1);
  EXPECT_EQ(vfs.search_paths().size(), 1u);
  EXPECT_EQ(s.world_triangle_count(), 4u);
}

TEST(MapLoader, ArchiveInALaterSearchPathOverridesALooseMaterialFile) {
  fs::path mod = fs::path(COHORT_BINARY_DIR) / "test_tmp" / "loader_mod";
  fs::remove_all(mod);
  fs::create_directories(mod);
  std::string mtr = "textures/test/floor { diffusemap textures/test/panel }\n";
  int error = 0;
  zip_t* zip = zip_open((mod / "pak000.pk4").string().c_str(), ZIP_CREATE | ZIP_TRUNCATE, &error);
  ASSERT_NE(zip, nullptr);
  zip_source_t* src = zip_source_buffer(zip, mtr.data(), mtr.size(), 0);
  ASSERT_GE(zip_file_add(zip, "materials/test.mtr", src, ZIP_FL_OVERWRITE), 0);
  ASSERT_EQ(zip_close(zip), 0);

  Vfs vfs;
  vfs.add_search_path(data_dir() / "base");
  vfs.add_search_path(mod);
  Scene s = load_map(vfs, "maps/two_rooms.map", nullptr);
  const Material& floor = material(s, "textures/test/floor");
  EXPECT_EQ(s.images.at(static_cast<size_t>(floor.diffuse_image)).name, "textures/test/panel");
  EXPECT_TRUE(material(s, "textures/test/wall").is_default);  // the archive's .mtr replaced the loose one
}

TEST(MapLoader, MissingMapAndBrokenFilesReportWhere) {
  Vfs vfs;
  vfs.add_search_path(data_dir() / "base");
  EXPECT_THROW(load_map(vfs, "no_such_map", nullptr), std::runtime_error);
  try {
    load_map(vfs, (data_dir() / "broken/unterminated_string.map").string(), nullptr);
    FAIL();
  } catch (const std::runtime_error& e) {
    // No .proc beside it: the map is parsed only after both are found.
    EXPECT_NE(std::string(e.what()).find("unterminated_string.proc"), std::string::npos) << e.what();
  }
}
