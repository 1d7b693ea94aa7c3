#include <algorithm>

#include "cohort/scene/decl_file.h"
#include "cohort/scene/model_file.h"
#include "ascii_case.h"

namespace cohort::scene {

namespace {

template <typename Decl>
void add_first_wins(std::map<std::string, Decl>& into, Decl decl, const char* type, std::vector<std::string>& warnings) {
  std::string key = lowercase(decl.name);
  auto existing = into.find(key);
  if (existing != into.end()) {
    warnings.push_back(decl.file + ":" + std::to_string(decl.line) + ": " + type + " " + decl.name +
                       " already defined at " + existing->second.file + ":" + std::to_string(existing->second.line) +
                       "; the first is kept");
    return;
  }
  into.emplace(std::move(key), std::move(decl));
}

std::string chain_text(const std::vector<std::string>& chain) {
  std::string out;
  for (const std::string& name : chain) out += (out.empty() ? "" : " -> ") + name;
  return out;
}

}  // namespace

const std::string* ResolvedEntityDef::get(std::string_view key) const {
  for (const auto& [k, v] : keys)
    if (equals_ignoring_case(k, key)) return &v;
  return nullptr;
}

void DeclLibrary::add(DeclFile file, std::vector<std::string>& warnings) {
  for (auto& w : file.warnings) warnings.push_back(std::move(w));
  for (auto& d : file.entity_defs) add_first_wins(entity_defs_, std::move(d), "entityDef", warnings);
  for (auto& d : file.model_defs) add_first_wins(model_defs_, std::move(d), "model", warnings);
  // Skins are looked up by canonical name (a skin may be named like a file).
  for (auto& d : file.skins) {
    d.name = canonical_decl_name(d.name);
    add_first_wins(skins_, std::move(d), "skin", warnings);
  }
  resolved_.clear();
  resolved_models_.clear();
}

const ResolvedEntityDef* DeclLibrary::entity_def(const std::string& name, std::vector<std::string>& warnings) {
  std::string key = lowercase(name);
  if (entity_defs_.find(key) == entity_defs_.end()) return nullptr;
  std::vector<std::string> chain;
  return &resolve(key, chain, warnings);
}

// idDeclEntityDef::Parse: classname forced to the def's name, then every key starting with "inherit"
// names a parent (dict order); the parents' resolved keys fill in what the child lacks.
const ResolvedEntityDef& DeclLibrary::resolve(const std::string& key, std::vector<std::string>& chain,
                                              std::vector<std::string>& warnings) {
  auto done = resolved_.find(key);
  if (done != resolved_.end()) return done->second;
  const EntityDefDecl& decl = entity_defs_.at(key);
  chain.push_back(decl.name);
  if (std::find(chain.begin(), chain.end() - 1, decl.name) != chain.end() - 1)
    throw DeclError(decl.file + ":" + std::to_string(decl.line) + ": entityDef inherit chain loops: " + chain_text(chain));
  if (static_cast<int>(chain.size()) > kMaxInheritDepth)
    throw DeclError(decl.file + ":" + std::to_string(decl.line) + ": entityDef inherit chain deeper than " +
                    std::to_string(kMaxInheritDepth) + ": " + chain_text(chain));
  ResolvedEntityDef out;
  out.file = decl.file;
  out.line = decl.line;
  out.ancestors.insert(key);
  std::vector<std::string> parents;
  for (const auto& [k, v] : decl.keys) {
    if (starts_with_ignoring_case(k, "inherit")) parents.push_back(v);
    else if (starts_with_ignoring_case(k, "editor_") || equals_ignoring_case(k, "classname")) continue;
    else out.keys.emplace_back(k, v);
  }
  out.keys.emplace_back("classname", decl.name);
  for (const std::string& parent : parents) {
    std::string parent_key = lowercase(parent);
    if (entity_defs_.find(parent_key) == entity_defs_.end()) {
      out.ancestors.insert(parent_key);   // still named: a class inheriting an undefined `light` is a light
      warnings.push_back(decl.file + ":" + std::to_string(decl.line) + ": entityDef " + decl.name + " inherits '" +
                         parent + "', which is not defined");
      continue;
    }
    if (std::find(chain.begin(), chain.end(), entity_defs_.at(parent_key).name) != chain.end()) {
      chain.push_back(entity_defs_.at(parent_key).name);
      throw DeclError(decl.file + ":" + std::to_string(decl.line) + ": entityDef inherit chain loops: " +
                      chain_text(chain));
    }
    const ResolvedEntityDef& base = resolve(parent_key, chain, warnings);
    out.ancestors.insert(base.ancestors.begin(), base.ancestors.end());
    for (const auto& [k, v] : base.keys)
      if (!out.get(k)) out.keys.emplace_back(k, v);
  }
  chain.pop_back();
  return resolved_.emplace(key, std::move(out)).first->second;
}

const ModelDefDecl* DeclLibrary::model_def(const std::string& name) {
  std::string key = lowercase(name);
  auto done = resolved_models_.find(key);
  if (done != resolved_models_.end()) return &done->second;
  auto found = model_defs_.find(key);
  if (found == model_defs_.end()) return nullptr;
  ModelDefDecl out = found->second;
  std::vector<std::string> chain{out.name};
  for (std::string parent = out.inherit; !parent.empty();) {
    auto base = model_defs_.find(lowercase(parent));
    if (base == model_defs_.end()) break;
    chain.push_back(base->second.name);
    if (std::find(chain.begin(), chain.end() - 1, base->second.name) != chain.end() - 1 ||
        static_cast<int>(chain.size()) > kMaxInheritDepth)
      throw DeclError(out.file + ":" + std::to_string(out.line) + ": model inherit chain loops or runs too deep: " +
                      chain_text(chain));
    if (out.mesh.empty()) out.mesh = base->second.mesh;
    if (out.skin.empty()) out.skin = base->second.skin;
    for (const auto& anim : base->second.anims)
      if (std::none_of(out.anims.begin(), out.anims.end(), [&](const auto& a) { return a.first == anim.first; }))
        out.anims.push_back(anim);
    parent = base->second.inherit;
  }
  return &resolved_models_.emplace(key, std::move(out)).first->second;
}

const SkinDecl* DeclLibrary::skin(const std::string& name) const {
  auto found = skins_.find(canonical_decl_name(name));
  return found == skins_.end() ? nullptr : &found->second;
}

}  // namespace cohort::scene
