#include <gtest/gtest.h>

#include <cstdio>
#include <unistd.h>
#include <filesystem>
#include <fstream>

#include "cohort/scene/render_world_stream.h"
#include "cohort/test_support/scene_builders.h"
#include "cohort/test_support/test_scenes.h"

using namespace cohort::scene;
namespace fs = std::filesystem;

namespace {

fs::path temp_file(const std::string& name) {
  fs::path dir = fs::temp_directory_path() / ("cohort_delta_stream_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir / name;
}

std::vector<uint8_t> read_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

void write_bytes(const fs::path& p, const std::vector<uint8_t>& bytes, size_t count) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(count));
}

// A few frames of every kind of call.
void drive(RenderWorldApi& world, int frames) {
  int door = world.FindEntityDef("door_main");
  int fan = world.FindEntityDef("fan_spin");
  int flicker = world.FindLightDef("light_flicker");
  int extra_light = -1, crate = -1;
  for (int f = 0; f < frames; ++f) {
    RenderEntity d = *world.EntityDef(door);
    d.origin.z += 2.0f;
    world.UpdateEntityDef(door, d);
    RenderEntity r = *world.EntityDef(fan);
    float a = 0.3f * float(f);
    r.axis = glm::mat3(glm::vec3(std::cos(a), std::sin(a), 0), glm::vec3(-std::sin(a), std::cos(a), 0),
                       glm::vec3(0, 0, 1));
    world.UpdateEntityDef(fan, r);
    RenderLight l = *world.LightDef(flicker);
    l.shader_parms[0] = 0.5f + 0.1f * float(f % 3);
    world.UpdateLightDef(flicker, l);
    if (f == 1) {
      RenderLight flash;
      flash.point_light = false;
      flash.target = {512, 0, 0};
      flash.right = {0, -128, 0};
      flash.up = {0, 0, 128};
      flash.shader_name = "lights/test/flicker";
      extra_light = world.AddLightDef(flash);
      int tex = world.DefineTexture(cohort::test::checker("textures/test/late", 2));
      Material m;
      m.name = "textures/test/late";
      m.diffuse_image = tex;
      m.inverse_vertex_color = true;
      // An environment stage (texgen normal) over six consecutive faces.
      for (int face = 0; face < 6; ++face) {
        const int image = world.DefineTexture(cohort::test::checker("env/late_" + std::to_string(face), 2));
        if (face == 0) m.environment_cube_image = image;
      }
      m.environment_by_normal = true;
      m.environment_under_layer = true;
      m.environment_color = {0.25f, 0.5f, 0.75f};
      int mat = world.DefineMaterial(m);
      Mesh crate_mesh = cohort::test::box_mesh("crate", {8, 8, 8}, mat);
      for (size_t v = 0; v < crate_mesh.vertices.size(); ++v) crate_mesh.colors.push_back(0xFF000000u | uint32_t(v * 0x010203u));
      world.DefineModel(crate_mesh);
      RenderEntity c;
      c.model_name = "crate";
      c.origin = {10, 20, 30};
      c.no_shadows = true;
      crate = world.AddEntityDef(c);
    }
    if (f == frames - 1 && crate >= 0) {
      world.FreeEntityDef(crate);
      world.FreeLightDef(extra_light);
    }
    RenderView view;
    view.origin = {float(f), 0, 40};
    view.time_ms = f * 16;
    world.RenderScene(view);
    world.EndFrame();
  }
}

template <class T>
void expect_same_defs(const std::vector<std::optional<T>>& a, const std::vector<std::optional<T>>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a[i], b[i]) << "handle " << i;
}

