#include "entity_models.h"

#include "cohort/scene/md5.h"
#include "cohort/scene/model_file.h"
#include "ascii_case.h"

namespace cohort::scene {

namespace {

bool is_model_file(const std::string& name) {
  return ends_with_ignoring_case(name, ".ase") || ends_with_ignoring_case(name, ".lwo") ||
         ends_with_ignoring_case(name, ".md5mesh");
}

}  // namespace

int EntityModels::mesh_for(const std::string& model, std::string skin, const std::string& anim, Entity& entity,
                           const std::string& where) {
  std::string file = model, anim_file;
  if (const ModelDefDecl* def = decls_.model_def(model)) {
    file = def->mesh;
    if (skin.empty()) skin = def->skin;
    for (const auto& [name, path] : def->anims)
      if (equals_ignoring_case(name, anim) || (anim.empty() && anim_file.empty())) anim_file = path;
    if (!anim.empty() && !ends_with_ignoring_case(anim, ".md5anim") && !equals_ignoring_case(anim_file, anim)) {
      bool known = false;
      for (const auto& a : def->anims) known = known || equals_ignoring_case(a.first, anim);
      if (!known) scene_.warnings.push_back(where + ": modelDef " + def->name + " has no anim '" + anim + "'");
    }
    if (file.empty()) {
      scene_.warnings.push_back(where + ": modelDef " + def->name + " (" + def->file + ":" + std::to_string(def->line) +
                                ") names no mesh; using a placeholder box");
      file = model;
    }
  } else if (!is_model_file(model)) {
    return -1;
  }
  if (ends_with_ignoring_case(anim, ".md5anim")) anim_file = anim;
  if (!ends_with_ignoring_case(file, ".md5mesh")) anim_file.clear();
  Loaded loaded = load(file, skin, anim_file, where);
  if (!loaded.error.empty()) {
    scene_.warnings.push_back(where + ": entity " + entity.name + ": " + loaded.error + "; using a placeholder box");
    ++report_.unresolved_models[file];
  }
  entity.model_file = file;
  entity.skin = skin;
  entity.anim_file = anim_file;
  entity.anim = loaded.anim;
  return loaded.mesh;
}

EntityModels::Loaded EntityModels::load(const std::string& file, const std::string& skin, const std::string& anim_file,
                                        const std::string& where) {
  const std::string key = Vfs::normalize(file) + "|" + canonical_decl_name(skin) + "|" + Vfs::normalize(anim_file);
  auto cached = loaded_.find(key);
  if (cached != loaded_.end()) return cached->second;

  Loaded out;
  ModelFile model;
  try {
    if (ends_with_ignoring_case(file, ".md5mesh")) {
      auto text = vfs_.read(file);
      if (!text) throw std::runtime_error(file + ": model file not found");
      Md5Mesh mesh = parse_md5mesh(*text, vfs_.describe(file));
      model = skin_md5(mesh, bind_pose(mesh));
      model.mesh.skin = std::make_shared<const MeshSkin>(md5_mesh_skin(mesh));
      if (!anim_file.empty()) {
        // The animation must fit the skeleton; a mismatch is reported but the mesh still shows.
        try {
          auto anim_text = vfs_.read(anim_file);
          if (!anim_text) throw std::runtime_error(anim_file + ": animation file not found");
          auto anim = std::make_shared<Md5Anim>(parse_md5anim(*anim_text, vfs_.describe(anim_file)));
          check_anim_matches(mesh, *anim);
          out.anim = std::move(anim);
        } catch (const std::exception& e) {
          scene_.warnings.push_back(where + ": " + e.what());
        }
      }
    } else {
      model = load_model_file(vfs_, file);
    }
    for (const std::string& w : model.warnings) scene_.warnings.push_back(w);
  } catch (const std::exception& e) {   // ParseError names file:line; a missing file names the file
    out.error = e.what();
    model = placeholder_model(file);
  }
  if (!skin.empty()) {
    if (const SkinDecl* decl = decls_.skin(skin)) {
      for (std::string& material : model.surface_materials) material = apply_skin(*decl, material);
    } else {
      scene_.warnings.push_back(where + ": skin '" + skin + "' is not defined in any skins/*.skin or def/*.def; "
                                "the model keeps its materials");
    }
  }
  for (size_t s = 0; s < model.mesh.surfaces.size(); ++s)
    model.mesh.surfaces[s].material = material_(model.surface_materials[s]);
  model.mesh.name = Vfs::normalize(file) + (skin.empty() ? "" : "#" + canonical_decl_name(skin));
  out.mesh = static_cast<int>(scene_.meshes.size());
  scene_.meshes.push_back(std::move(model.mesh));
  if (out.error.empty()) ++report_.model_files_loaded;
  loaded_.emplace(key, out);
  return out;
}

}  // namespace cohort::scene
