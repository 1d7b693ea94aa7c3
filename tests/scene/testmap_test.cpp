// The generated test map (assets/testmap) loads completely, and what the loader reports agrees with
// counts taken from the files by plain text scanning, independent of the parsers.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <set>
#include <sstream>
#include <tuple>

#include "cohort/scene/map_loader.h"
#include "cohort/scene/md5.h"
#include "test_files.h"

using namespace cohort::scene;
using cohort::scene::test::read_text;
namespace fs = std::filesystem;

namespace {

fs::path testmap_dir() { return fs::path(COHORT_SOURCE_DIR) / "assets/testmap"; }

struct TextCounts {
  int area_models = 0, inline_models = 0;
  size_t world_triangles = 0;
  int lights = 0, projected = 0, parallel = 0;
  std::map<std::string, int> classes;
};

// The number after a "/* label = */" comment on a line, or -1.
long long labelled_number(const std::string& line, const std::string& label) {
  auto at = line.find("/* " + label + " = */");
  if (at == std::string::npos) return -1;
  return std::stoll(line.substr(at + label.size() + 8));
}

std::string quoted_after(const std::string& line, size_t from) {
  auto open = line.find('"', from);
  auto close = line.find('"', open + 1);
  return line.substr(open + 1, close - open - 1);
}

TextCounts count_from_text() {
  TextCounts counts;
  std::istringstream proc(read_text(testmap_dir() / "maps/testmap.proc"));
  bool in_area = false;
  for (std::string line; std::getline(proc, line);) {
    if (line.rfind("model {", 0) == 0) {
      in_area = quoted_after(line, 0).rfind("_area", 0) == 0;
      (in_area ? counts.area_models : counts.inline_models)++;
    }
    long long indexes = labelled_number(line, "numIndexes");
    if (in_area && indexes > 0) counts.world_triangles += static_cast<size_t>(indexes / 3);
    if (line.rfind("shadowModel", 0) == 0 || line.rfind("interAreaPortals", 0) == 0) in_area = false;
  }
  // Classes that are lights: `light` and the .def's entityDefs whose "inherit" line names "light".
  std::set<std::string> light_classes{"light"};
  std::istringstream def(read_text(testmap_dir() / "def/testmap.def"));
  std::string current_def;
  for (std::string line; std::getline(def, line);) {
    if (line.rfind("entityDef ", 0) == 0) current_def = line.substr(10);
    if (line.find("\"inherit\"") != std::string::npos && line.find("\"light\"") != std::string::npos)
      light_classes.insert(current_def);
  }
  std::istringstream map(read_text(testmap_dir() / "maps/testmap.map"));
  bool in_light = false;
  for (std::string line; std::getline(map, line);) {
    if (line.rfind("\"classname\"", 0) == 0) {
      std::string classname = quoted_after(line, 11);
      in_light = light_classes.count(classname) > 0;
      if (in_light) ++counts.lights;
      else if (classname != "worldspawn") ++counts.classes[classname];
    }
    if (in_light && line.rfind("\"light_target\"", 0) == 0) ++counts.projected;
    if (in_light && line == "\"parallel\" \"1\"") ++counts.parallel;
  }
  return counts;
}

// The value of key in the map entity named name, by text scanning.
std::string entity_value(const std::string& name, const std::string& key) {
  std::istringstream map(read_text(testmap_dir() / "maps/testmap.map"));
  std::vector<std::string> block;
  for (std::string line; std::getline(map, line);) {
    if (line == "{") block.clear();
    block.push_back(line);
    if (line == "}" && std::find(block.begin(), block.end(), "\"name\" \"" + name + "\"") != block.end())
      for (const auto& l : block)
        if (l.rfind("\"" + key + "\"", 0) == 0) return quoted_after(l, key.size() + 2);
  }
  return "";
}

glm::vec3 vec3_of(const std::string& text) {
  std::istringstream in(text);
  glm::vec3 v(0.0f);
  in >> v.x >> v.y >> v.z;
  return v;
}

class TestMap : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::exists(testmap_dir() / "maps/testmap.map")) GTEST_SKIP() << "assets/testmap is not generated";
    Vfs vfs;
    vfs.add_search_path(testmap_dir());
    scene = load_map(vfs, "testmap", &report);
  }
  Scene scene;
  LoadReport report;
};

const Light& light_named(const Scene& s, const std::string& name) {
  for (const Light& l : s.lights)
    if (l.name == name) return l;
  throw std::runtime_error("no light " + name);
}

}  // namespace

