// The entry point from files to a Scene: reads a .map, the .proc beside it, every materials/*.mtr,
// and the images the used materials name.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "cohort/scene/parse_error.h"
#include "cohort/scene/scene.h"
#include "cohort/scene/vfs.h"

namespace cohort::scene {

struct LoadReport {
  std::string map_file, proc_file;           // where they were read from
  int material_files = 0;
  int materials_declared = 0;                // across all .mtr files
  int materials_used = 0, materials_missing = 0;
  int images_loaded = 0, images_placeholder = 0;
  int areas = 0, inline_models = 0, portals = 0, nodes = 0, shadow_models_skipped = 0;
  size_t world_triangles = 0, entity_triangles = 0;
  int lights_point = 0, lights_projected = 0, lights_parallel = 0;
  std::map<std::string, int> entities_by_class;
  int emitters = 0;
  std::vector<std::string> warnings;         // also in Scene::warnings
};

// `map` is a disk path to a .map file (its base folder, the parent of maps/, is added to the Vfs), a
// game path such as "maps/testmap.map", or a bare name ("testmap"). Throws ParseError for malformed
// .map/.proc/.mtr structure and std::runtime_error when the map or its .proc cannot be found.
Scene load_map(Vfs& vfs, const std::string& map, LoadReport* report = nullptr);

}  // namespace cohort::scene
