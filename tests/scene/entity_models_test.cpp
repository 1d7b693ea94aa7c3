// entityDefs, modelDefs and skins (parsed and resolved), and map entities whose models are model files:
// a temporary game folder on top of the hand-written two_rooms map, with generated model files.
#include <gtest/gtest.h>

#include <fstream>

#include "cohort/scene/decl_file.h"
#include "cohort/scene/map_loader.h"
#include "test_files.h"

using namespace cohort::scene;
using cohort::scene::test::data_dir;
using cohort::scene::test::read_text;
namespace fs = std::filesystem;

namespace {

const char* kDefs = R"(// classes
entityDef base_prop {
	"editor_color" "1 0 0"
	"spawnclass" "idStaticEntity"
	"skin" "skins/none"
	"shared" "from base"
}
entityDef mid_prop {
	"inherit" "base_prop"
	"shared" "from mid"
	"skin" ""
}
prop_box {
	"inherit" "mid_prop"
	"model" "models/box.ase"
}
entityDef light_fixture {
	"inherit" "light"
	"light_radius" "64 64 64"
	"model" "models/box.ase"
}
entityDef light { "spawnclass" "idLight" }
entityDef orphan { "inherit" "nowhere" }
entityDef base_prop { "spawnclass" "second definition" }
model walker_def {
	mesh models/walker.md5mesh
	offset ( 0 0 1 )
	channel torso ( root child )
	anim idle models/walker.md5anim
	anim run models/a.md5anim, models/b.md5anim { frame 1 sound foo }
}
material textures/in_a_def { diffusemap x.tga }
skin skins/red { * textures/test/crate }
)";

const char* kSkins = R"(skins/blue {
	model models/box.ase
	textures/Test/Wall.tga	textures/test/floor
	*	textures/test/crate
	textures/test/floor	textures/never
}
)";

DeclLibrary library_of(const char* defs, std::vector<std::string>& warnings) {
  DeclLibrary lib;
  lib.add(parse_decls(defs, "def/test.def", "entityDef"), warnings);
  lib.add(parse_decls(kSkins, "skins/test.skin", "skin"), warnings);
  return lib;
}

TEST(Decls, InheritChainsChildFirstEditorKeysDropped) {
  std::vector<std::string> warnings;
  DeclLibrary lib = library_of(kDefs, warnings);
  const ResolvedEntityDef* box = lib.entity_def("Prop_Box", warnings);
  ASSERT_NE(box, nullptr);
  EXPECT_EQ(*box->get("classname"), "prop_box");
  EXPECT_EQ(*box->get("shared"), "from mid");              // the child beats its parent
  EXPECT_EQ(*box->get("spawnclass"), "idStaticEntity");    // two levels up; the duplicate def is ignored
  EXPECT_EQ(*box->get("skin"), "");
  EXPECT_EQ(box->get("editor_color"), nullptr);
  EXPECT_EQ(box->get("inherit"), nullptr);
  EXPECT_EQ(box->ancestors, (std::set<std::string>{"prop_box", "mid_prop", "base_prop"}));
  EXPECT_TRUE(lib.entity_def("light_fixture", warnings)->ancestors.count("light"));
  EXPECT_EQ(lib.entity_def("no_such_class", warnings), nullptr);
  ASSERT_NE(lib.entity_def("orphan", warnings), nullptr);
  EXPECT_TRUE(lib.entity_def("orphan", warnings)->ancestors.count("nowhere"));   // named, though undefined
  auto has = [&](const std::string& part) {
    for (const auto& w : warnings)
      if (w.find(part) != std::string::npos) return true;
    return false;
  };
  EXPECT_TRUE(has("def/test.def:24: entityDef base_prop already defined at def/test.def:2"))
      << ::testing::PrintToString(warnings);
  EXPECT_TRUE(has("inherits 'nowhere', which is not defined"));
}