void expect_same_world(const RenderWorld& a, const RenderWorld& b) {
  expect_same_defs(a.entity_defs(), b.entity_defs());
  expect_same_defs(a.light_defs(), b.light_defs());
  EXPECT_EQ(a.view(), b.view());
  EXPECT_EQ(a.frame_count(), b.frame_count());
  ASSERT_EQ(a.scene().materials.size(), b.scene().materials.size());
  for (size_t i = 0; i < a.scene().materials.size(); ++i) {
    EXPECT_EQ(a.scene().materials[i].name, b.scene().materials[i].name);
    EXPECT_EQ(a.scene().materials[i].diffuse_image, b.scene().materials[i].diffuse_image);
    EXPECT_EQ(a.scene().materials[i].vertex_color, b.scene().materials[i].vertex_color);
    EXPECT_EQ(a.scene().materials[i].inverse_vertex_color, b.scene().materials[i].inverse_vertex_color);
    EXPECT_EQ(a.scene().materials[i].environment_cube_image, b.scene().materials[i].environment_cube_image);
    EXPECT_EQ(a.scene().materials[i].environment_by_normal, b.scene().materials[i].environment_by_normal);
    EXPECT_EQ(a.scene().materials[i].environment_under_layer, b.scene().materials[i].environment_under_layer);
    EXPECT_EQ(a.scene().materials[i].environment_color, b.scene().materials[i].environment_color);
  }
  ASSERT_EQ(a.scene().images.size(), b.scene().images.size());
  for (size_t i = 0; i < a.scene().images.size(); ++i) EXPECT_EQ(a.scene().images[i].rgba, b.scene().images[i].rgba);
  ASSERT_EQ(a.scene().meshes.size(), b.scene().meshes.size());
  for (size_t i = 0; i < a.scene().meshes.size(); ++i) {
    EXPECT_EQ(a.scene().meshes[i].indices, b.scene().meshes[i].indices);
    EXPECT_EQ(a.scene().meshes[i].colors, b.scene().meshes[i].colors);
    ASSERT_EQ(a.scene().meshes[i].vertices.size(), b.scene().meshes[i].vertices.size());
    for (size_t v = 0; v < a.scene().meshes[i].vertices.size(); ++v)
      EXPECT_EQ(a.scene().meshes[i].vertices[v].position, b.scene().meshes[i].vertices[v].position);
  }
}

fs::path record_small_stream(const std::string& name, int frames) {
  fs::path file = temp_file(name);
  RenderWorld world(cohort::test::small_test_map());
  Recorder recorder(world, file, "small");
  drive(recorder, frames);
  recorder.finish();
  return file;
}

// Plays the whole file into a fresh world; returns the error text, or "" when it played cleanly.
std::string play_all(const fs::path& file) {
  try {
    Player player(file);
    RenderWorld world(cohort::test::small_test_map());
    while (player.play_frame(world)) {
    }
    return "";
  } catch (const StreamError& e) {
    return e.what();
  }
}

}  // namespace

TEST(DeltaStream, ReplayGivesTheSameStateAsTheDirectCalls) {
  const int frames = 6;
  RenderWorld direct(cohort::test::small_test_map());
  drive(direct, frames);

  fs::path file = record_small_stream("replay.cds", frames);
  Player player(file);
  EXPECT_EQ(player.header().map_name, "small");
  EXPECT_EQ(player.header().version, kDeltaStreamVersion);
  RenderWorld replayed(cohort::test::small_test_map());
  int played = 0;
  while (player.play_frame(replayed)) {
    ++played;
    EXPECT_EQ(replayed.frame_count(), played);
  }
  EXPECT_EQ(played, frames);
  EXPECT_FALSE(player.play_frame(replayed));
  expect_same_world(direct, replayed);
  // The late crate's vertex colours and its material's inverseVertexColor came through the stream.
  const int crate = replayed.scene().find_mesh("crate");
  ASSERT_GE(crate, 0);
  ASSERT_EQ(replayed.scene().meshes[size_t(crate)].colors.size(), replayed.scene().meshes[size_t(crate)].vertices.size());
  EXPECT_EQ(replayed.scene().meshes[size_t(crate)].colors[2], 0xFF000000u | (2u * 0x010203u));
  const int late = replayed.scene().find_material("textures/test/late");
  ASSERT_GE(late, 0);
  EXPECT_TRUE(replayed.scene().materials[size_t(late)].inverse_vertex_color);
  EXPECT_GE(replayed.scene().materials[size_t(late)].environment_cube_image, 0);
  EXPECT_TRUE(replayed.scene().materials[size_t(late)].environment_by_normal);
  EXPECT_TRUE(replayed.scene().materials[size_t(late)].environment_under_layer);
  EXPECT_EQ(replayed.scene().materials[size_t(late)].environment_color, glm::vec3(0.25f, 0.5f, 0.75f));
}

