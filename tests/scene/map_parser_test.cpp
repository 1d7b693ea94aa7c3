#include <gtest/gtest.h>

#include <cmath>

#include "cohort/scene/map_entities.h"
#include "cohort/scene/map_file.h"
#include "cohort/scene/parse_error.h"
#include "test_files.h"

using namespace cohort::scene;
using cohort::scene::test::data_dir;
using cohort::scene::test::read_text;

TEST(MapParser, EntitiesKeysAndSkippedPrimitives) {
  MapFile map = parse_map(read_text(data_dir() / "base/maps/two_rooms.map"), "two_rooms.map");
  EXPECT_EQ(map.version, 2);
  ASSERT_EQ(map.entities.size(), 6u);
  EXPECT_EQ(map.entities[0].classname(), "worldspawn");
  EXPECT_EQ(map.entities[0].brush_count, 1);
  EXPECT_EQ(map.entities[0].patch_count, 1);
  EXPECT_EQ(map.entities[1].get_or("ORIGIN", ""), "32 32 8");  // keys are case-insensitive
  EXPECT_EQ(map.entities[5].brush_count, 1);
  EXPECT_TRUE(map.warnings.empty());
}

TEST(MapEntities, PointLightKeys) {
  MapFile map = parse_map(read_text(data_dir() / "base/maps/two_rooms.map"), "two_rooms.map");
  std::vector<std::string> warnings;
  MapLight point = light_from_entity(map.entities[2], "two_rooms.map", warnings);
  EXPECT_EQ(point.light.type, LightType::Point);
  EXPECT_EQ(point.light.name, "light_point");
  EXPECT_EQ(point.light.origin, glm::vec3(32, 32, 48));
  EXPECT_EQ(point.light.radius, glm::vec3(200, 150, 100));
  EXPECT_EQ(point.light.center, glm::vec3(0, 0, 8));
  EXPECT_EQ(point.light.color, glm::vec3(1, 0.5f, 0.25f));
  EXPECT_FLOAT_EQ(point.light.shader_parms[1], 0.5f);
  EXPECT_TRUE(point.light.no_specular);
  EXPECT_FALSE(point.light.no_shadows);
  EXPECT_TRUE(point.texture.empty());
  EXPECT_TRUE(warnings.empty());
}

TEST(MapEntities, ProjectedLightDefaultsEndToTargetAndStartToZero) {
  MapFile map = parse_map(read_text(data_dir() / "base/maps/two_rooms.map"), "two_rooms.map");
  std::vector<std::string> warnings;
  MapLight spot = light_from_entity(map.entities[3], "two_rooms.map", warnings);
  EXPECT_EQ(spot.light.type, LightType::Projected);
  EXPECT_EQ(spot.light.target, glm::vec3(0, 0, -64));
  EXPECT_EQ(spot.light.up, glm::vec3(0, 32, 0));
  EXPECT_EQ(spot.light.right, glm::vec3(32, 0, 0));
  EXPECT_EQ(spot.light.start, glm::vec3(0));
  EXPECT_EQ(spot.light.end, glm::vec3(0, 0, -80));
  EXPECT_TRUE(spot.light.has_start_end);
  EXPECT_EQ(spot.texture, "lights/test_gel");
  EXPECT_TRUE(spot.light.no_shadows);

  MapEntity no_end;
  no_end.keys = {{"classname", "light"}, {"light_target", "0 0 -10"}, {"light_up", "0 1 0"}, {"light_right", "1 0 0"}};
  MapLight defaulted = light_from_entity(no_end, "x", warnings);
  EXPECT_EQ(defaulted.light.end, glm::vec3(0, 0, -10));
  EXPECT_FALSE(defaulted.light.has_start_end);
}

TEST(MapEntities, ParallelLightWithAngle) {
  MapFile map = parse_map(read_text(data_dir() / "base/maps/two_rooms.map"), "two_rooms.map");
  std::vector<std::string> warnings;
  MapLight sun = light_from_entity(map.entities[4], "two_rooms.map", warnings);
  EXPECT_EQ(sun.light.type, LightType::Parallel);
  EXPECT_EQ(sun.light.center, glm::vec3(10, 20, 400));
  EXPECT_NEAR(sun.light.axis[0].x, 0.0f, 1e-6f);  // angle 90: forward is +y
  EXPECT_NEAR(sun.light.axis[0].y, 1.0f, 1e-6f);
  EXPECT_NEAR(sun.light.axis[1].x, -1.0f, 1e-6f);
}

TEST(MapEntities, DefaultRadiusAndMalformedValuesWarn) {
  MapEntity e;
  e.keys = {{"classname", "light"}, {"_color", "red"}};
  std::vector<std::string> warnings;
  MapLight l = light_from_entity(e, "m.map:7", warnings);
  EXPECT_EQ(l.light.radius, glm::vec3(300.0f));
  EXPECT_EQ(l.light.color, glm::vec3(1.0f));
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("m.map:7"), std::string::npos);
  EXPECT_NE(warnings[0].find("_color"), std::string::npos);
}

TEST(MapEntities, EntityRotationRowsAreAxes) {
  MapFile map = parse_map(read_text(data_dir() / "base/maps/two_rooms.map"), "two_rooms.map");
  std::vector<std::string> warnings;
  Entity crate = entity_from_map(map.entities[5], "two_rooms.map", warnings);
  EXPECT_EQ(crate.classname, "func_static");
  EXPECT_EQ(crate.origin, glm::vec3(100, 20, 0));
  EXPECT_EQ(crate.axis[0], glm::vec3(0, 1, 0));
  EXPECT_EQ(crate.axis[1], glm::vec3(-1, 0, 0));
  EXPECT_EQ(crate.keys.at("model"), "func_static_crate");
}

struct BrokenMap {
  const char* file;
  int line;
  const char* message_part;
};

class BrokenMapFile : public ::testing::TestWithParam<BrokenMap> {};

TEST_P(BrokenMapFile, GivesFileLineAndMessage) {
  const BrokenMap& b = GetParam();
  try {
    parse_map(read_text(data_dir() / "broken" / b.file), b.file);
    FAIL() << b.file << " parsed without error";
  } catch (const ParseError& e) {
    EXPECT_EQ(e.line(), b.line) << e.what();
    EXPECT_NE(std::string(e.what()).find(b.message_part), std::string::npos) << e.what();
  }
}

INSTANTIATE_TEST_SUITE_P(Files, BrokenMapFile,
                         ::testing::Values(BrokenMap{"unterminated_string.map", 6, "unterminated string"},
                                           BrokenMap{"truncated.map", 5, "end of file"},
                                           BrokenMap{"missing_value.map", 5, "quoted value for key \"origin\""},
                                           BrokenMap{"bad_version.map", 1, "found 'two'"}),
                         [](const auto& info) {
                           std::string n = info.param.file;
                           for (char& c : n)
                             if (!isalnum(static_cast<unsigned char>(c))) c = '_';
                           return n;
                         });
