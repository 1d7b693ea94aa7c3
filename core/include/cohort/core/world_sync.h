// The one path from the scene model to the tracers' scene. WorldSync keeps the core's master
// TracerScene: built from an empty world by a first sync over everything the world holds (that is
// compile_scene), then updated once a frame from RenderWorld's change log (instance transforms, new
// BLASes, the TLAS, lights, materials, textures, camera), producing the frame's commit records, which
// it folds into every tracer's pending commit buffer.
//
// Index conventions: entity handle = KInstance::entity; instances are the static world then the entity
// defs in handle order; lights are the live light defs in handle order; textures use texture_slot().
// The default material sits right after the map's materials; materials defined later and entity
// material instances (below) go after it in the order they appear, so no triangle's material index ever
// moves (kmaterial_index()).
//
// Animated materials (docs/materials.md): every sync evaluates the materials whose registers read time or
// globals at the view's time (RenderView::time_ms, or set_time()), with the world's parms (parm0-3 = 1);
// diff_materials then sends only those whose KMaterial changed, so a constant material is never re-sent.
// An entity whose parms differ from the world's and whose model (or customShader) uses a material that
// reads parms gets its own evaluated copy of that material (a material instance, one KMaterial slot per
// entity and material, reused when its parms change): through KInstance::material_override when the
// model draws one material, else through its own BLAS with the instance slots in its triangles. Lights
// whose shader's stage colour reads time (flicker tables) are converted again every frame.
//
// Replaying a recorded stream (`cohort render --replay FILE`), per frame:
//   scene::Player player(file);                       // player.header().map_name names the map to load
//   scene::RenderWorld world(load the map);
//   WorldSync sync(world, options);
//   while (player.play_frame(world)) {
//     renderer.submit_commit(sync.sync(world.TakeChanges(), frame), [&] { return sync.snapshot(); });
//     (the Renderer hands the records to every tracer through its commit channel)
//     render with sync.master().camera ...
//   }
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "cohort/commit/commit_buffer.h"
#include "cohort/core/bvh.h"
#include "cohort/core/frame_defaults.h"
#include "cohort/core/gpu_scene.h"
#include "cohort/scene/material_registers.h"
#include "cohort/scene/render_world.h"

namespace cohort::core {

struct WorldSyncOptions {
  GpuSceneOptions gpu;
  uint32_t width = kDefaultWidth, height = kDefaultHeight;  // written into KCamera
};

struct WorldSyncStats {  // of the last sync()
  uint64_t frame = 0;
  size_t record_bytes = 0, records = 0;
  uint32_t blas_builds = 0;
  uint32_t skins_posed = 0;     // skinned characters whose joints changed (skinned and refit here too)
  uint32_t skin_rebuilds = 0;   // of those, BLASes rebuilt because the refit tree had decayed
  bool tlas_rebuilt = false;
  bool tlas_refit = false;      // only instance transforms changed: the TLAS was refit, not rebuilt
  uint32_t lights_skipped = 0;  // lights left out for a defect (light_defect), warned once each
  uint32_t materials_evaluated = 0;  // animated materials and entity material instances evaluated
  uint32_t lights_animated = 0;      // lights converted again for an animated shader
  double sync_ms = 0.0;
};

class WorldSync {
 public:
  // Compiles the world as it stands (its pending change log is left for the caller to take). The
  // world must outlive this object.
  explicit WorldSync(const scene::RenderWorld& world, WorldSyncOptions options = {});

  // Fold the world's changes (world.TakeChanges()) into the master; returns the frame's records.
  commit::CommitBuffer sync(const scene::ChangeLog& changes, uint64_t frame);
  const commit::TracerScene& master() const { return master_; }
  // An immutable copy of the master, shared by every full resync of the same frame.
  std::shared_ptr<const commit::TracerScene> snapshot();
  const WorldSyncStats& last_stats() const { return stats_; }

  uint32_t blas_of_mesh(int mesh) const;
  uint32_t world_blas() const { return world_blas_; }
  // The master with its mesh-to-BLAS map, moved out: what compile_scene returns.
  CompiledScene release() &&;
  // KMaterial index of scene material m (see above); the default material for -1.
  uint32_t kmaterial_index(int scene_material) const;
  // Material registers' time in seconds from now on, instead of the view's time_ms (headless renders
  // without a view). The next sync evaluates animated materials at it.
  void set_time(double seconds) { time_override_ = seconds; }
  double material_time() const;

