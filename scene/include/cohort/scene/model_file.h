// Model files a map's entities name (idTech 4's model manager): ASE and LWO static meshes, and the
// placeholder cube that stands in for a model that is missing or broken. MD5 skeletal models are in
// md5.h. Every parser takes the file's bytes and a name for messages; malformed input throws ParseError
// naming file:line (text formats) or file and byte offset (LWO).
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>

#include "cohort/scene/parse_error.h"
#include "cohort/scene/scene.h"
#include "cohort/scene/vfs.h"

namespace cohort::scene {

struct ModelFile {
  // Surface::material left at -1 (see surface_materials); mesh.colors holds the vertex colours where the
  // format has them (ASE CVERTLIST, else white; LWO RGB/RGBA vertex maps, else the surface COLR) and is
  // empty for MD5, whose vertices are white here.
  Mesh mesh;
  std::vector<std::string> surface_materials;  // material name per mesh surface (canonical: no extension)
  std::vector<std::string> warnings;           // things the engine would only warn about
};

// ASE (3ds Max ASCII export), read as Model_ase.cpp does: vertices as stored, faces turned to idTech's
// clockwise fronts, one material per object from the diffuse *BITMAP path, file normals kept.
ModelFile parse_ase(std::string_view text, const std::string& file_name);
// LightWave object, LWO2 (and the older LWOB), first layer only, as Model_lwo.cpp reads it.
ModelFile parse_lwo(std::string_view bytes, const std::string& file_name);

// A model file through the VFS, by extension (.ase, .lwo, .md5mesh in its bind pose). Throws ParseError
// for malformed files and std::runtime_error for missing ones or unknown extensions.
ModelFile load_model_file(const Vfs& vfs, const std::string& name);

// The engine's default model: a cube of half-size 8 around the origin with the default material.
ModelFile placeholder_model(const std::string& name);

// idTech 4's canonical decl name: lower case, '/' separators, everything from the last '.' removed.
std::string canonical_decl_name(std::string_view name);

}  // namespace cohort::scene
