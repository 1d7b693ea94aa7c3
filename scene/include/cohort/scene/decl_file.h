// Game decls a renderer needs beyond materials: entityDefs (def/*.def), modelDefs (`model` decls in
// .def files) and skins (skins/*.skin), read as the engine's DeclManager, DeclEntityDef, Anim_Blend
// (idDeclModelDef) and DeclSkin do; and the library that resolves their names and inherit chains.
#pragma once

#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "cohort/scene/parse_error.h"

namespace cohort::scene {

using KeyValues = std::vector<std::pair<std::string, std::string>>;   // in file order

struct EntityDefDecl {
  std::string name, file;
  int line = 0;
  KeyValues keys;
};

struct ModelDefDecl {
  std::string name, file;
  int line = 0;
  std::string inherit, mesh, skin;
  glm::vec3 offset{0.0f};
  std::vector<std::pair<std::string, std::string>> anims;   // anim name, first md5anim file
};

struct SkinDecl {
  std::string name, file;
  int line = 0;
  std::vector<std::pair<std::string, std::string>> remaps;   // from (canonical, or "*"), to
};

struct DeclFile {
  std::vector<EntityDefDecl> entity_defs;
  std::vector<ModelDefDecl> model_defs;
  std::vector<SkinDecl> skins;
  std::vector<std::string> warnings;    // decls the engine would default, with file:line
};

// `default_type` is the folder's type for decls written without a type word: "entityDef" for def/,
// "skin" for skins/. Other decl types (material, table, fx, ...) are skipped. Throws ParseError for
// malformed structure (unbalanced braces, a missing name).
DeclFile parse_decls(std::string_view text, const std::string& file_name, std::string_view default_type);

// An inherit chain that loops or runs too deep; the message names the chain.
class DeclError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// What a class name resolves to: its keys with every ancestor merged in (child first, editor_* keys
// dropped, classname = the def's own name), and every class it inherits from.
struct ResolvedEntityDef {
  KeyValues keys;
  std::set<std::string> ancestors;      // lower case, the def itself and undefined parents included
  std::string file;
  int line = 0;
  // The value of a key (case-insensitive), or nullptr.
  const std::string* get(std::string_view key) const;
};

class DeclLibrary {
 public:
  static constexpr int kMaxInheritDepth = 32;

  // Adds a file's decls; a name defined again warns and the first definition is kept.
  void add(DeclFile file, std::vector<std::string>& warnings);

  // nullptr for an unknown class; throws DeclError for a cyclic or too-deep chain. Unknown parents warn
  // (once, into `warnings`) and are skipped, as the engine does.
  const ResolvedEntityDef* entity_def(const std::string& name, std::vector<std::string>& warnings);
  // A modelDef with its inherit chain applied (mesh, skin, offset, anims from the nearest definer).
  // nullptr when unknown; DeclError for a cyclic chain.
  const ModelDefDecl* model_def(const std::string& name);
  const SkinDecl* skin(const std::string& name) const;

  size_t entity_def_count() const { return entity_defs_.size(); }
  size_t model_def_count() const { return model_defs_.size(); }
  size_t skin_count() const { return skins_.size(); }

 private:
  const ResolvedEntityDef& resolve(const std::string& key, std::vector<std::string>& chain,
                                   std::vector<std::string>& warnings);

  std::map<std::string, EntityDefDecl> entity_defs_;   // by lower-case name
  std::map<std::string, ModelDefDecl> model_defs_;
  std::map<std::string, SkinDecl> skins_;
  std::map<std::string, ResolvedEntityDef> resolved_;
  std::map<std::string, ModelDefDecl> resolved_models_;
};

// A skin's remap of one material name (canonical): the first matching pair wins, "*" matches any.
// Returns the name unchanged when no pair matches.
std::string apply_skin(const SkinDecl& skin, const std::string& material);

}  // namespace cohort::scene