 private:
  uint32_t ensure_blas(int mesh, commit::CommitBuffer& out);
  // The moved entities' instances updated in place and the TLAS refit; false (nothing changed) when
  // the refit tree has decayed past the rebuild threshold.
  bool refit_moved_instances(const std::vector<int>& moved, commit::CommitBuffer& out);
  uint32_t build_mesh_blas(int mesh, commit::CommitBuffer& out, const std::map<int, uint32_t>* instance_slots = nullptr);
  commit::BlasUpload append_blas(const scene::Mesh& mesh, std::vector<KVertex> vertices, BlasBuild build, size_t node_room);
  // A character drawn with a skinned mesh and joints: its own BLAS (its own vertices), posed by its
  // joints. Returns the BLAS, or K_NONE when the joints do not fit the skin (not drawn, as in the engine).
  uint32_t pose_skinned_entity(int handle, const scene::RenderEntity& def, commit::CommitBuffer& out);
  struct SkinnedEntity {
    int mesh = -1;
    uint32_t skin = K_NONE, blas = K_NONE;
    float built_sah = 0.0f;
    bool posed = false;
  };
  SkinnedEntity add_skinned_blas(int mesh, commit::CommitBuffer& out);
  void rebuild_skinned_blas(SkinnedEntity& entity, commit::CommitBuffer& out);
  bool update_textures(const std::set<int>& changed, commit::CommitBuffer& out);
  void set_material(int scene_material);
  scene::RegisterInputs world_registers() const;
  // The entity's material instances brought to its parms and this frame's time; returns the material
  // override and whether it needs a BLAS of its own (several instanced materials on one model).
  struct EntityMaterials {
    std::map<int, uint32_t> slots;   // scene material -> its KMaterial instance slot
    int mesh = -1;
    uint32_t own_blas = K_NONE;      // the model with the instance slots in its triangles
  };
  bool needs_material_instances(const scene::RenderEntity& def) const;
  void update_entity_materials(int handle, const scene::RenderEntity& def, EntityMaterials& em);
  uint32_t entity_blas(int handle, const scene::RenderEntity& def, uint32_t shared_blas, commit::CommitBuffer& out);
  void release_entity_materials(int handle);
  uint32_t new_material_slot();
  bool evaluate_animated(commit::CommitBuffer& out);
  void build_static_world();
  KInstance entity_instance(int handle, const scene::RenderEntity& def, uint32_t blas) const;
  KLight to_klight_at_time(int handle, const scene::Light& light);
  void warn_bad_light(int handle, const scene::Light& light, const std::string& defect);

  const scene::RenderWorld& world_;
  WorldSyncOptions options_;
  commit::TracerScene master_;
  std::vector<uint32_t> blas_of_mesh_;
  uint32_t world_blas_ = K_NONE;
  bool instances_stale_ = true;                   // until the first sync lists the static world
  float tlas_built_sah_ = 0.0f;                   // the TLAS's SAH when last rebuilt, to judge refits
  std::vector<KInstance> static_instances_;       // the world: entity == K_NONE
  std::map<int, KInstance> entity_instances_;     // by entity handle
  std::map<int, int> mesh_of_entity_;
  std::map<int, SkinnedEntity> skinned_;          // by entity handle
  struct SharedSkin {                             // a skinned mesh's data, shared by its characters
    uint32_t skin_vertex_offset = 0, triangle_offset = 0, triangle_count = 0;
  };
  std::map<int, SharedSkin> skin_vertices_of_mesh_;
  std::set<int> warned_joint_counts_;             // entity handles
  std::map<int, KLight> lights_by_handle_;
  std::set<std::string> warned_lights_;           // "handle defect" already warned about
  uint32_t base_material_count_ = 0;              // the map's materials; the default material's index
  mutable std::map<int, uint32_t> late_material_slots_;  // scene materials defined after the map
  mutable uint32_t next_material_slot_ = 0;
  std::vector<uint32_t> free_material_slots_;     // instance slots of freed entities
  std::vector<int> animated_materials_;           // scene materials whose registers read time or globals
  std::map<int, EntityMaterials> entity_materials_;  // entities with material instances, by handle
  std::set<int> animated_lights_;                 // light handles whose shader animates
  std::optional<double> time_override_;
  std::vector<std::array<KTexture, kTextureUseCount>> image_textures_;  // per scene image and use
  std::shared_ptr<const commit::TracerScene> snapshot_;
  WorldSyncStats stats_;
};

}  // namespace cohort::core
