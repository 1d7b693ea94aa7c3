// The compiled-map (.proc, "mapProcFile003") reader: area and inline models, portals, the area BSP.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "cohort/scene/parse_error.h"
#include "cohort/scene/scene.h"

namespace cohort::scene {

struct ProcModel {
  Mesh mesh;                                  // Surface::material left at -1; see surface_materials
  std::vector<std::string> surface_materials;  // material name per mesh surface
  int area = -1;                              // N for "_areaN", -1 for inline models
};

struct ProcFile {
  std::vector<ProcModel> models;
  int area_count = 0;            // from interAreaPortals, or 1 + the highest _areaN
  std::vector<Portal> portals;
  std::vector<AreaNode> nodes;
  int shadow_models_skipped = 0;
};

// Throws ParseError (file_name:line:column) on malformed input.
ProcFile parse_proc(std::string_view text, const std::string& file_name);

}  // namespace cohort::scene