TEST_F(TestMap, CountsAgreeWithTheFiles) {
  TextCounts expected = count_from_text();
  EXPECT_EQ(report.areas, expected.area_models);
  EXPECT_EQ(static_cast<int>(scene.area_meshes.size()), expected.area_models);
  EXPECT_EQ(report.inline_models, expected.inline_models);
  EXPECT_EQ(scene.world_triangle_count(), expected.world_triangles);
  EXPECT_EQ(static_cast<int>(scene.lights.size()), expected.lights);
  EXPECT_EQ(report.lights_projected, expected.projected);
  EXPECT_EQ(report.lights_parallel, expected.parallel);
  EXPECT_EQ(report.lights_point, expected.lights - expected.projected - expected.parallel);
  EXPECT_EQ(report.entities_by_class, expected.classes);
  EXPECT_GT(scene.portals.size(), 0u);
  EXPECT_GT(scene.nodes.size(), 0u);
}

TEST_F(TestMap, LoadsWithoutWarningsOrPlaceholders) {
  EXPECT_TRUE(report.warnings.empty()) << ::testing::PrintToString(report.warnings);
  EXPECT_EQ(report.materials_missing, 0);
  EXPECT_EQ(report.images_placeholder, 0);
  for (const Entity& e : scene.entities)
    if (e.classname != "info_player_start") { EXPECT_GE(e.mesh, 0) << e.name; }
}

TEST_F(TestMap, ProjectedBeamMatchesItsKeys) {
  const Light& beam = light_named(scene, "light_beam");
  EXPECT_EQ(beam.type, LightType::Projected);
  EXPECT_EQ(beam.origin, vec3_of(entity_value("light_beam", "origin")));
  EXPECT_EQ(beam.target, vec3_of(entity_value("light_beam", "light_target")));
  EXPECT_EQ(beam.right, vec3_of(entity_value("light_beam", "light_right")));
  EXPECT_EQ(beam.up, vec3_of(entity_value("light_beam", "light_up")));
  EXPECT_EQ(beam.start, vec3_of(entity_value("light_beam", "light_start")));
  EXPECT_EQ(beam.end, vec3_of(entity_value("light_beam", "light_end")));
  EXPECT_EQ(beam.color, vec3_of(entity_value("light_beam", "_color")));
  EXPECT_TRUE(beam.has_start_end);
  ASSERT_GE(beam.material, 0);
  const Material& shader = scene.materials[static_cast<size_t>(beam.material)];
  EXPECT_EQ(shader.name, entity_value("light_beam", "texture"));
  EXPECT_TRUE(shader.is_light_material);
  EXPECT_GE(shader.light_image, 0);
  EXPECT_GE(shader.falloff_image, 0);
}

TEST_F(TestMap, SunIsParallelWithItsCenter) {
  const Light& sun = light_named(scene, "light_sun");
  EXPECT_EQ(sun.type, LightType::Parallel);
  EXPECT_EQ(sun.center, vec3_of(entity_value("light_sun", "light_center")));
  EXPECT_EQ(sun.radius, vec3_of(entity_value("light_sun", "light_radius")));
}

