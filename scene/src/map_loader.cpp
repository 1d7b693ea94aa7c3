#include "cohort/scene/map_loader.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <tuple>

#include "cohort/scene/decl_file.h"
#include "cohort/scene/image_library.h"
#include "cohort/scene/map_entities.h"
#include "cohort/scene/map_file.h"
#include "cohort/scene/material_build.h"
#include "cohort/scene/material_file.h"
#include "cohort/scene/proc_file.h"
#include "ascii_case.h"
#include "entity_models.h"

namespace cohort::scene {

namespace fs = std::filesystem;

namespace {

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

std::string read_disk_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path.string() + ": cannot read");
  std::ostringstream out;
  out << in.rdbuf();
  return out.str();
}

struct MapSource {
  std::string map_text, proc_text, map_where, proc_where, name;
};

MapSource find_map(Vfs& vfs, const std::string& map) {
  MapSource src;
  std::error_code ec;
  fs::path disk(map);
  if (ends_with(lowercase(map), ".map") && fs::is_regular_file(disk, ec)) {
    fs::path folder = fs::absolute(disk, ec).parent_path();
    if (lowercase(folder.filename().string()) == "maps") {
      fs::path base = folder.parent_path();
      bool known = std::any_of(vfs.search_paths().begin(), vfs.search_paths().end(),
                               [&](const fs::path& p) { return fs::equivalent(p, base, ec); });
      if (!known) vfs.add_search_path(base);
    }
    src.name = disk.stem().string();
    src.map_where = disk.string();
    src.map_text = read_disk_file(disk);
    fs::path proc = disk;
    proc.replace_extension(".proc");
    if (!fs::is_regular_file(proc, ec))
      throw std::runtime_error(proc.string() + ": no .proc beside the map (compile it with dmap)");
    src.proc_where = proc.string();
    src.proc_text = read_disk_file(proc);
    return src;
  }
  std::string game_path = Vfs::normalize(map);
  if (game_path.rfind("maps/", 0) != 0) game_path = "maps/" + game_path;
  if (!ends_with(game_path, ".map")) game_path += ".map";
  auto text = vfs.read(game_path);
  if (!text) {
    std::string searched;
    for (const auto& p : vfs.search_paths()) searched += (searched.empty() ? "" : ", ") + p.string();
    throw std::runtime_error("map '" + map + "' not found as a file nor as " + game_path + " in [" + searched + "]");
  }
  src.name = fs::path(game_path).stem().string();
  src.map_where = vfs.describe(game_path);
  src.map_text = std::move(*text);
  std::string proc_path = game_path.substr(0, game_path.size() - 4) + ".proc";
  auto proc = vfs.read(proc_path);
  if (!proc) throw std::runtime_error(proc_path + ": no .proc beside the map (compile it with dmap)");
  src.proc_where = vfs.describe(proc_path);
  src.proc_text = std::move(*proc);
  return src;
}

class SceneBuilder {
 public:
  SceneBuilder(Vfs& vfs, Scene& scene, LoadReport& report)
      : scene_(scene), report_(report), images_(vfs, scene.images, scene.warnings) {}

  void read_materials(Vfs& vfs) {
    for (const std::string& file : vfs.list("materials", ".mtr")) {
      auto text = vfs.read(file);
      if (!text) continue;
      MaterialFile parsed = parse_materials(*text, vfs.describe(file), tables_);
      ++report_.material_files;
      for (auto& w : parsed.warnings) scene_.warnings.push_back(std::move(w));
      for (auto& decl : parsed.materials) {
        ++report_.materials_declared;
        std::string key = lowercase(decl.name);
        auto existing = decls_.find(key);
        if (existing != decls_.end()) {
          scene_.warnings.push_back(decl.file + ":" + std::to_string(decl.line) + ": material " + decl.name +
                                    " already defined at " + existing->second.file + ":" +
                                    std::to_string(existing->second.line) + "; the first is kept");
          continue;
        }
        decls_.emplace(std::move(key), std::move(decl));
      }
    }
  }

  int material(const std::string& name, bool as_light) {
    std::string key = lowercase(name) + (as_light ? "#light" : "");
    auto found = used_.find(key);
    if (found != used_.end()) return found->second;
    auto decl = decls_.find(lowercase(name));
    Material m;
    if (decl != decls_.end()) {
      m = build_material(decl->second, images_, as_light);
    } else {
      ++report_.materials_missing;
      scene_.warnings.push_back("material '" + name + "' is not defined in any materials/*.mtr; " +
                                (images_.can_find(name) ? "using the image of that name" : "using a checker"));
      m = default_material(name, images_);
    }
    int index = static_cast<int>(scene_.materials.size());
    scene_.materials.push_back(std::move(m));
    used_[key] = index;
    return index;
  }

