// A commit buffer carries what changed in the scene since the frame a tracer last applied. The core
// fills one per tracer for frame N+1 while the tracer renders frame N from its own copy (Brigade,
// Fig. 7-8). The simplest commit is a full resync: the whole TracerScene; the usual one is a handful of
// incremental records (instance transforms, new BLASes, the new TLAS, lights, materials, the texture
// table and new texels, the camera).
//
// Records coalesce: writing the same element twice keeps only the last value, so a buffer that
// accumulates several frames (a tracer that skipped frames) stays as small as the set of elements that
// changed, and applying it gives the same TracerScene as applying every frame's commit in turn.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <vector>

#include "cohort/commit/tracer_scene.h"

namespace cohort::commit {

// A new BLAS: its nodes, its triangles (leaf order, absolute vertex indices) and the vertices they
// use, written at the given offsets of the tracer's geometry pools (appended at the end normally).
// vertex_colors: one per vertex, or empty when every vertex is white (what most meshes are, so that
// they send no colour bytes); the tracer's colour pool follows the vertex pool either way.
struct BlasUpload {
  uint32_t blas_index = 0;
  KBlas blas{};
  uint32_t vertex_offset = 0;
  std::vector<KVertex> vertices;
  std::vector<KVertexColor> vertex_colors;
  uint32_t triangle_offset = 0;
  std::vector<KTriangle> triangles;
  uint32_t node_offset = 0;
  std::vector<KBvhNode> nodes;
  size_t bytes() const;
};

// A new skinned character's bind-pose data (kernel/skinning.h), appended to the skin pools; its BLAS
// (the vertices it writes) comes as a BlasUpload and its pose as set_skin_joints.
struct SkinUpload {
  uint32_t skin_index = 0;
  KSkin skin{};
  // skin.skin_vertex_offset and skin.triangle_offset place the vertices and triangles; the skin's faces
  // (skin.face_offset, one per triangle) are the tracer's to write.
  uint32_t weight_offset = 0, adjacency_offset = 0;
  std::vector<KSkinVertex> vertices;
  std::vector<KSkinWeight> weights;
  std::vector<KSkinTriangle> triangles;
  std::vector<uint32_t> adjacency;
  size_t bytes() const;
};

// Texels of new or replaced textures (all their mip levels), written at `offset` of the texel buffer
// (appended at the end normally; a replaced texture's old texels stay unused until a full resync).
struct TexelUpload {
  uint32_t offset = 0;
  std::vector<uint32_t> texels;
  size_t bytes() const;
};

// Per-record framing cost counted in CommitStats::bytes, as if the records were sent over a wire:
// a 4-byte type and a 4-byte index or count.
constexpr size_t kRecordHeaderBytes = 8;

class CommitBuffer {
 public:
  CommitBuffer() = default;

  // A commit that replaces the tracer's whole scene.
  static CommitBuffer full(std::shared_ptr<const TracerScene> scene, uint64_t frame);

  bool is_full_resync() const { return full_ != nullptr; }
  uint64_t frame() const { return frame_; }
  const TracerScene* full_scene() const { return full_.get(); }
  const std::shared_ptr<const TracerScene>& shared_full_scene() const { return full_; }

  // ---- Filling (the core side). Each call replaces any earlier record for the same element. ----
  void set_frame(uint64_t frame) { frame_ = frame; }
  // Resize an array; elements past the old end must then be written with set_*.
  void set_instance_count(uint32_t count);
  void set_instance(uint32_t index, const KInstance& instance);
  void set_tlas(std::vector<KBvhNode> nodes);
  void set_light_count(uint32_t count);
  void set_light(uint32_t index, const KLight& light);
  // The derived light-sampling arrays, replaced whole (they are small and rebuilt together).
  void set_light_tree(std::vector<KLightNode> nodes);
  void set_emissive_triangles(std::vector<KEmissiveTriangle> triangles);
  void set_material_count(uint32_t count);
  void set_material(uint32_t index, const KMaterial& material);
  void set_texture_count(uint32_t count);
  void set_texture(uint32_t index, const KTexture& texture);
  void add_blas(BlasUpload upload);
  void add_texels(TexelUpload upload);
  void add_skin(SkinUpload upload);
  // A skin's pose (its joint_count joints): the per-frame record of a character.
  void set_skin_joints(uint32_t skin, std::vector<KJoint> joints);
  void set_camera(const KCamera& camera);

