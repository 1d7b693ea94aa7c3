// `cohort pack`: one self-contained binary file holding a compiled scene (geometry, BLASes, instances,
// materials, lights, decoded and mip-mapped textures). It loads with no image library, faster than
// decoding hundreds of images, and is what a remote tracer would be sent. Format: docs/scene-pack.md.
#pragma once

#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "cohort/commit/tracer_scene.h"

namespace cohort::core {

struct PackedScene {
  std::string map_name;
  commit::TracerScene tracer_scene;
  std::vector<uint32_t> blas_of_mesh;     // scene mesh index -> BLAS index (K_NONE if unused)
  uint32_t world_blas = K_NONE;
  std::vector<std::string> instance_names;  // per instance in tracer_scene.instances: entity name or "world"
  float player_start[3] = {0, 0, 0};
  float player_yaw = 0.0f;
};

class PackError : public std::runtime_error {
 public:
  PackError(const std::string& file, uint64_t offset, const std::string& what);
};

constexpr uint32_t kScenePackVersion = 3;  // 2: vertex colours (VCOL); 3: KMaterial's environment cube (128 bytes)

void write_scene_pack(const std::filesystem::path& file, const PackedScene& pack);
PackedScene read_scene_pack(const std::filesystem::path& file);
// True when the file starts with the pack magic (so `render` can take either a map or a pack).
bool is_scene_pack(const std::filesystem::path& file);

}  // namespace cohort::core