TEST_F(TestMap, MaterialClasses) {
  auto m = [&](const char* name) -> const Material& {
    int i = scene.find_material(name);
    EXPECT_GE(i, 0) << name;
    return scene.materials.at(static_cast<size_t>(i));
  };
  EXPECT_TRUE(m("textures/testmap/grate").alpha_test);
  EXPECT_TRUE(m("textures/testmap/grate").two_sided);
  EXPECT_EQ(m("textures/testmap/glass").blend, BlendClass::Alpha);
  EXPECT_TRUE(m("textures/testmap/glass").translucent);
  EXPECT_TRUE(m("textures/testmap/glass").no_shadows);
  EXPECT_EQ(m("textures/testmap/decal_blood").blend, BlendClass::Modulate);
  EXPECT_EQ(m("textures/testmap/lightpanel").blend, BlendClass::Additive);
  EXPECT_TRUE(m("textures/testmap/lightpanel").emitter);
  EXPECT_EQ(m("textures/testmap/lightpanel_blue").emissive_color, glm::vec4(0.5f, 0.75f, 1.0f, 1.0f));
  EXPECT_TRUE(m("textures/testmap/sky").emitter);
  EXPECT_EQ(m("textures/testmap/sky").blend, BlendClass::Opaque);
  // The sky court's ceiling: a camera cube map with texgen skybox, its six faces found (docs/sky.md).
  const Material& skybox = m("textures/testmap/skybox");
  EXPECT_EQ(skybox.blend, BlendClass::Sky);
  ASSERT_GE(skybox.sky_cube_image, 0);
  for (int face = 0; face < 6; ++face)
    EXPECT_FALSE(scene.images.at(static_cast<size_t>(skybox.sky_cube_image + face)).is_placeholder) << face;
  EXPECT_EQ(scene.images.at(static_cast<size_t>(skybox.sky_cube_image + 4)).name, "env/testmap_sky_up");
  EXPECT_TRUE(m("textures/testmap/leaves").no_self_shadow);
  // The court's chrome pipe: lit and bump-mapped, reflecting the same sky cube (one set of faces).
  const Material& chrome = m("textures/testmap/chrome");
  EXPECT_EQ(chrome.blend, BlendClass::Opaque);
  EXPECT_GE(chrome.normal_image, 0);
  EXPECT_EQ(chrome.environment_cube_image, skybox.sky_cube_image);
  EXPECT_FALSE(chrome.environment_by_normal);
  EXPECT_EQ(chrome.environment_color, glm::vec3(0.7f));
  EXPECT_EQ(m("textures/testmap/floor_tiles").blend, BlendClass::Opaque);
  EXPECT_GE(m("textures/testmap/floor_tiles").normal_image, 0);
  EXPECT_TRUE(scene.images[static_cast<size_t>(m("textures/testmap/floor_tiles").normal_image)].is_normal_map);
  EXPECT_FLOAT_EQ(m("textures/testmap/concrete").tex_transform[0], 2.0f);
}

const Entity& entity_named(const Scene& s, const std::string& name) {
  for (const Entity& e : s.entities)
    if (e.name == name) return e;
  throw std::runtime_error("no entity " + name);
}

std::string material_of(const Scene& s, const Entity& e, size_t surface = 0) {
  const Mesh& mesh = s.meshes.at(static_cast<size_t>(e.mesh));
  return s.materials.at(static_cast<size_t>(mesh.surfaces.at(surface).material)).name;
}

TEST_F(TestMap, ModelPropsResolveThroughClassesAndShareMeshes) {
  EXPECT_TRUE(report.unresolved_classes.empty()) << ::testing::PrintToString(report.unresolved_classes);
  EXPECT_TRUE(report.unresolved_models.empty());
  const Entity &lamp1 = entity_named(scene, "lamp_1"), &lamp2 = entity_named(scene, "lamp_2");
  EXPECT_EQ(lamp1.mesh, lamp2.mesh);   // one mesh, so one BLAS, for both instances
  EXPECT_EQ(entity_value("lamp_1", "model"), "");   // the model comes from the class testmap_lamp
  EXPECT_EQ(lamp1.model_file, "models/testmap/lamp.ase");
  EXPECT_EQ(lamp1.keys.at("spawnclass"), "idStaticEntity");   // from func_static, two levels up
  for (const auto& [key, value] : lamp1.keys) EXPECT_NE(key.rfind("editor_", 0), 0u) << key;
  const Mesh& lamp = scene.meshes.at(static_cast<size_t>(lamp1.mesh));
  ASSERT_EQ(lamp.surfaces.size(), 2u);
  EXPECT_EQ(material_of(scene, lamp1, 0), "textures/testmap/lamppost");
  // The post's vertex colours reach the mesh, and its material multiplies by them.
  ASSERT_EQ(lamp.colors.size(), lamp.vertices.size());
  EXPECT_NE(std::count(lamp.colors.begin(), lamp.colors.end(), 0xFFFFFFFFu), std::ptrdiff_t(lamp.colors.size()));
  EXPECT_TRUE(scene.materials.at(static_cast<size_t>(lamp.surfaces[0].material)).vertex_color);
  EXPECT_EQ(material_of(scene, lamp1, 1), "textures/testmap/wood");   // the last sub-material's bitmap
  EXPECT_EQ(entity_named(scene, "wedge_1").mesh, entity_named(scene, "wedge_2").mesh);
  // The wedge's RGBA map: 0.5 grey-yellow at the foot (idTech z = 0), white-ish at the ridge (z = 24).
  const Mesh& wedge = scene.meshes.at(static_cast<size_t>(entity_named(scene, "wedge_1").mesh));
  ASSERT_EQ(wedge.colors.size(), wedge.vertices.size());
  for (size_t v = 0; v < wedge.vertices.size(); ++v) {
    const float shade = 0.5f + 0.5f * wedge.vertices[v].position.z / 24.0f;
    const glm::vec4 c = unpack_rgba8(wedge.colors[v]);
    EXPECT_NEAR(c.r, shade, 0.6f / 255.0f) << "vertex " << v;
    EXPECT_NEAR(c.b, shade * 0.9f, 0.6f / 255.0f) << "vertex " << v;
    EXPECT_EQ(c.a, 1.0f);
  }
  const Entity &walker1 = entity_named(scene, "walker_1"), &walker2 = entity_named(scene, "walker_2");
  EXPECT_NE(walker1.mesh, walker2.mesh);   // another skin, another mesh
  EXPECT_EQ(material_of(scene, walker1), "models/testmap/walker");
  EXPECT_EQ(material_of(scene, walker2), "textures/testmap/door");
  EXPECT_EQ(walker1.anim_file, "models/testmap/walker_walk.md5anim");
  EXPECT_EQ(walker2.skin, "skins/testmap/walker_metal");
  // The lamp's bulb is a light because its class inherits from `light`; its keys come from the def.
  const Light& bulb = light_named(scene, "light_lamp");
  EXPECT_EQ(bulb.radius, glm::vec3(96.0f));
  EXPECT_EQ(bulb.color, glm::vec3(1.0f, 0.8f, 0.55f));
  EXPECT_GE(bulb.material, 0);
}