  // Fold a later commit into this one (the later one wins where both write an element). A full
  // resync in `later` replaces everything here.
  void merge(const CommitBuffer& later);
  // Drop every record and become a full resync to `scene` (the budget overflowed).
  void reset_to_full(std::shared_ptr<const TracerScene> scene, uint64_t frame);
  // Drop everything (the buffer is reused for the next frame).
  void clear();

  // Incremental records only (a full resync's scene is shared, not counted).
  size_t bytes() const { return bytes_; }
  size_t record_count() const;
  bool empty() const { return !is_full_resync() && record_count() == 0; }

  // ---- Reading (apply_commit, tests, tools). ----
  const std::optional<uint32_t>& instance_count() const { return instance_count_; }
  const std::map<uint32_t, KInstance>& instances() const { return instances_; }
  const std::optional<std::vector<KBvhNode>>& tlas() const { return tlas_; }
  const std::optional<uint32_t>& light_count() const { return light_count_; }
  const std::map<uint32_t, KLight>& lights() const { return lights_; }
  const std::optional<std::vector<KLightNode>>& light_tree() const { return light_tree_; }
  const std::optional<std::vector<KEmissiveTriangle>>& emissive_triangles() const { return emissive_; }
  const std::optional<uint32_t>& material_count() const { return material_count_; }
  const std::map<uint32_t, KMaterial>& materials() const { return materials_; }
  const std::vector<BlasUpload>& blas_uploads() const { return blas_uploads_; }
  const std::optional<uint32_t>& texture_count() const { return texture_count_; }
  const std::map<uint32_t, KTexture>& textures() const { return textures_; }
  const std::vector<TexelUpload>& texel_uploads() const { return texel_uploads_; }
  const std::vector<SkinUpload>& skin_uploads() const { return skin_uploads_; }
  const std::map<uint32_t, std::vector<KJoint>>& skin_joints() const { return skin_joints_; }
  const std::optional<KCamera>& camera() const { return camera_; }

 private:
  template <class T> void set_element(std::map<uint32_t, T>& map, std::optional<uint32_t>& count, uint32_t index,
                                      const T& value);
  template <class T> void set_count(std::map<uint32_t, T>& map, std::optional<uint32_t>& count, uint32_t new_count);

  std::shared_ptr<const TracerScene> full_;
  uint64_t frame_ = 0;
  std::optional<uint32_t> instance_count_, light_count_, material_count_, texture_count_;
  std::map<uint32_t, KInstance> instances_;
  std::map<uint32_t, KLight> lights_;
  std::map<uint32_t, KMaterial> materials_;
  std::map<uint32_t, KTexture> textures_;
  std::optional<std::vector<KBvhNode>> tlas_;
  std::optional<std::vector<KLightNode>> light_tree_;
  std::optional<std::vector<KEmissiveTriangle>> emissive_;
  std::vector<BlasUpload> blas_uploads_;
  std::vector<TexelUpload> texel_uploads_;
  std::vector<SkinUpload> skin_uploads_;
  std::map<uint32_t, std::vector<KJoint>> skin_joints_;
  std::optional<KCamera> camera_;
  size_t bytes_ = 0;
};

// Apply a commit to a tracer's scene copy; says what changed. Throws std::invalid_argument when a
// record does not fit the scene (an element index past the array's end), leaving `scene` partly
// updated: the caller must then ask for a full resync.
//
// Skinning: by default the posed skins' vertices and BLASes are brought up to date here on the host
// (skin_on_host), so the scene equals the core's; a tracer that skins on its device passes
// Skinning::by_tracer, keeps the joints and finds the skins to run in ChangeSet::posed_skins.
enum class Skinning { on_host, by_tracer };
ChangeSet apply_commit(const CommitBuffer& commit, TracerScene& scene, Skinning skinning = Skinning::on_host);

}  // namespace cohort::commit