  // def/*.def (entityDefs, modelDefs, skins inside) and skins/*.skin, in sorted order: the first
  // definition of a name wins.
  void read_decls(Vfs& vfs) {
    for (const auto& [folder, extension, type] :
         {std::tuple{"def", ".def", "entityDef"}, std::tuple{"skins", ".skin", "skin"}}) {
      for (const std::string& file : vfs.list(folder, extension)) {
        auto text = vfs.read(file);
        if (!text) continue;
        decls_lib_.add(parse_decls(*text, vfs.describe(file), type), scene_.warnings);
        ++report_.def_files;
      }
    }
    report_.entity_defs = static_cast<int>(decls_lib_.entity_def_count());
    report_.model_defs = static_cast<int>(decls_lib_.model_def_count());
    report_.skins = static_cast<int>(decls_lib_.skin_count());
  }

  void add_proc(ProcFile& proc) {
    std::vector<std::pair<int, int>> areas;  // area number, mesh index
    for (ProcModel& model : proc.models) {
      for (size_t s = 0; s < model.mesh.surfaces.size(); ++s)
        model.mesh.surfaces[s].material = material(model.surface_materials[s], false);
      int index = static_cast<int>(scene_.meshes.size());
      if (model.area >= 0) {
        areas.emplace_back(model.area, index);
        report_.world_triangles += model.mesh.triangle_count();
      } else {
        ++report_.inline_models;
      }
      scene_.meshes.push_back(std::move(model.mesh));
    }
    proc_mesh_count_ = static_cast<int>(scene_.meshes.size());
    std::sort(areas.begin(), areas.end());
    for (size_t i = 0; i < areas.size(); ++i) {
      if (areas[i].first != static_cast<int>(i))
        scene_.warnings.push_back("the .proc has no model for area " + std::to_string(i) +
                                  "; Scene::area_meshes is in area order without it");
      scene_.area_meshes.push_back(areas[i].second);
    }
    report_.areas = proc.area_count;
    report_.portals = static_cast<int>(proc.portals.size());
    report_.nodes = static_cast<int>(proc.nodes.size());
    report_.shadow_models_skipped = proc.shadow_models_skipped;
    scene_.portals = std::move(proc.portals);
    scene_.nodes = std::move(proc.nodes);
  }

  void add_entities(const MapFile& map, const std::string& map_where, const Vfs& vfs) {
    EntityModels models(vfs, scene_, decls_lib_, report_, [this](const std::string& name) { return material(name, false); });
    for (const std::string& w : map.warnings) scene_.warnings.push_back(w);
    for (size_t index = 0; index < map.entities.size(); ++index) {
      const std::string where = map_where + ":" + std::to_string(map.entities[index].line);
      const std::string classname = map.entities[index].classname();
      if (classname == "worldspawn") continue;
      // The map's keys, then the entityDef's for the keys the map lacks (SetDefaults).
      MapEntity e = map.entities[index];
      bool light_class = is_light_entity(e);
      if (const ResolvedEntityDef* def = classname.empty() ? nullptr : decls_lib_.entity_def(classname, scene_.warnings)) {
        for (const auto& [key, value] : def->keys)
          if (!e.get(key)) e.keys.emplace_back(key, value);
        light_class = light_class || def->ancestors.count("light") > 0;
      } else {
        ++report_.unresolved_classes[classname.empty() ? "(no classname)" : classname];
      }
      if (light_class) {
        MapLight light = light_from_entity(e, where, scene_.warnings);
        if (light.light.name.empty()) light.light.name = "light_" + std::to_string(index);  // as the engine names them
        light.light.source = where;
        if (!light.texture.empty()) light.light.material = material(light.texture, true);
        switch (light.light.type) {
          case LightType::Point: ++report_.lights_point; break;
          case LightType::Projected: ++report_.lights_projected; break;
          case LightType::Parallel: ++report_.lights_parallel; break;
        }
        if (auto model = e.get("model")) add_light_model(e, light.light, *model, where, models);
        scene_.lights.push_back(std::move(light.light));
        continue;
      }
      Entity entity = entity_from_map(e, where, scene_.warnings);
      if (entity.name.empty()) entity.name = (classname.empty() ? "entity" : classname) + "_" + std::to_string(index);
      if (classname == "info_player_start") {
        scene_.player_start = entity.origin;
        auto angle = e.get("angle");
        auto yaw = angle ? parse_floats(*angle, 1) : std::nullopt;
        scene_.player_yaw = yaw ? (*yaw)[0] : 0.0f;
      }
      auto model = e.get("model");
      if (model) entity.mesh = find_inline_model(*model);
      if (entity.mesh < 0 && !entity.name.empty() && (!model || *model == entity.name))
        entity.mesh = find_inline_model(entity.name);
      if (entity.mesh < 0 && model)
        entity.mesh = models.mesh_for(*model, e.get_or("skin", ""), e.get_or("anim", ""), entity, where);
      if (entity.mesh < 0 && model) {
        scene_.warnings.push_back(where + ": entity " + entity.name + ": model '" + *model +
                                  "' is no inline model of the .proc, modelDef or model file (.ase, .lwo, .md5mesh)");
        ++report_.unresolved_models[*model];
      }
      if (entity.mesh >= 0) report_.entity_triangles += scene_.meshes[static_cast<size_t>(entity.mesh)].triangle_count();
      ++report_.entities_by_class[classname.empty() ? "(no classname)" : classname];
      scene_.entities.push_back(std::move(entity));
    }
  }

