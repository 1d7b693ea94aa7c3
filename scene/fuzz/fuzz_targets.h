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

#include "cohort/scene/decl_file.h"
#include "cohort/scene/image_decode.h"
#include "cohort/scene/image_library.h"
#include "cohort/scene/image_ops.h"
#include "cohort/scene/map_entities.h"
#include "cohort/scene/map_file.h"
#include "cohort/scene/material_build.h"
#include "cohort/scene/material_file.h"
#include "cohort/scene/md5.h"
#include "cohort/scene/model_file.h"
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

// A model the parser returned must be well formed: whole triangles, indices in range, surfaces covering
// the index list, one material name per surface, colours (when present) one per vertex.
inline void check_model(const ModelFile& model) {
  const Mesh& mesh = model.mesh;
  if (mesh.indices.size() % 3 != 0 || model.surface_materials.size() != mesh.surfaces.size()) __builtin_trap();
  if (!mesh.colors.empty() && mesh.colors.size() != mesh.vertices.size()) __builtin_trap();
  for (uint32_t index : mesh.indices)
    if (index >= mesh.vertices.size()) __builtin_trap();
  for (const Surface& s : mesh.surfaces)
    if (size_t(s.first_index) + s.index_count > mesh.indices.size()) __builtin_trap();
}

inline void fuzz_ase(const uint8_t* data, size_t size) {
  try {
    check_model(parse_ase(as_text(data, size), "fuzz.ase"));
  } catch (const ParseError&) {
  }
}

inline void fuzz_lwo(const uint8_t* data, size_t size) {
  try {
    check_model(parse_lwo(as_text(data, size), "fuzz.lwo"));
  } catch (const ParseError&) {
  }
}

// Either kind of MD5 file: a mesh is skinned in its bind pose, an animation evaluated at a few times.
inline void fuzz_md5(const uint8_t* data, size_t size) {
  try {
    Md5Mesh mesh = parse_md5mesh(as_text(data, size), "fuzz.md5mesh");
    check_model(skin_md5(mesh, bind_pose(mesh)));
  } catch (const ParseError&) {
  }
  try {
    Md5Anim anim = parse_md5anim(as_text(data, size), "fuzz.md5anim");
    for (int t : {0, 17, 1000, anim.length_ms(), 123456789})
      if (anim_pose(anim, t).size() != anim.joints.size()) __builtin_trap();
  } catch (const ParseError&) {
  }
}

// def/*.def or skins/*.skin text: parsed, then every class, modelDef and skin resolved (cycles and deep
// chains must end in DeclError, never in unbounded recursion).
inline void fuzz_def(const uint8_t* data, size_t size) {
  try {
    DeclFile file = parse_decls(as_text(data, size), "fuzz.def", "entityDef");
    DeclLibrary library;
    std::vector<std::string> warnings;
    library.add(file, warnings);
    for (const EntityDefDecl& def : file.entity_defs) {
      try {
        library.entity_def(def.name, warnings);
      } catch (const DeclError&) {
      }
    }
    for (const ModelDefDecl& def : file.model_defs) {
      try {
        library.model_def(def.name);
      } catch (const DeclError&) {
      }
    }
    for (const SkinDecl& skin : file.skins) apply_skin(skin, "textures/a");
  } catch (const ParseError&) {
  }
}

}  // namespace cohort::scene::fuzz
