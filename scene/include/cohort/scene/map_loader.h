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
  int emitters = 0;                          // materials that glow (ambient-only stages)
  int emitting_surfaces = 0;                 // of those, opaque ones: light sources for NEE (the rest are layers)
  int skies = 0;                             // sky materials (cube map + texgen skybox/wobbleSky; docs/sky.md)
  int environment_maps = 0;                  // materials with an environment stage (texgen reflect/normal)
  int no_self_shadow = 0;                    // materials marked noSelfShadow
  int def_files = 0, entity_defs = 0, model_defs = 0, skins = 0;
  int model_files_loaded = 0;                // distinct model files (and skins of them) read
  std::map<std::string, int> unresolved_classes;   // classnames no entityDef defines, with their counts
  std::map<std::string, int> unresolved_models;    // model names that failed (placeholder box), counts
  std::vector<std::string> warnings;         // also in Scene::warnings
};

// Entities: each map entity's keys are completed from the entityDef of its classname (def/*.def, inherit
// chains resolved); a class inheriting from `light` is a light. A `model` key names an inline .proc
// model, a modelDef, or a model file (.ase, .lwo, .md5mesh) read through the VFS; entities naming the
// same model and skin share one Scene mesh. A missing or broken model file warns (file:line) and the
// entity gets the engine's default cube. `skin` (or the modelDef's) remaps the mesh's materials from
// skins/*.skin. A cyclic or too-deep inherit chain throws DeclError.
//
// `map` is a disk path to a .map file (its base folder, the parent of maps/, is added to the Vfs), a
// game path such as "maps/testmap.map", or a bare name ("testmap"). Throws ParseError for malformed
// .map/.proc/.mtr structure and std::runtime_error when the map or its .proc cannot be found.
Scene load_map(Vfs& vfs, const std::string& map, LoadReport* report = nullptr);

}  // namespace cohort::scene