TEST(Decls, ModelDefsAndSkins) {
  std::vector<std::string> warnings;
  DeclLibrary lib = library_of(kDefs, warnings);
  const ModelDefDecl* walker = lib.model_def("walker_def");
  ASSERT_NE(walker, nullptr);
  EXPECT_EQ(walker->mesh, "models/walker.md5mesh");
  EXPECT_EQ(walker->offset, glm::vec3(0, 0, 1));
  ASSERT_EQ(walker->anims.size(), 2u);
  EXPECT_EQ(walker->anims[1], (std::pair<std::string, std::string>{"run", "models/a.md5anim"}));
  const SkinDecl* blue = lib.skin("Skins/Blue");
  ASSERT_NE(blue, nullptr);
  EXPECT_EQ(apply_skin(*blue, "textures/test/wall"), "textures/test/floor");   // canonical names match
  EXPECT_EQ(apply_skin(*blue, "textures/test/floor"), "textures/test/crate");  // `*` shadows later pairs
  ASSERT_NE(lib.skin("skins/red"), nullptr);                                    // a skin inside a .def
  EXPECT_EQ(lib.entity_def_count(), 6u);   // the second base_prop is not kept
}

TEST(Decls, CyclesAndDeepChainsNameTheChain) {
  std::vector<std::string> warnings;
  DeclLibrary cyclic = library_of(R"(entityDef a { "inherit" "b" }
entityDef b { "inherit2" "c" }
entityDef c { "inherit" "a" })", warnings);
  try {
    cyclic.entity_def("a", warnings);
    FAIL() << "no error";
  } catch (const DeclError& e) {
    EXPECT_NE(std::string(e.what()).find("a -> b -> c -> a"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("def/test.def:3"), std::string::npos) << e.what();
  }
  std::string deep;
  for (int i = 0; i < 40; ++i) deep += "entityDef d" + std::to_string(i) + " { \"inherit\" \"d" + std::to_string(i + 1) + "\" }\n";
  DeclLibrary too_deep = library_of(deep.c_str(), warnings);
  try {
    too_deep.entity_def("d0", warnings);
    FAIL() << "no error";
  } catch (const DeclError& e) {
    EXPECT_NE(std::string(e.what()).find("deeper than 32: d0 -> d1"), std::string::npos) << e.what();
  }
  DeclLibrary self = library_of(R"(model m { inherit m mesh x.md5mesh })", warnings);
  EXPECT_THROW(self.model_def("m"), DeclError);
}

TEST(Decls, MalformedFilesFailOrDefaultWithFileAndLine) {
  try {
    parse_decls("entityDef a {\n \"k\" \"v\"\n", "def/cut.def", "entityDef");
    FAIL() << "no error";
  } catch (const ParseError& e) {
    EXPECT_NE(std::string(e.what()).find("def/cut.def:"), std::string::npos) << e.what();
  }
  DeclFile defaulted = parse_decls("entityDef a {\n unquoted \"v\"\n}\nentityDef b { \"k\" \"v\" }", "def/x.def", "entityDef");
  ASSERT_EQ(defaulted.entity_defs.size(), 2u);
  EXPECT_EQ(defaulted.entity_defs[0].keys, (KeyValues{{"DEFAULTED", "1"}}));
  ASSERT_EQ(defaulted.warnings.size(), 1u);
  EXPECT_NE(defaulted.warnings[0].find("def/x.def:2: entityDef a: expected a quoted key"), std::string::npos);
  EXPECT_EQ(defaulted.entity_defs[1].keys, (KeyValues{{"k", "v"}}));
}

// --- map entities with model files ---------------------------------------------------------------------

const char* kBoxAse = R"(*MATERIAL_LIST { *MATERIAL_COUNT 1 *MATERIAL 0 { *MAP_DIFFUSE { *BITMAP "x:\base\textures\test\wall.tga" } } }
*GEOMOBJECT { *MESH { *MESH_NUMVERTEX 3 *MESH_NUMFACES 1
  *MESH_VERTEX_LIST {
    *MESH_VERTEX 0 0 0 0
    *MESH_VERTEX 1 8 0 0
    *MESH_VERTEX 2 0 8 0
  }
  *MESH_FACE_LIST {
    *MESH_FACE 0: A: 0 B: 1 C: 2
  } }
  *MATERIAL_REF 0 }
)";

