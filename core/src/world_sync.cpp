#include "cohort/core/world_sync.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <unordered_set>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "cohort/commit/array_diff.h"
#include "cohort/commit/host_skinning.h"
#include "cohort/core/bvh.h"
#include "cohort/core/light_sampling.h"
#include "cohort/core/view.h"
#include "gpu_scene_textures.h"
#include "skin_data.h"

namespace cohort::core {
namespace {

KMaterial default_material() {
  scene::Material m;
  m.name = "_default";
  m.diffuse_color = glm::vec4(0.5f, 0.5f, 0.5f, 1.0f);
  return to_kmaterial(m, scene::Scene{});
}

template <typename Handles>
std::set<int> live_handles(const Handles& defs) {
  std::set<int> live;
  for (size_t h = 0; h < defs.size(); ++h)
    if (defs[h]) live.insert(int(h));
  return live;
}

std::set<int> all_indices(size_t count) {
  std::set<int> indices;
  for (size_t i = 0; i < count; ++i) indices.insert(int(i));
  return indices;
}

}  // namespace

WorldSync::WorldSync(const scene::RenderWorld& world, WorldSyncOptions options) : world_(world), options_(options) {
  const scene::Scene& scene = world_.scene();
  base_material_count_ = static_cast<uint32_t>(scene.materials.size());
  next_material_slot_ = base_material_count_ + 1;
  blas_of_mesh_.assign(scene.meshes.size(), K_NONE);
  master_.materials.assign(size_t(base_material_count_) + 1, KMaterial{});
  master_.materials[base_material_count_] = default_material();
  build_static_world();

  // Compiling is syncing from an empty world: everything the world holds counts as changed.
  scene::ChangeLog everything;
  everything.textures = all_indices(scene.images.size());
  everything.materials = all_indices(scene.materials.size());
  everything.entities = live_handles(world_.entity_defs());
  everything.lights = live_handles(world_.light_defs());
  everything.view = world_.view().has_value();
  sync(everything, 0);
  if (!world_.view())
    master_.camera = make_camera(player_eye(scene), ViewAngles{scene.player_yaw, 0.0f}, kDefaultFovX,
                                 int(options_.width), int(options_.height));
}

// One BLAS over every area of the map, built once; the world's single instance comes first.
void WorldSync::build_static_world() {
  const scene::Scene& scene = world_.scene();
  std::vector<KTriangle> triangles;
  for (int mesh_index : scene.area_meshes) {
    const scene::Mesh& mesh = scene.meshes.at(size_t(mesh_index));
    const uint32_t base = uint32_t(master_.vertices.size());
    append_vertex_colors(master_.vertex_colors, mesh);
    for (const scene::Vertex& v : mesh.vertices) master_.vertices.push_back(to_kvertex(v));
    std::vector<KTriangle> own = mesh_triangles(mesh, base, [this](int m) { return kmaterial_index(m); });
    triangles.insert(triangles.end(), own.begin(), own.end());
  }
  if (triangles.empty()) return;
  BlasBuild build = build_blas(master_.vertices, triangles);
  world_blas_ = uint32_t(master_.blases.size());
  master_.blases.push_back({uint32_t(master_.blas_nodes.size()), uint32_t(build.nodes.size()),
                            uint32_t(master_.triangles.size()), uint32_t(build.triangles.size())});
  master_.blas_nodes.insert(master_.blas_nodes.end(), build.nodes.begin(), build.nodes.end());
  master_.triangles.insert(master_.triangles.end(), build.triangles.begin(), build.triangles.end());
  for (int m : scene.area_meshes) blas_of_mesh_[size_t(m)] = world_blas_;

  KInstance world_instance{};
  set_instance_transform(world_instance, glm::vec3(0.0f), glm::mat3(1.0f));
  world_instance.blas = world_blas_;
  world_instance.mask = K_MASK_PRIMARY | K_MASK_SHADOW;
  world_instance.entity = K_NONE;
  world_instance.material_override = K_NONE;
  static_instances_.push_back(world_instance);
}

CompiledScene WorldSync::release() && {
  return CompiledScene{std::move(master_), std::move(blas_of_mesh_), world_blas_};
}

uint32_t WorldSync::blas_of_mesh(int mesh) const {
  return mesh >= 0 && size_t(mesh) < blas_of_mesh_.size() ? blas_of_mesh_[mesh] : K_NONE;
}

uint32_t WorldSync::kmaterial_index(int m) const {
  if (m < 0 || size_t(m) >= world_.scene().materials.size()) return base_material_count_;
  if (uint32_t(m) < base_material_count_) return uint32_t(m);
  auto [slot, added] = late_material_slots_.try_emplace(m, next_material_slot_);
  if (added) ++next_material_slot_;
  return slot->second;
}

uint32_t WorldSync::new_material_slot() {
  if (!free_material_slots_.empty()) {
    const uint32_t slot = free_material_slots_.back();
    free_material_slots_.pop_back();
    return slot;
  }
  return next_material_slot_++;
}

double WorldSync::material_time() const {
  if (time_override_) return *time_override_;
  return world_.view() ? world_.view()->time_ms * 0.001 : 0.0;
}

scene::RegisterInputs WorldSync::world_registers() const {
  scene::RegisterInputs r;   // parms as the engine gives world surfaces; globals as the game starts them
  r.time = float(material_time());
  return r;
}

uint32_t WorldSync::ensure_blas(int mesh, commit::CommitBuffer& out) {
  if (size_t(mesh) >= blas_of_mesh_.size()) blas_of_mesh_.resize(world_.scene().meshes.size(), K_NONE);
  if (size_t(mesh) >= blas_of_mesh_.size()) return K_NONE;
  if (blas_of_mesh_[mesh] == K_NONE) blas_of_mesh_[mesh] = build_mesh_blas(mesh, out);
  return blas_of_mesh_[mesh];
}

// A new BLAS slot at the end of the pools (a redefined model's old one stays until a full resync).
uint32_t WorldSync::build_mesh_blas(int mesh_index, commit::CommitBuffer& out, const std::map<int, uint32_t>* instance_slots) {
  const scene::Mesh& mesh = world_.scene().meshes.at(size_t(mesh_index));
  std::vector<KVertex> vertices;
  vertices.reserve(mesh.vertices.size());
  for (const scene::Vertex& v : mesh.vertices) vertices.push_back(to_kvertex(v));
  std::vector<KTriangle> triangles = mesh_triangles(mesh, 0, [this, instance_slots](int m) {
    if (instance_slots)
      if (auto slot = instance_slots->find(m); slot != instance_slots->end()) return slot->second;
    return kmaterial_index(m);
  });
  if (triangles.empty()) return K_NONE;
  BlasBuild build = build_blas(vertices, triangles);
  commit::BlasUpload up = append_blas(mesh, std::move(vertices), std::move(build), 0);
  uint32_t index = up.blas_index;
  out.add_blas(std::move(up));
  return index;
}

// A BLAS built on the mesh's own vertices, appended to the master pools (shared by every BLAS: its
// triangles are moved to its vertices' place there), with room for at least node_room nodes.
commit::BlasUpload WorldSync::append_blas(const scene::Mesh& mesh, std::vector<KVertex> vertices, BlasBuild build,
                                          size_t node_room) {
  commit::BlasUpload up;
  up.blas_index = uint32_t(master_.blases.size());
  up.vertex_offset = uint32_t(master_.vertices.size());
  up.triangle_offset = uint32_t(master_.triangles.size());
  up.node_offset = uint32_t(master_.blas_nodes.size());
  up.vertices = std::move(vertices);
  up.vertex_colors = mesh.colors;
  up.triangles = std::move(build.triangles);
  for (KTriangle& t : up.triangles) {
    t.v0 += up.vertex_offset;
    t.v1 += up.vertex_offset;
    t.v2 += up.vertex_offset;
  }
  up.blas = {up.node_offset, uint32_t(build.nodes.size()), up.triangle_offset, uint32_t(up.triangles.size())};
  up.nodes = std::move(build.nodes);
  up.nodes.resize(std::max(up.nodes.size(), node_room), KBvhNode{});
  append_vertex_colors(master_.vertex_colors, mesh);   // first: it throws for a mesh with colours missing
  master_.vertices.insert(master_.vertices.end(), up.vertices.begin(), up.vertices.end());
  master_.triangles.insert(master_.triangles.end(), up.triangles.begin(), up.triangles.end());
  master_.blas_nodes.insert(master_.blas_nodes.end(), up.nodes.begin(), up.nodes.end());
  master_.blases.push_back(up.blas);
  ++stats_.blas_builds;
  return up;
}

// New or redefined images: their texels (with mips, exactly as compile_scene makes them) are appended
// and the texture table is rebuilt. Returns true when the image count changed, which moves every
// light-image and falloff slot (texture_slot), so materials and lights must be converted again.
bool WorldSync::update_textures(const std::set<int>& changed, commit::CommitBuffer& out) {
  const scene::Scene& scene = world_.scene();
  const size_t before = image_textures_.size(), images = scene.images.size();
  image_textures_.resize(images);
  for (int i : changed) {
    scene::Scene one;
    one.images.push_back(scene.images.at(size_t(i)));
    commit::TracerScene compiled;
    compile_textures(one, compiled);
    commit::TexelUpload up;
    up.offset = uint32_t(master_.texels.size());
    up.texels = std::move(compiled.texels);
    for (uint32_t use = 0; use < kTextureUseCount; ++use) {
      KTexture t = compiled.textures.at(use);
      if (t.width != 0) t.offset += up.offset;
      image_textures_[size_t(i)][use] = t;
    }
    master_.texels.insert(master_.texels.end(), up.texels.begin(), up.texels.end());
    if (!up.texels.empty()) out.add_texels(std::move(up));
  }
  std::vector<KTexture> table(images * kTextureUseCount);
  for (size_t i = 0; i < images; ++i)
    for (uint32_t use = 0; use < kTextureUseCount; ++use) table[use * images + i] = image_textures_[i][use];
  commit::diff_textures(master_.textures, table, out);
  master_.textures = std::move(table);
  return images != before;
}

void WorldSync::set_material(int m) {
  const scene::Scene& scene = world_.scene();
  uint32_t index = kmaterial_index(m);
  if (master_.materials.size() <= index) master_.materials.resize(index + 1);
  const scene::Material& base = scene.materials.at(size_t(m));
  const bool animated = base.registers && (base.registers->depends & (scene::kDependsTime | scene::kDependsGlobals));
  auto listed = std::lower_bound(animated_materials_.begin(), animated_materials_.end(), m);
  const bool was_listed = listed != animated_materials_.end() && *listed == m;
  if (animated && !was_listed) animated_materials_.insert(listed, m);
  if (!animated && was_listed) animated_materials_.erase(listed);
  scene::Material evaluated;
  scene::evaluate_material(base, world_registers(), evaluated);
  master_.materials[index] = to_kmaterial(evaluated, scene);
}

namespace {

// The materials an entity draws with: its customShader, else its model's surfaces' materials.
std::set<int> entity_material_set(const scene::Scene& scene, const scene::RenderEntity& def) {
  std::set<int> used;
  if (def.custom_shader >= 0) {
    used.insert(def.custom_shader);
  } else if (def.model >= 0 && size_t(def.model) < scene.meshes.size()) {
    for (const scene::Surface& surface : scene.meshes[size_t(def.model)].surfaces) used.insert(surface.material);
  }
  return used;
}

const scene::MaterialRegisters* registers_of(const scene::Scene& scene, int m) {
  return m >= 0 && size_t(m) < scene.materials.size() ? scene.materials[size_t(m)].registers.get() : nullptr;
}

}  // namespace

bool WorldSync::needs_material_instances(const scene::RenderEntity& def) const {
  const scene::Scene& scene = world_.scene();
  const scene::RegisterInputs world_parms;
  for (int m : entity_material_set(scene, def)) {
    const scene::MaterialRegisters* r = registers_of(scene, m);
    if (!r || !(r->depends & scene::kDependsParms)) continue;
    for (int p = 0; p < scene::kMaterialParms; ++p)
      if ((r->parms_read >> p & 1u) && def.shader_parms[p] != world_parms.parms[p]) return true;
  }
  return false;
}

void WorldSync::update_entity_materials(int, const scene::RenderEntity& def, EntityMaterials& em) {
  const scene::Scene& scene = world_.scene();
  scene::RegisterInputs r = world_registers();
  std::copy(std::begin(def.shader_parms), std::end(def.shader_parms), r.parms);
  for (int m : entity_material_set(scene, def)) {
    const scene::MaterialRegisters* regs = registers_of(scene, m);
    if (!regs || !(regs->depends & scene::kDependsParms)) continue;
    auto [slot, added] = em.slots.try_emplace(m, 0u);
    if (added) slot->second = new_material_slot();
    if (master_.materials.size() <= slot->second) master_.materials.resize(slot->second + 1);
    scene::Material evaluated;
    scene::evaluate_material(scene.materials[size_t(m)], r, evaluated);
    master_.materials[slot->second] = to_kmaterial(evaluated, scene);
    ++stats_.materials_evaluated;
  }
}

void WorldSync::release_entity_materials(int handle) {
  auto it = entity_materials_.find(handle);
  if (it == entity_materials_.end()) return;
  for (const auto& [m, slot] : it->second.slots) free_material_slots_.push_back(slot);
  entity_materials_.erase(it);
}

uint32_t WorldSync::entity_blas(int handle, const scene::RenderEntity& def, uint32_t shared_blas,
                                commit::CommitBuffer& out) {
  if (!needs_material_instances(def)) {
    release_entity_materials(handle);
    return shared_blas;
  }
  EntityMaterials& em = entity_materials_[handle];
  if (em.mesh != def.model) {   // another model: its own set of instances
    for (const auto& [m, slot] : em.slots) free_material_slots_.push_back(slot);
    em = EntityMaterials{};
    em.mesh = def.model;
  }
  update_entity_materials(handle, def, em);
  if (def.custom_shader >= 0 || entity_material_set(world_.scene(), def).size() == 1) return shared_blas;
  if (em.own_blas == K_NONE) em.own_blas = build_mesh_blas(def.model, out, &em.slots);
  return em.own_blas == K_NONE ? shared_blas : em.own_blas;
}

// Every frame: animated materials at this frame's time, and entity instances of materials that read
// time or globals. The caller's diff sends only the KMaterials that changed.
bool WorldSync::evaluate_animated(commit::CommitBuffer&) {
  for (int m : std::vector<int>(animated_materials_)) {
    set_material(m);
    ++stats_.materials_evaluated;
  }
  const scene::Scene& scene = world_.scene();
  for (auto& [handle, em] : entity_materials_) {
    bool animated = false;
    for (const auto& [m, slot] : em.slots)
      if (const scene::MaterialRegisters* r = registers_of(scene, m))
        animated |= (r->depends & (scene::kDependsTime | scene::kDependsGlobals)) != 0;
    const scene::RenderEntity* def = world_.EntityDef(handle);
    if (animated && def) update_entity_materials(handle, *def, em);
  }
  return true;
}

KInstance WorldSync::entity_instance(int handle, const scene::RenderEntity& def, uint32_t blas) const {
  KInstance inst{};
  set_instance_transform(inst, def.origin, def.axis);
  inst.blas = blas;
  inst.mask = K_MASK_PRIMARY | (def.no_shadows ? 0u : K_MASK_SHADOW);
  inst.entity = uint32_t(handle);
  inst.material_override = def.custom_shader >= 0 ? kmaterial_index(def.custom_shader) : K_NONE;
  // A model drawn with one instanced material: the instance replaces it.
  auto em = entity_materials_.find(handle);
  if (em != entity_materials_.end() && em->second.own_blas == K_NONE && em->second.slots.size() == 1 && blas != K_NONE)
    inst.material_override = em->second.slots.begin()->second;
  return inst;
}

WorldSync::SkinnedEntity WorldSync::add_skinned_blas(int mesh_index, commit::CommitBuffer& out) {
  const scene::Mesh& mesh = world_.scene().meshes.at(size_t(mesh_index));
  SkinnedEntity entity;
  entity.mesh = mesh_index;
  std::vector<KVertex> vertices;
  vertices.reserve(mesh.vertices.size());
  for (const scene::Vertex& v : mesh.vertices) vertices.push_back(to_kvertex(v));
  std::vector<KTriangle> triangles = mesh_triangles(mesh, 0, [this](int m) { return kmaterial_index(m); });
  if (triangles.empty()) return entity;

  commit::SkinUpload skin_up;
  auto shared = skin_vertices_of_mesh_.find(mesh_index);
  if (shared == skin_vertices_of_mesh_.end()) {  // the mesh's weights and adjacency, once for all its characters
    MeshSkinData data = mesh_skin_data(mesh);
    skin_up.weight_offset = uint32_t(master_.skin_weights.size());
    skin_up.adjacency_offset = uint32_t(master_.skin_adjacency.size());
    for (KSkinVertex& v : data.vertices) {
      v.first_weight += skin_up.weight_offset;
      v.first_adjacent += skin_up.adjacency_offset;
    }
    shared = skin_vertices_of_mesh_
                 .emplace(mesh_index, SharedSkin{uint32_t(master_.skin_vertices.size()),
                                                 uint32_t(master_.skin_triangles.size()), uint32_t(data.triangles.size())})
                 .first;
    skin_up.vertices = std::move(data.vertices);
    skin_up.weights = std::move(data.weights);
    skin_up.triangles = std::move(data.triangles);
    skin_up.adjacency = std::move(data.adjacency);
    master_.skin_vertices.insert(master_.skin_vertices.end(), skin_up.vertices.begin(), skin_up.vertices.end());
    master_.skin_weights.insert(master_.skin_weights.end(), skin_up.weights.begin(), skin_up.weights.end());
    master_.skin_triangles.insert(master_.skin_triangles.end(), skin_up.triangles.begin(), skin_up.triangles.end());
    master_.skin_adjacency.insert(master_.skin_adjacency.end(), skin_up.adjacency.begin(), skin_up.adjacency.end());
  }

  BlasBuild build = build_blas(vertices, triangles);
  entity.built_sah = build.sah_cost;
  // Room for any binary tree over these triangles, so a rebuild after the refit decays stays in place.
  commit::BlasUpload up = append_blas(mesh, std::move(vertices), std::move(build), 2 * triangles.size() - 1);
  entity.blas = up.blas_index;

  skin_up.skin_index = uint32_t(master_.skins.size());
  const SharedSkin& shared_skin = shared->second;
  skin_up.skin = KSkin{entity.blas,
                       up.vertex_offset,
                       uint32_t(up.vertices.size()),
                       shared_skin.skin_vertex_offset,
                       uint32_t(master_.joints.size()),
                       uint32_t(mesh.skin->joint_count),
                       shared_skin.triangle_offset,
                       shared_skin.triangle_count,
                       uint32_t(master_.skin_faces.size()),
                       0u, 0u, 0u};
  master_.joints.resize(master_.joints.size() + size_t(mesh.skin->joint_count), KJoint{});
  master_.skin_faces.resize(master_.skin_faces.size() + shared_skin.triangle_count, KSkinFace{});
  master_.skins.push_back(skin_up.skin);
  entity.skin = skin_up.skin_index;
  out.add_blas(std::move(up));
  out.add_skin(std::move(skin_up));
  return entity;
}

// The refit tree has decayed: a new tree over the posed vertices, written in place of the old one (its
// node range has room for any tree), sent as a BLAS upload without vertices.
void WorldSync::rebuild_skinned_blas(SkinnedEntity& entity, commit::CommitBuffer& out) {
  KBlas blas = master_.blases[entity.blas];
  const std::vector<KTriangle> triangles(master_.triangles.begin() + blas.tri_offset,
                                         master_.triangles.begin() + blas.tri_offset + blas.tri_count);
  BlasBuild build = build_blas(master_.vertices, triangles);
  if (build.nodes.size() > 2 * size_t(blas.tri_count) - 1) throw std::logic_error("WorldSync: a BLAS outgrew its node range");
  blas.node_count = uint32_t(build.nodes.size());
  master_.blases[entity.blas] = blas;
  std::copy(build.nodes.begin(), build.nodes.end(), master_.blas_nodes.begin() + blas.node_offset);
  std::copy(build.triangles.begin(), build.triangles.end(), master_.triangles.begin() + blas.tri_offset);
  commit::skin_on_host(master_, entity.skin);  // the refit every tracer does after this upload
  entity.built_sah = sah_cost(std::vector<KBvhNode>(master_.blas_nodes.begin() + blas.node_offset,
                                                    master_.blas_nodes.begin() + blas.node_offset + blas.node_count));
  commit::BlasUpload up;
  up.blas_index = entity.blas;
  up.blas = blas;
  up.vertex_offset = master_.skins[entity.skin].vertex_offset;
  up.triangle_offset = blas.tri_offset;
  up.triangles = std::move(build.triangles);
  up.node_offset = blas.node_offset;
  up.nodes = std::move(build.nodes);
  out.add_blas(std::move(up));
  ++stats_.blas_builds;
  ++stats_.skin_rebuilds;
}

uint32_t WorldSync::pose_skinned_entity(int handle, const scene::RenderEntity& def, commit::CommitBuffer& out) {
  constexpr float kSkinRebuildThreshold = 1.5f;
  const scene::Mesh& mesh = world_.scene().meshes.at(size_t(def.model));
  if (def.joints.size() != size_t(mesh.skin->joint_count)) {
    if (warned_joint_counts_.insert(handle).second)
      spdlog::warn("WorldSync: entity {} has {} joints for model '{}' of {}; not drawn", handle, def.joints.size(),
                   mesh.name, mesh.skin->joint_count);
    skinned_.erase(handle);
    return K_NONE;
  }
  auto it = skinned_.find(handle);
  if (it == skinned_.end() || it->second.mesh != def.model)
    it = skinned_.insert_or_assign(handle, add_skinned_blas(def.model, out)).first;
  SkinnedEntity& entity = it->second;
  if (entity.blas == K_NONE) return K_NONE;
  const KSkin skin = master_.skins[entity.skin];
  std::vector<KJoint> joints = to_kjoints(def.joints);
  KJoint* current = master_.joints.data() + skin.joint_offset;
  if (entity.posed && std::memcmp(current, joints.data(), joints.size() * sizeof(KJoint)) == 0) return entity.blas;
  std::copy(joints.begin(), joints.end(), current);
  commit::skin_on_host(master_, entity.skin);
  out.set_skin_joints(entity.skin, std::move(joints));
  entity.posed = true;
  ++stats_.skins_posed;
  const KBlas& blas = master_.blases[entity.blas];
  const float refit_sah = sah_cost(std::vector<KBvhNode>(master_.blas_nodes.begin() + blas.node_offset,
                                                         master_.blas_nodes.begin() + blas.node_offset + blas.node_count));
  if (blas_needs_rebuild(entity.built_sah, refit_sah, kSkinRebuildThreshold)) rebuild_skinned_blas(entity, out);
  return entity.blas;
}

bool WorldSync::refit_moved_instances(const std::vector<int>& moved, commit::CommitBuffer& out) {
  constexpr float kTlasRebuildThreshold = 1.3f;  // a rebuild costs ~0.3 ms per 1,000 instances (docs/bvh.md)
  std::unordered_map<uint32_t, size_t> slot_of_entity;
  for (size_t i = 0; i < master_.instances.size(); ++i)
    if (master_.instances[i].entity != K_NONE) slot_of_entity[master_.instances[i].entity] = i;
  std::vector<KInstance> instances = master_.instances;
  for (int handle : moved) {
    const auto slot = slot_of_entity.find(uint32_t(handle));
    if (slot == slot_of_entity.end()) return false;
    instances[slot->second] = entity_instances_.at(handle);
  }
  std::vector<KBvhNode> tlas = master_.tlas_nodes;
  if (blas_needs_rebuild(tlas_built_sah_, refit_scene_tlas(instances, master_, tlas), kTlasRebuildThreshold)) return false;
  commit::diff_instances(master_.instances, instances, out);
  commit::diff_tlas(master_.tlas_nodes, tlas, out);
  master_.instances = std::move(instances);
  master_.tlas_nodes = std::move(tlas);
  stats_.tlas_refit = true;
  return true;
}

commit::CommitBuffer WorldSync::sync(const scene::ChangeLog& changes, uint64_t frame) {
  const auto start = std::chrono::steady_clock::now();
  const scene::Scene& scene = world_.scene();
  stats_ = {};
  stats_.frame = frame;
  commit::CommitBuffer out;
  out.set_frame(frame);

  bool slots_moved = false;
  if (!changes.textures.empty()) slots_moved = update_textures(changes.textures, out);

  // Materials: new ones go after the default material; all of them again when texture slots moved.
  const std::vector<KMaterial> materials_before = master_.materials;
  if (slots_moved) {
    for (size_t m = 0; m < scene.materials.size(); ++m) set_material(int(m));
  } else {
    for (int m : changes.materials) set_material(m);
  }
  evaluate_animated(out);

  // Redefined models in use get a new BLAS; their entities are re-instanced below.
  std::set<int> entities = changes.entities;
  for (int mesh : changes.models) {
    if (size_t(mesh) >= blas_of_mesh_.size() || blas_of_mesh_[mesh] == K_NONE) continue;
    if (std::find(scene.area_meshes.begin(), scene.area_meshes.end(), mesh) != scene.area_meshes.end()) {
      spdlog::warn("WorldSync: area mesh {} was redefined; the static world BLAS is not rebuilt", mesh);
      continue;
    }
    blas_of_mesh_[mesh] = K_NONE;
    skin_vertices_of_mesh_.erase(mesh);
    for (const auto& [handle, m] : mesh_of_entity_)
      if (m == mesh) entities.insert(handle), skinned_.erase(handle);
  }

  bool instances_changed = instances_stale_;
  // While the same instances keep their BLASes and only move, the TLAS is refit instead of rebuilt.
  bool only_moved = !instances_stale_;
  std::vector<int> moved;
  for (int handle : changes.freed_entities) {
    release_entity_materials(handle);
    const bool erased = entity_instances_.erase(handle) > 0;
    instances_changed |= erased;
    only_moved &= !erased;
    mesh_of_entity_.erase(handle);
    skinned_.erase(handle);
  }
  for (int handle : entities) {
    const scene::RenderEntity* def = world_.EntityDef(handle);
    const bool skinned = def && def->model >= 0 && !def->joints.empty() && scene.meshes.at(size_t(def->model)).skin;
    if (!skinned) skinned_.erase(handle);
    uint32_t blas = skinned ? pose_skinned_entity(handle, *def, out)
                            : def && def->model >= 0 ? ensure_blas(def->model, out) : K_NONE;
    if (def && blas != K_NONE && !skinned) {
      blas = entity_blas(handle, *def, blas, out);
    } else {
      release_entity_materials(handle);
    }
    if (blas == K_NONE) {  // freed, no model, or a model without triangles
      const bool erased = entity_instances_.erase(handle) > 0;
      instances_changed |= erased;
      only_moved &= !erased;
      mesh_of_entity_.erase(handle);
      continue;
    }
    const auto existing = entity_instances_.find(handle);
    if (existing == entity_instances_.end() || existing->second.blas != blas) only_moved = false;
    moved.push_back(handle);
    entity_instances_[handle] = entity_instance(handle, *def, blas);
    mesh_of_entity_[handle] = def->model;
    instances_changed = true;
  }
  bool emitters_moved = false;  // a refit moved instances whose triangles emit: their world positions change
  if (instances_changed && only_moved && !master_.tlas_nodes.empty() && refit_moved_instances(moved, out)) {
    instances_changed = false;
    const std::unordered_set<int> moved_handles(moved.begin(), moved.end());
    for (const KEmissiveTriangle& e : master_.emissive_triangles) {
      const kuint entity = master_.instances[e.instance].entity;
      if (entity != K_NONE && moved_handles.count(int(entity))) {
        emitters_moved = true;
        break;
      }
    }
  }
  // After the entities: their material instances were brought to their parms above.
  commit::diff_materials(materials_before, master_.materials, out);
  const bool materials_changed = materials_before.size() != master_.materials.size() ||
                                 std::memcmp(materials_before.data(), master_.materials.data(),
                                             materials_before.size() * sizeof(KMaterial)) != 0;

  if (instances_changed) {
    std::vector<KInstance> instances = static_instances_;
    instances.reserve(static_instances_.size() + entity_instances_.size());
    for (const auto& [handle, inst] : entity_instances_) instances.push_back(inst);
    std::vector<KBvhNode> tlas = build_scene_tlas(instances, master_);
    commit::diff_instances(master_.instances, instances, out);
    commit::diff_tlas(master_.tlas_nodes, tlas, out);
    master_.instances = std::move(instances);
    master_.tlas_nodes = std::move(tlas);
    tlas_built_sah_ = sah_cost(master_.tlas_nodes);
    stats_.tlas_rebuilt = true;
    instances_stale_ = false;
  }

  // Lights, in handle order of the live defs.
  bool light_sources_changed = false;
  if (slots_moved || !changes.lights.empty() || !changes.freed_lights.empty() || !animated_lights_.empty()) {
    for (int handle : changes.freed_lights) lights_by_handle_.erase(handle), animated_lights_.erase(handle);
    auto convert = [&](int handle) {
      lights_by_handle_.erase(handle);
      if (!world_.LightDef(handle)) return;
      const scene::Light light = world_.scene_light(handle);
      if (std::optional<std::string> defect = light_defect(light, scene, options_.gpu)) {
        warn_bad_light(handle, light, *defect);
        return;
      }
      lights_by_handle_[handle] = to_klight_at_time(handle, light);
    };
    if (slots_moved) {
      for (size_t h = 0; h < world_.light_defs().size(); ++h) convert(int(h));
    } else {
      std::set<int> handles = changes.lights;
      handles.insert(animated_lights_.begin(), animated_lights_.end());
      for (int handle : handles) convert(handle);
    }
    std::vector<KLight> lights;
    lights.reserve(lights_by_handle_.size());
    for (const auto& [handle, light] : lights_by_handle_) lights.push_back(light);
    light_sources_changed = lights.size() != master_.lights.size() ||
                            std::memcmp(lights.data(), master_.lights.data(), lights.size() * sizeof(KLight)) != 0;
    commit::diff_lights(master_.lights, lights, out);
    master_.lights = std::move(lights);
  }

  // Emissive triangles move with their instances and appear or go with materials; the light node array
  // holds the trees over both kinds of source, so either change rebuilds it.
  if (light_sources_changed || instances_changed || emitters_moved || slots_moved || materials_changed) {
    EmissiveList emissive = list_emissive_triangles(master_);
    std::vector<KLightNode> nodes = build_light_nodes(master_.lights, emissive);
    commit::diff_light_tree(master_.light_nodes, nodes, out);
    commit::diff_emissive_triangles(master_.emissive_triangles, emissive.triangles, out);
    master_.light_nodes = std::move(nodes);
    master_.emissive_triangles = std::move(emissive.triangles);
  }

  if (changes.view && world_.view()) {
    master_.camera = make_camera(*world_.view(), int(options_.width), int(options_.height));
    out.set_camera(master_.camera);
  }
  master_.version = frame;
  stats_.record_bytes = out.bytes();
  stats_.records = out.record_count();
  stats_.sync_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  snapshot_.reset();
  return out;
}

// The light with its shader's stage colour evaluated at this frame's time with the light's parms
// (parm0-2 = 1: to_klight multiplies by _color itself); remembered as animated when that reads time.
KLight WorldSync::to_klight_at_time(int handle, const scene::Light& light) {
  const scene::Scene& scene = world_.scene();
  int material = light.material;
  if (material < 0)
    material = scene.find_material(light.type == scene::LightType::Projected ? "lights/defaultProjectedLight"
                                                                              : "lights/defaultPointLight");
  const scene::MaterialRegisters* regs = registers_of(scene, material);
  if (!regs || !regs->light) {
    animated_lights_.erase(handle);
    return to_klight(light, scene, options_.gpu);
  }
  if (regs->depends & (scene::kDependsTime | scene::kDependsGlobals)) {
    animated_lights_.insert(handle);
    ++stats_.lights_animated;
  } else {
    animated_lights_.erase(handle);
  }
  scene::RegisterInputs r = world_registers();
  std::copy(std::begin(light.shader_parms), std::end(light.shader_parms), r.parms);
  r.parms[0] = r.parms[1] = r.parms[2] = 1.0f;
  scene::Material evaluated;
  scene::evaluate_material(scene.materials[size_t(material)], r, evaluated);
  return to_klight(light, scene, options_.gpu, &evaluated.light_stage_color);
}

// Once per light def and defect, so a bad light that the game keeps updating does not flood the log.
void WorldSync::warn_bad_light(int handle, const scene::Light& light, const std::string& defect) {
  const std::string key = std::to_string(handle) + " " + defect;
  if (!warned_lights_.insert(key).second) return;
  const scene::Scene& scene = world_.scene();
  std::string where = light.source;
  if (where.empty() && size_t(handle) < scene.lights.size() && scene.lights[size_t(handle)].name == light.name)
    where = scene.lights[size_t(handle)].source;
  spdlog::warn("{}light '{}' (map '{}') skipped: {}", where.empty() ? "" : where + ": ", light.name, scene.name,
               defect);
  ++stats_.lights_skipped;
}

std::shared_ptr<const commit::TracerScene> WorldSync::snapshot() {
  if (!snapshot_) snapshot_ = std::make_shared<const commit::TracerScene>(master_);
  return snapshot_;
}

}  // namespace cohort::core
