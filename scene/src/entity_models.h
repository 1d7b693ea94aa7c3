// The map loader's model manager: turns an entity's `model` key (an inline .proc model, a modelDef or a
// model file) into a Scene mesh, with its skin applied, loading each (model, skin) once so that every
// entity naming it shares the mesh and with it one BLAS. Private to the scene library.
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <string>

#include "cohort/scene/decl_file.h"
#include "cohort/scene/map_loader.h"
#include "cohort/scene/scene.h"
#include "cohort/scene/vfs.h"

namespace cohort::scene {

class EntityModels {
 public:
  using MaterialLookup = std::function<int(const std::string& name)>;
  EntityModels(const Vfs& vfs, Scene& scene, DeclLibrary& decls, LoadReport& report, MaterialLookup material)
      : vfs_(vfs), scene_(scene), decls_(decls), report_(report), material_(std::move(material)) {}

  // The mesh for `model` skinned by `skin` (empty: the modelDef's, else none); sets entity.model_file,
  // skin and anim_file (from the `anim` value, a modelDef anim name or an .md5anim path). Warnings are
  // prefixed by `where`. -1 when the name is neither a modelDef nor a file name with a model extension.
  int mesh_for(const std::string& model, std::string skin, const std::string& anim, Entity& entity,
               const std::string& where);

 private:
  struct Loaded {
    int mesh = -1;
    std::string error;   // non-empty: the mesh is the placeholder box
    std::shared_ptr<const Md5Anim> anim;   // the md5anim, when it fits the mesh
  };
  Loaded load(const std::string& file, const std::string& skin, const std::string& anim_file, const std::string& where);

  const Vfs& vfs_;
  Scene& scene_;
  DeclLibrary& decls_;
  LoadReport& report_;
  MaterialLookup material_;
  std::map<std::string, Loaded> loaded_;   // by "file|skin"
};

}  // namespace cohort::scene