TEST_F(TestMap, ModelMeshesAreClosedAndFaceOutwards) {
  // Every prop is built of closed solids: each directed edge is matched by its reverse, and the mesh's
  // signed volume (clockwise fronts, so -1/6 sum p0.(p1 x p2)) is positive.
  for (const char* name : {"lamp_1", "wedge_1", "walker_1"}) {
    const Mesh& mesh = scene.meshes.at(static_cast<size_t>(entity_named(scene, name).mesh));
    std::map<std::tuple<float, float, float, float, float, float>, int> edges;
    double volume = 0.0;
    for (size_t t = 0; t < mesh.triangle_count(); ++t) {
      glm::vec3 p[3];
      for (int k = 0; k < 3; ++k) p[k] = mesh.vertices[mesh.indices[t * 3 + static_cast<size_t>(k)]].position;
      volume -= glm::dot(p[0], glm::cross(p[1], p[2])) / 6.0;
      for (int k = 0; k < 3; ++k) {
        const glm::vec3 &a = p[k], &b = p[(k + 1) % 3];
        ++edges[{a.x, a.y, a.z, b.x, b.y, b.z}];
        --edges[{b.x, b.y, b.z, a.x, a.y, a.z}];
      }
    }
    for (const auto& [edge, count] : edges) EXPECT_EQ(count, 0) << name;
    EXPECT_GT(volume, 0.0) << name;
  }
}

TEST_F(TestMap, WalkerAnimationLoopsAndMovesTheLegs) {
  Vfs vfs;
  vfs.add_search_path(testmap_dir());
  Md5Mesh mesh = parse_md5mesh(*vfs.read("models/testmap/walker.md5mesh"), "walker.md5mesh");
  Md5Anim anim = parse_md5anim(*vfs.read("models/testmap/walker_walk.md5anim"), "walker_walk.md5anim");
  check_anim_matches(mesh, anim);
  EXPECT_EQ(anim.length_ms(), 1000);
  auto positions = [&](int ms) {
    std::vector<glm::vec3> out;
    for (const Vertex& v : skin_md5(mesh, anim_pose(anim, ms)).mesh.vertices) out.push_back(v.position);
    return out;
  };
  std::vector<glm::vec3> start = positions(0), quarter = positions(250), looped = positions(1000);
  float moved = 0.0f, loop_error = 0.0f;
  for (size_t i = 0; i < start.size(); ++i) {
    moved = std::max(moved, glm::length(quarter[i] - start[i]));
    loop_error = std::max(loop_error, glm::length(looped[i] - start[i]));
  }
  EXPECT_GT(moved, 5.0f);          // a thigh swung by 30 degrees moves the foot by several units
  EXPECT_LT(loop_error, 1e-3f);    // one second later it is back where it started
  // Every frame stays inside the animation's bounds.
  for (int frame = 0; frame < anim.frame_count(); ++frame) {
    for (const Vertex& v : skin_md5(mesh, anim_frame_pose(anim, frame)).mesh.vertices) {
      for (int axis = 0; axis < 3; ++axis) {
        EXPECT_GE(v.position[axis], anim.bounds[size_t(frame)].first[axis] - 1e-3f) << frame;
        EXPECT_LE(v.position[axis], anim.bounds[size_t(frame)].second[axis] + 1e-3f) << frame;
      }
    }
  }
}
