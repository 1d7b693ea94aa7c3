#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <gtest/gtest.h>

#include "id_plane_output.h"

namespace cohort::app {
namespace {

TEST(IdPlaneOutput, WritesA16BitPgmThatReadsBack) {
  const std::filesystem::path path = std::filesystem::path(testing::TempDir()) / "cohort_ids_test.pgm";
  // 3x2: the world, two entities, a miss, an id too large for 16 bits.
  const std::vector<uint32_t> id = {0u, 3u, 258u, 0xFFFFFFFFu, 70000u, 1u};
  write_id_plane_pgm(path.string(), 3, 2, id);
  std::ifstream in(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string header = "P5\n3 2\n65535\n";
  ASSERT_EQ(bytes.size(), header.size() + 12);
  EXPECT_EQ(bytes.substr(0, header.size()), header);
  auto value = [&](int p) {
    return (unsigned(static_cast<unsigned char>(bytes[header.size() + 2 * p])) << 8) |
           unsigned(static_cast<unsigned char>(bytes[header.size() + 2 * p + 1]));
  };
  EXPECT_EQ(value(0), 0u);
  EXPECT_EQ(value(1), 3u);
  EXPECT_EQ(value(2), 258u) << "big-endian, as PGM stores 16-bit samples";
  EXPECT_EQ(value(3), kIdPlaneMiss);
  EXPECT_EQ(value(4), kIdPlaneMiss - 1u) << "ids past 16 bits are not mistaken for a miss";
  EXPECT_EQ(value(5), 1u);
  std::filesystem::remove(path);
}

TEST(IdPlaneOutput, RejectsAPlaneOfTheWrongSize) {
  EXPECT_THROW(write_id_plane_pgm((std::filesystem::path(testing::TempDir()) / "x.pgm").string(), 4, 4, {1u, 2u}),
               std::runtime_error);
}

TEST(IdPlaneOutput, MovedEntitiesNamesTheDefsWhosePlacementChanged) {
  scene::Scene s;
  s.name = "t";
  s.entities.resize(3);
  s.entities[0].name = "door";
  s.entities[1].name = "crate";
  s.entities[2].name = "fan";
  scene::RenderWorld world(s);
  MovedEntities moved;
  EXPECT_TRUE(moved.update(world).empty()) << "the first frame has nothing to compare with";
  scene::RenderEntity door = *world.EntityDef(0);
  door.origin.z += 4.0f;
  world.UpdateEntityDef(0, door);
  scene::RenderEntity crate = *world.EntityDef(1);
  world.UpdateEntityDef(1, crate);  // updated, but in the same place: not moved
  scene::RenderEntity fan = *world.EntityDef(2);
  fan.shader_parms[0] = 0.5f;  // a colour change is no motion either
  world.UpdateEntityDef(2, fan);
  EXPECT_EQ(moved.update(world), std::vector<std::string>{"door"});
  EXPECT_TRUE(moved.update(world).empty()) << "the door stands still now";
  const std::map<std::string, uint32_t> ids = entity_plane_ids(world);
  EXPECT_EQ(ids.at("door"), 1u) << "the id plane gives entity handle + 1";
  EXPECT_EQ(ids.at("fan"), 3u);
}

}  // namespace
}  // namespace cohort::app