TEST(DeltaStream, ModelWithColoursForSomeVerticesIsRefused) {
  RenderWorld world(cohort::test::small_test_map());
  Mesh mesh = cohort::test::box_mesh("half_coloured", {1, 1, 1}, 0);
  mesh.colors.assign(mesh.vertices.size() - 1, 0xFFFFFFFFu);
  try {
    world.DefineModel(mesh);
    FAIL() << "accepted " << mesh.colors.size() << " colours for " << mesh.vertices.size() << " vertices";
  } catch (const RenderWorldError& e) {
    EXPECT_NE(std::string(e.what()).find("'half_coloured': 7 vertex colours for 8 vertices"), std::string::npos) << e.what();
  }
}

TEST(DeltaStream, ReplayKeepsThePerFrameChangeLog) {
  fs::path file = record_small_stream("changelog.cds", 3);
  Player player(file);
  RenderWorld replayed(cohort::test::small_test_map());
  // Frame by frame, the replay's change log equals the one of the direct calls.
  for (int f = 0; f < 3; ++f) {
    ASSERT_TRUE(player.play_frame(replayed));
    ChangeLog log = replayed.TakeChanges();
    EXPECT_EQ(log.frames_ended, 1);
    EXPECT_TRUE(log.entities.count(1));
    EXPECT_TRUE(log.lights.count(0));
  }
}

TEST(DeltaStream, TruncatedAtEveryByteGivesAClearError) {
  fs::path file = record_small_stream("truncate_src.cds", 3);
  std::vector<uint8_t> bytes = read_bytes(file);
  ASSERT_GT(bytes.size(), 200u);
  fs::path cut = temp_file("truncated.cds");
  for (size_t n = 0; n < bytes.size(); ++n) {
    write_bytes(cut, bytes, n);
    std::string error = play_all(cut);
    ASSERT_FALSE(error.empty()) << "a file cut to " << n << " of " << bytes.size() << " bytes played cleanly";
    EXPECT_NE(error.find("offset"), std::string::npos) << error;
  }
  EXPECT_EQ(play_all(file), "");
}

TEST(DeltaStream, EveryFlippedByteIsDetected) {
  fs::path file = record_small_stream("flip_src.cds", 3);
  std::vector<uint8_t> bytes = read_bytes(file);
  fs::path flipped = temp_file("flipped.cds");
  for (size_t i = 0; i < bytes.size(); ++i) {
    for (uint8_t mask : {uint8_t(0x01), uint8_t(0x80)}) {
      std::vector<uint8_t> damaged = bytes;
      damaged[i] ^= mask;
      write_bytes(flipped, damaged, damaged.size());
      EXPECT_FALSE(play_all(flipped).empty()) << "flipping byte " << i << " went unnoticed";
    }
  }
}

namespace {

uint32_t le32(const std::vector<uint8_t>& b, size_t at) {
  return uint32_t(b[at]) | uint32_t(b[at + 1]) << 8 | uint32_t(b[at + 2]) << 16 | uint32_t(b[at + 3]) << 24;
}
void put32(std::vector<uint8_t>& b, size_t at, uint32_t v) {
  for (int i = 0; i < 4; ++i) b[at + i] = uint8_t(v >> (8 * i));
}

// Offset of the first frame chunk: magic, version, header length, header, header CRC.
size_t first_chunk(const std::vector<uint8_t>& b) { return 16 + le32(b, 12) + 4; }

void fix_chunk_crc(std::vector<uint8_t>& b, size_t chunk) {
  uint32_t length = le32(b, chunk + 8);
  put32(b, chunk + 12, crc32(b.data() + chunk + 16, length));
}

}  // namespace