class ModelEntities : public ::testing::Test {
 protected:
  void SetUp() override {
    root = fs::path(COHORT_BINARY_DIR) / "entity_models_test" /
           ::testing::UnitTest::GetInstance()->current_test_info()->name();
    fs::remove_all(root);
    write("maps/props.proc", read_text(data_dir() / "base/maps/two_rooms.proc"));
    write("def/test.def", kDefs);
    write("skins/test.skin", kSkins);
    write("models/box.ase", kBoxAse);
    write("models/broken.lwo", "FORM\0\0\0\x10LWO2PNTS\0\0\0\x20", 20);
  }
  void write(const std::string& path, const std::string& text, size_t size = std::string::npos) {
    fs::create_directories((root / path).parent_path());
    std::ofstream(root / path, std::ios::binary).write(text.data(), std::streamsize(std::min(size, text.size())));
  }
  void write(const std::string& path, const char* bytes, size_t size) {
    fs::create_directories((root / path).parent_path());
    std::ofstream(root / path, std::ios::binary).write(bytes, std::streamsize(size));
  }
  Scene load(const std::string& entities, LoadReport* report = nullptr) {
    write("maps/props.map", "Version 2\n{\n\"classname\" \"worldspawn\"\n}\n" + entities);
    Vfs vfs;
    vfs.add_search_path(data_dir() / "base");
    vfs.add_search_path(root);
    return load_map(vfs, "props", report);
  }
  static const Entity& named(const Scene& s, const std::string& name) {
    for (const Entity& e : s.entities)
      if (e.name == name) return e;
    throw std::runtime_error("no entity " + name);
  }
  static bool has_warning(const Scene& s, const std::string& part) {
    for (const auto& w : s.warnings)
      if (w.find(part) != std::string::npos) return true;
    return false;
  }
  fs::path root;
};

TEST_F(ModelEntities, ClassModelsLoadOnceAndSkinsMakeTheirOwnMesh) {
  LoadReport report;
  Scene s = load(R"({
"classname" "prop_box"
"name" "a"
"origin" "8 8 0"
}
{
"classname" "func_static"
"name" "b"
"model" "MODELS/BOX.ASE"
}
{
"classname" "prop_box"
"name" "c"
"skin" "skins/blue"
}
)", &report);
  const Entity &a = named(s, "a"), &b = named(s, "b"), &c = named(s, "c");
  EXPECT_GE(a.mesh, 0);
  EXPECT_EQ(a.mesh, b.mesh);
  EXPECT_NE(a.mesh, c.mesh);
  EXPECT_EQ(a.keys.at("shared"), "from mid");
  EXPECT_EQ(a.origin, glm::vec3(8, 8, 0));
  auto material = [&](const Entity& e) {
    return s.materials.at(size_t(s.meshes.at(size_t(e.mesh)).surfaces.at(0).material)).name;
  };
  EXPECT_EQ(material(a), "textures/test/wall");
  EXPECT_EQ(material(c), "textures/test/floor");
  EXPECT_EQ(s.meshes.at(size_t(a.mesh)).triangle_count(), 1u);
  EXPECT_EQ(report.model_files_loaded, 2);
  EXPECT_EQ(report.unresolved_classes, (std::map<std::string, int>{{"func_static", 1}}));
  EXPECT_TRUE(report.unresolved_models.empty());
}

