#include <cstdio>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "cohort/core/scene_pack.h"

using namespace cohort::core;
namespace fs = std::filesystem;

namespace {

PackedScene small_pack() {
  PackedScene p;
  p.map_name = "maps/unit";
  auto& s = p.tracer_scene;
  s.vertices.resize(3);
  s.vertices[1].pos[0] = 1.0f;
  s.vertices[2].pos[1] = 1.0f;
  s.vertex_colors.assign(3, K_VERTEX_COLOR_WHITE);
  s.triangles.push_back({0, 1, 2, 0});
  s.blas_nodes.push_back({{0, 0, 0}, 0, {1, 1, 0}, 1});
  s.blases.push_back({0, 1, 0, 1});
  KInstance inst{};
  inst.blas = 0;
  inst.mask = K_MASK_PRIMARY | K_MASK_SHADOW;
  s.instances.push_back(inst);
  s.tlas_nodes.push_back({{0, 0, 0}, 0, {1, 1, 0}, 1});
  s.materials.resize(1);
  s.textures.push_back({0, 2, 2, K_TEX_SRGB | (1u << 8)});
  s.texels = {0xff0000ffu, 0xff00ff00u, 0xffff0000u, 0xffffffffu};
  s.lights.resize(2);
  s.lights[1].type = K_LIGHT_PROJECTED;
  s.camera.width = 64;
  p.blas_of_mesh = {0, K_NONE};
  p.world_blas = 0;
  p.instance_names = {"world"};
  p.player_start[2] = 40.0f;
  p.player_yaw = 90.0f;
  return p;
}

fs::path temp_file(const char* name) { return fs::temp_directory_path() / (std::string("cohort_") + name); }

std::vector<char> read_all(const fs::path& f) {
  std::ifstream in(f, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_all(const fs::path& f, const std::vector<char>& bytes) {
  std::ofstream out(f, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), std::streamsize(bytes.size()));
}

}  // namespace

TEST(ScenePack, RoundTripKeepsEveryArray) {
  auto file = temp_file("roundtrip.cpk");
  PackedScene in = small_pack();
  write_scene_pack(file, in);
  ASSERT_TRUE(is_scene_pack(file));
  PackedScene out = read_scene_pack(file);
  EXPECT_EQ(out.map_name, in.map_name);
  EXPECT_EQ(out.tracer_scene.texels, in.tracer_scene.texels);
  EXPECT_EQ(out.tracer_scene.triangles.size(), 1u);
  EXPECT_EQ(out.tracer_scene.triangles[0].v2, 2u);
  EXPECT_EQ(out.tracer_scene.lights[1].type, K_LIGHT_PROJECTED);
  EXPECT_EQ(out.tracer_scene.camera.width, 64u);
  EXPECT_EQ(out.blas_of_mesh, in.blas_of_mesh);
  EXPECT_EQ(out.instance_names, in.instance_names);
  EXPECT_FLOAT_EQ(out.player_start[2], 40.0f);
  EXPECT_FLOAT_EQ(out.player_yaw, 90.0f);
  fs::remove(file);
}

TEST(ScenePack, EveryTruncationIsAClearErrorNotACrash) {
  auto file = temp_file("truncated.cpk");
  write_scene_pack(file, small_pack());
  auto bytes = read_all(file);
  for (size_t n = 0; n < bytes.size(); ++n) {
    write_all(file, std::vector<char>(bytes.begin(), bytes.begin() + long(n)));
    EXPECT_THROW(read_scene_pack(file), PackError) << "truncated to " << n << " bytes";
  }
  fs::remove(file);
}

TEST(ScenePack, FlippedByteIsDetected) {
  auto file = temp_file("flipped.cpk");
  write_scene_pack(file, small_pack());
  auto bytes = read_all(file);
  size_t detected = 0;
  for (size_t i = 0; i < bytes.size(); ++i) {
    auto copy = bytes;
    copy[i] = char(copy[i] ^ 0x5a);
    write_all(file, copy);
    try {
      read_scene_pack(file);
    } catch (const PackError&) {
      ++detected;
    }
  }
  // Every byte is covered by the magic, a header field or a checksum.
  EXPECT_EQ(detected, bytes.size());
  fs::remove(file);
}

TEST(ScenePack, ErrorNamesFileAndOffset) {
  auto file = temp_file("bad_magic.cpk");
  write_all(file, std::vector<char>(64, 'x'));
  try {
    read_scene_pack(file);
    FAIL() << "expected a PackError";
  } catch (const PackError& e) {
    EXPECT_NE(std::string(e.what()).find("bad_magic.cpk: byte 8: not a Cohort scene pack"), std::string::npos)
        << e.what();
  }
  fs::remove(file);
}

TEST(ScenePack, VertexColoursRoundTripAndMustMatchTheVertices) {
  auto file = temp_file("colours.cpk");
  PackedScene in = small_pack();
  in.tracer_scene.vertex_colors = {0xFF0000FFu, 0x80FF00FFu, K_VERTEX_COLOR_WHITE};
  write_scene_pack(file, in);
  EXPECT_EQ(read_scene_pack(file).tracer_scene.vertex_colors, in.tracer_scene.vertex_colors);
  in.tracer_scene.vertex_colors.pop_back();
  write_scene_pack(file, in);
  try {
    read_scene_pack(file);
    FAIL() << "read a pack with 2 vertex colours for 3 vertices";
  } catch (const PackError& e) {
    EXPECT_NE(std::string(e.what()).find("2 vertex colours for 3 vertices"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(file.string()), std::string::npos) << e.what();
  }
  fs::remove(file);
}