// A checksum only catches accidents; a file written by a buggy or hostile writer must still be
// refused by the checks on every field.
TEST(DeltaStream, ForgedRecordWithAValidChecksumIsRefusedWithItsOffsetAndType) {
  fs::path file = record_small_stream("forge_src.cds", 2);
  std::vector<uint8_t> bytes = read_bytes(file);
  size_t chunk = first_chunk(bytes);
  size_t record = chunk + 16;
  ASSERT_EQ(bytes[record], uint8_t(DeltaRecord::UpdateEntityDef));
  std::vector<uint8_t> forged = bytes;
  put32(forged, record + 8, 77);  // the door's handle becomes one that does not exist
  fix_chunk_crc(forged, chunk);
  fs::path out = temp_file("forged.cds");
  write_bytes(out, forged, forged.size());
  std::string error = play_all(out);
  std::printf("example error: %s\n", error.c_str());
  EXPECT_NE(error.find("UpdateEntityDef"), std::string::npos) << error;
  EXPECT_NE(error.find("offset " + std::to_string(record)), std::string::npos) << error;
  EXPECT_NE(error.find("77"), std::string::npos) << error;

  forged = bytes;
  put32(forged, record + 4, 0x7FFFFFF0u);  // a body length far past the chunk
  fix_chunk_crc(forged, chunk);
  write_bytes(out, forged, forged.size());
  error = play_all(out);
  EXPECT_NE(error.find("runs past the frame chunk"), std::string::npos) << error;
}

TEST(DeltaStream, HugeCountsAreRefusedBeforeAllocating) {
  fs::path file = temp_file("huge_src.cds");
  {
    RenderWorld world(cohort::test::small_test_map());
    Recorder recorder(world, file, "small");
    recorder.DefineModel(cohort::test::box_mesh("m", {1, 1, 1}, 0));
    recorder.EndFrame();
    recorder.finish();
  }
  std::vector<uint8_t> bytes = read_bytes(file);
  size_t chunk = first_chunk(bytes);
  size_t body = chunk + 16 + 8;
  // DefineModel body: index i32, name (u32 length + "m"), vertex count u32.
  size_t vertex_count = body + 4 + 4 + 1;
  ASSERT_EQ(le32(bytes, vertex_count), 8u);
  put32(bytes, vertex_count, 0xFFFFFFFFu);
  fix_chunk_crc(bytes, chunk);
  fs::path out = temp_file("huge.cds");
  write_bytes(out, bytes, bytes.size());
  std::string error = play_all(out);
  EXPECT_NE(error.find("DefineModel"), std::string::npos) << error;
  EXPECT_NE(error.find("vertex count 4294967295"), std::string::npos) << error;
}

TEST(DeltaStream, NotAStreamAndWrongVersionAreNamed) {
  fs::path out = temp_file("garbage.cds");
  std::vector<uint8_t> garbage(64, 'x');
  write_bytes(out, garbage, garbage.size());
  EXPECT_NE(play_all(out).find("bad magic"), std::string::npos);
  std::vector<uint8_t> bytes = read_bytes(record_small_stream("version_src.cds", 1));
  put32(bytes, 8, 99);
  write_bytes(out, bytes, bytes.size());
  EXPECT_NE(play_all(out).find("version 99"), std::string::npos);
  EXPECT_THROW(Player(temp_file("does_not_exist.cds")), std::runtime_error);
}

TEST(DeltaStream, AStreamForAnotherMapGivesAHandleMismatch) {
  fs::path file = record_small_stream("other_map.cds", 3);
  Scene other = cohort::test::small_test_map();
  other.entities.push_back(other.entities[1]);  // one more seeded entity: the crate gets another handle
  other.entities.back().name = "door_copy";
  Player player(file);
  RenderWorld world(std::move(other));
  try {
    while (player.play_frame(world)) {
    }
    FAIL() << "played cleanly";
  } catch (const StreamError& e) {
    EXPECT_EQ(e.record(), "AddEntityDef");
    EXPECT_NE(std::string(e.what()).find("does not match this map"), std::string::npos) << e.what();
  }
}