  // A light's `model` is its visible fixture (Light.cpp Spawn); Cohort shows it as an entity of its own
  // at the light's place.
  void add_light_model(const MapEntity& e, const Light& light, const std::string& model, const std::string& where,
                       EntityModels& models) {
    Entity fixture;
    fixture.name = light.name + "_model";
    fixture.classname = e.classname();
    fixture.origin = light.origin;
    fixture.axis = light.axis;
    for (const auto& [key, value] : e.keys) fixture.keys[key] = value;
    fixture.mesh = find_inline_model(model);
    if (fixture.mesh < 0) fixture.mesh = models.mesh_for(model, e.get_or("skin", ""), "", fixture, where);
    if (fixture.mesh < 0) {
      scene_.warnings.push_back(where + ": light " + light.name + ": model '" + model +
                                "' is no inline model, modelDef or model file; the light has no fixture");
      ++report_.unresolved_models[model];
      return;
    }
    scene_.warnings.push_back(where + ": light " + light.name + " has a model ('" + model +
                              "'): shown as entity " + fixture.name + " (its materials do not follow the light's parms)");
    report_.entity_triangles += scene_.meshes[static_cast<size_t>(fixture.mesh)].triangle_count();
    ++report_.entities_by_class["(light model)"];
    scene_.entities.push_back(std::move(fixture));
  }

  // A .proc model by name (the meshes the model files add later are found by EntityModels).
  int find_inline_model(const std::string& name) const {
    int mesh = scene_.find_mesh(name);
    return mesh >= 0 && mesh < proc_mesh_count_ ? mesh : -1;
  }

  void finish() {
    report_.materials_used = static_cast<int>(scene_.materials.size());
    report_.images_loaded = images_.loaded_count();
    report_.images_placeholder = images_.placeholder_count();
    for (const Material& m : scene_.materials) {
      report_.emitters += m.emitter ? 1 : 0;
      report_.emitting_surfaces += m.emitter && m.blend == BlendClass::Opaque ? 1 : 0;
      report_.skies += m.blend == BlendClass::Sky ? 1 : 0;
      report_.environment_maps += m.environment_cube_image >= 0 ? 1 : 0;
      report_.no_self_shadow += m.no_self_shadow ? 1 : 0;
    }
  }

 private:
  Scene& scene_;
  LoadReport& report_;
  ImageLibrary images_;
  MaterialTables tables_;
  std::map<std::string, MaterialDecl> decls_;
  std::map<std::string, int> used_;
  DeclLibrary decls_lib_;
  int proc_mesh_count_ = 0;
};

}  // namespace

Scene load_map(Vfs& vfs, const std::string& map, LoadReport* report_out) {
  MapSource src = find_map(vfs, map);
  LoadReport report;
  report.map_file = src.map_where;
  report.proc_file = src.proc_where;
  MapFile parsed_map = parse_map(src.map_text, src.map_where);
  ProcFile proc = parse_proc(src.proc_text, src.proc_where);

  Scene scene;
  scene.name = src.name;
  SceneBuilder builder(vfs, scene, report);
  builder.read_materials(vfs);
  builder.read_decls(vfs);
  builder.add_proc(proc);
  builder.add_entities(parsed_map, src.map_where, vfs);
  builder.finish();
  report.warnings = scene.warnings;
  if (report_out) *report_out = std::move(report);
  return scene;
}

}  // namespace cohort::scene