TEST_F(ModelEntities, MissingOrBrokenModelsWarnWithFileAndLineAndGetThePlaceholderBox) {
  LoadReport report;
  Scene s = load(R"({
"classname" "func_static"
"name" "missing"
"model" "models/nothere.ase"
}
{
"classname" "func_static"
"name" "broken"
"model" "models/broken.lwo"
}
{
"classname" "func_static"
"name" "unknown"
"model" "not_a_model"
}
)", &report);
  const Entity &missing = named(s, "missing"), &broken = named(s, "broken");
  ASSERT_GE(missing.mesh, 0);
  ASSERT_GE(broken.mesh, 0);
  EXPECT_EQ(s.meshes.at(size_t(missing.mesh)).triangle_count(), 12u);   // the engine's default cube
  EXPECT_EQ(s.meshes.at(size_t(broken.mesh)).triangle_count(), 12u);
  EXPECT_TRUE(has_warning(s, "props.map:5: entity missing: models/nothere.ase: model file not found; using a placeholder box"));
  EXPECT_TRUE(has_warning(s, "props.map:10: entity broken: "));
  EXPECT_TRUE(has_warning(s, "broken.lwo: byte 8: FORM size 16 runs past the file end"));
  EXPECT_TRUE(has_warning(s, "props.map:15: entity unknown: model 'not_a_model' is no inline model"));
  EXPECT_EQ(named(s, "unknown").mesh, -1);
  EXPECT_EQ(report.unresolved_models.size(), 3u) << ::testing::PrintToString(s.warnings);
  EXPECT_EQ(s.lights.size(), 0u);
}

TEST_F(ModelEntities, LightSubclassesAreLightsAndTheirModelIsShown) {
  LoadReport report;
  Scene s = load(R"({
"classname" "light_fixture"
"name" "lamp"
"origin" "16 16 32"
}
)", &report);
  ASSERT_EQ(s.lights.size(), 1u);
  EXPECT_EQ(s.lights[0].radius, glm::vec3(64.0f));
  EXPECT_EQ(report.lights_point, 1);
  const Entity& fixture = named(s, "lamp_model");
  EXPECT_GE(fixture.mesh, 0);
  EXPECT_EQ(fixture.origin, glm::vec3(16, 16, 32));
  EXPECT_TRUE(has_warning(s, "props.map:5: light lamp has a model ('models/box.ase')"));
}

TEST_F(ModelEntities, Md5ModelDefWithAnAnimThatDoesNotFit) {
  write("models/walker.md5mesh", R"(MD5Version 10
numJoints 1
numMeshes 1
joints { "root" -1 ( 0 0 0 ) ( 0 0 0 ) }
mesh { shader "textures/test/crate" numverts 3
  vert 0 ( 0 0 ) 0 1
  vert 1 ( 1 0 ) 1 1
  vert 2 ( 0 1 ) 2 1
  numtris 1 tri 0 0 2 1
  numweights 3 weight 0 0 1 ( 0 0 0 ) weight 1 0 1 ( 8 0 0 ) weight 2 0 1 ( 0 8 0 ) }
)");
  write("models/walker.md5anim", R"(MD5Version 10
numFrames 1 numJoints 1 frameRate 24 numAnimatedComponents 0
hierarchy { "pelvis" -1 0 0 }
bounds { ( 0 0 0 ) ( 1 1 1 ) }
baseframe { ( 0 0 0 ) ( 0 0 0 ) }
frame 0 { }
)");
  Scene s = load(R"({
"classname" "func_animate"
"name" "w"
"model" "walker_def"
"anim" "idle"
}
)");
  const Entity& w = named(s, "w");
  ASSERT_GE(w.mesh, 0);
  EXPECT_EQ(s.meshes.at(size_t(w.mesh)).triangle_count(), 1u);
  EXPECT_EQ(w.anim_file, "models/walker.md5anim");
  EXPECT_TRUE(has_warning(s, "walker.md5anim does not fit"));
  EXPECT_TRUE(has_warning(s, "walker.md5mesh: joint 0 is 'pelvis', the mesh has 'root'"));
}

TEST_F(ModelEntities, CyclicClassFailsTheLoadNamingTheChain) {
  write("def/z_cycle.def", R"(entityDef loop_a { "inherit" "loop_b" }
entityDef loop_b { "inherit" "loop_a" })");
  try {
    load("{\n\"classname\" \"loop_a\"\n}\n");
    FAIL() << "no error";
  } catch (const DeclError& e) {
    EXPECT_NE(std::string(e.what()).find("loop_a -> loop_b -> loop_a"), std::string::npos) << e.what();
  }
}

}  // namespace
