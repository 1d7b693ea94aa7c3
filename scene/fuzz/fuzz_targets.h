// One function per parser that takes arbitrary bytes: the libFuzzer targets call them, and the
// corpus replay test (tests/scene/fuzz_corpus_test.cpp) runs them over the seed corpus in every
// build, so a crash the fuzzer once found stays fixed. Parse errors are expected outcomes; anything
// else escaping, a crash, a hang or a sanitizer report is a bug.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "cohort/scene/image_decode.h"
#include "cohort/scene/image_library.h"
#include "cohort/scene/image_ops.h"
#include "cohort/scene/map_entities.h"
#include "cohort/scene/map_file.h"
#include "cohort/scene/material_build.h"
#include "cohort/scene/material_file.h"
#include "cohort/scene/proc_file.h"

namespace cohort::scene::fuzz {

inline std::string_view as_text(const uint8_t* data, size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

inline void fuzz_proc(const uint8_t* data, size_t size) {
  try {
    ProcFile proc = parse_proc(as_text(data, size), "fuzz.proc");
    for (const ProcModel& m : proc.models)
      for (uint32_t index : m.mesh.indices)
        if (index >= m.mesh.vertices.size()) __builtin_trap();   // the parser promised valid indices
  } catch (const ParseError&) {
  }
}

inline void fuzz_map(const uint8_t* data, size_t size) {
  try {
    MapFile map = parse_map(as_text(data, size), "fuzz.map");
    std::vector<std::string> warnings;
    for (const MapEntity& e : map.entities) {
      if (is_light_entity(e)) light_from_entity(e, "fuzz.map", warnings);
      else entity_from_map(e, "fuzz.map", warnings);
    }
  } catch (const ParseError&) {
  }
}

inline void fuzz_mtr(const uint8_t* data, size_t size) {
  try {
    MaterialTables tables;
    MaterialFile file = parse_materials(as_text(data, size), "fuzz.mtr", tables);
    Vfs empty;   // every image is missing: exercises the placeholder paths of the builder
    std::vector<Image> images;
    std::vector<std::string> warnings;
    ImageLibrary library(empty, images, warnings);
    for (const MaterialDecl& decl : file.materials) {
      build_material(decl, library, false);
      build_material(decl, library, true);
    }
  } catch (const ParseError&) {
  }
}

inline void fuzz_image(const uint8_t* data, size_t size) {
  std::string error;
  auto tga = decode_tga(as_text(data, size), error);
  if (tga && tga->rgba.size() != static_cast<size_t>(tga->width) * tga->height * 4) __builtin_trap();
  if (tga && static_cast<long long>(tga->width) * tga->height <= 4096) {
    heightmap_to_normals(*tga, 3.0f);
    add_normals(*tga, *tga);
    smooth_normals(*tga);
    make_alpha(*tga);
  }
  is_rxgb_dds(as_text(data, size));
}

}  // namespace cohort::scene::fuzz
