#include "cohort/commit/commit_buffer.h"

#include "cohort/commit/host_skinning.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace cohort::commit {

size_t BlasUpload::bytes() const {
  return kRecordHeaderBytes + sizeof(blas) + 3 * sizeof(uint32_t) + vertices.size() * sizeof(KVertex) +
         vertex_colors.size() * sizeof(KVertexColor) +
         triangles.size() * sizeof(KTriangle) + nodes.size() * sizeof(KBvhNode);
}

size_t SkinUpload::bytes() const {
  return kRecordHeaderBytes + sizeof(skin) + 2 * sizeof(uint32_t) + vertices.size() * sizeof(KSkinVertex) +
         weights.size() * sizeof(KSkinWeight) + triangles.size() * sizeof(KSkinTriangle) +
         adjacency.size() * sizeof(uint32_t);
}

size_t TexelUpload::bytes() const { return kRecordHeaderBytes + texels.size() * sizeof(uint32_t); }

CommitBuffer CommitBuffer::full(std::shared_ptr<const TracerScene> scene, uint64_t frame) {
  CommitBuffer c;
  c.full_ = std::move(scene);
  c.frame_ = frame;
  return c;
}

template <class T>
void CommitBuffer::set_element(std::map<uint32_t, T>& map, std::optional<uint32_t>& count, uint32_t index,
                               const T& value) {
  auto [it, inserted] = map.insert_or_assign(index, value);
  if (inserted) bytes_ += kRecordHeaderBytes + sizeof(T);
}

template <class T>
void CommitBuffer::set_count(std::map<uint32_t, T>& map, std::optional<uint32_t>& count, uint32_t new_count) {
  if (!count) bytes_ += kRecordHeaderBytes;
  count = new_count;
  // Writes past the new end are dead: the array was shrunk after them.
  for (auto it = map.lower_bound(new_count); it != map.end();) {
    bytes_ -= kRecordHeaderBytes + sizeof(T);
    it = map.erase(it);
  }
}

void CommitBuffer::set_instance_count(uint32_t count) { set_count(instances_, instance_count_, count); }
void CommitBuffer::set_instance(uint32_t index, const KInstance& v) { set_element(instances_, instance_count_, index, v); }
void CommitBuffer::set_light_count(uint32_t count) { set_count(lights_, light_count_, count); }
void CommitBuffer::set_light(uint32_t index, const KLight& v) { set_element(lights_, light_count_, index, v); }
void CommitBuffer::set_material_count(uint32_t count) { set_count(materials_, material_count_, count); }
void CommitBuffer::set_material(uint32_t index, const KMaterial& v) { set_element(materials_, material_count_, index, v); }
void CommitBuffer::set_texture_count(uint32_t count) { set_count(textures_, texture_count_, count); }
void CommitBuffer::set_texture(uint32_t index, const KTexture& v) { set_element(textures_, texture_count_, index, v); }

void CommitBuffer::set_tlas(std::vector<KBvhNode> nodes) {
  bytes_ -= tlas_ ? kRecordHeaderBytes + tlas_->size() * sizeof(KBvhNode) : 0;
  bytes_ += kRecordHeaderBytes + nodes.size() * sizeof(KBvhNode);
  tlas_ = std::move(nodes);
}

// A whole-array record: replaces an earlier one and counts its bytes once.
template <class T>
static void set_whole_array(std::optional<std::vector<T>>& slot, std::vector<T> values, size_t& bytes) {
  bytes -= slot ? kRecordHeaderBytes + slot->size() * sizeof(T) : 0;
  bytes += kRecordHeaderBytes + values.size() * sizeof(T);
  slot = std::move(values);
}

void CommitBuffer::set_light_tree(std::vector<KLightNode> nodes) { set_whole_array(light_tree_, std::move(nodes), bytes_); }
void CommitBuffer::set_emissive_triangles(std::vector<KEmissiveTriangle> triangles) {
  set_whole_array(emissive_, std::move(triangles), bytes_);
}

void CommitBuffer::add_blas(BlasUpload upload) {
  bytes_ += upload.bytes();
  blas_uploads_.push_back(std::move(upload));
}

void CommitBuffer::add_texels(TexelUpload upload) {
  bytes_ += upload.bytes();
  texel_uploads_.push_back(std::move(upload));
}

void CommitBuffer::add_skin(SkinUpload upload) {
  bytes_ += upload.bytes();
  skin_uploads_.push_back(std::move(upload));
}

void CommitBuffer::set_skin_joints(uint32_t skin, std::vector<KJoint> joints) {
  auto existing = skin_joints_.find(skin);
  if (existing != skin_joints_.end()) bytes_ -= kRecordHeaderBytes + existing->second.size() * sizeof(KJoint);
  bytes_ += kRecordHeaderBytes + joints.size() * sizeof(KJoint);
  skin_joints_[skin] = std::move(joints);
}

void CommitBuffer::set_camera(const KCamera& camera) {
  if (!camera_) bytes_ += kRecordHeaderBytes + sizeof(KCamera);
  camera_ = camera;
}

size_t CommitBuffer::record_count() const {
  return (instance_count_ ? 1 : 0) + instances_.size() + (tlas_ ? 1 : 0) + (light_count_ ? 1 : 0) + lights_.size() +
         (light_tree_ ? 1 : 0) + (emissive_ ? 1 : 0) +
         (material_count_ ? 1 : 0) + materials_.size() + (texture_count_ ? 1 : 0) + textures_.size() +
         blas_uploads_.size() + texel_uploads_.size() + skin_uploads_.size() + skin_joints_.size() +
         (camera_ ? 1 : 0);
}

void CommitBuffer::clear() {
  full_.reset();
  instance_count_.reset();
  light_count_.reset();
  material_count_.reset();
  texture_count_.reset();
  textures_.clear();
  instances_.clear();
  lights_.clear();
  light_tree_.reset();
  emissive_.reset();
  materials_.clear();
  tlas_.reset();
  blas_uploads_.clear();
  texel_uploads_.clear();
  skin_uploads_.clear();
  skin_joints_.clear();
  camera_.reset();
  bytes_ = 0;
}

void CommitBuffer::reset_to_full(std::shared_ptr<const TracerScene> scene, uint64_t frame) {
  clear();
  full_ = std::move(scene);
  frame_ = frame;
}

void CommitBuffer::merge(const CommitBuffer& later) {
  if (later.is_full_resync()) {
    *this = later;
    return;
  }
  // Counts before elements: a shrink drops earlier writes past the end, later writes then land.
  if (later.instance_count_) set_instance_count(*later.instance_count_);
  for (const auto& [i, v] : later.instances_) set_instance(i, v);
  if (later.tlas_) set_tlas(*later.tlas_);
  if (later.light_count_) set_light_count(*later.light_count_);
  for (const auto& [i, v] : later.lights_) set_light(i, v);
  if (later.light_tree_) set_light_tree(*later.light_tree_);
  if (later.emissive_) set_emissive_triangles(*later.emissive_);
  if (later.material_count_) set_material_count(*later.material_count_);
  for (const auto& [i, v] : later.materials_) set_material(i, v);
  if (later.texture_count_) set_texture_count(*later.texture_count_);
  for (const auto& [i, v] : later.textures_) set_texture(i, v);
  for (const auto& upload : later.blas_uploads_) add_blas(upload);
  for (const auto& upload : later.texel_uploads_) add_texels(upload);
  for (const auto& upload : later.skin_uploads_) add_skin(upload);
  for (const auto& [skin, joints] : later.skin_joints_) set_skin_joints(skin, joints);
  if (later.camera_) set_camera(*later.camera_);
  frame_ = later.frame_;
}

namespace {

template <class T>
void write_range(std::vector<T>& pool, uint32_t offset, const std::vector<T>& values) {
  if (values.empty()) return;
  size_t end = size_t(offset) + values.size();
  if (pool.size() < end) pool.resize(end);
  std::copy(values.begin(), values.end(), pool.begin() + offset);
}

template <class T>
bool apply_elements(std::vector<T>& array, const std::optional<uint32_t>& count,
                    const std::map<uint32_t, T>& elements, const char* what) {
  bool changed = false;
  if (count && *count != array.size()) {
    array.resize(*count);
    changed = true;
  }
  for (const auto& [index, value] : elements) {
    if (index >= array.size())
      throw std::invalid_argument(std::string("commit writes ") + what + " " + std::to_string(index) +
                                  " but the tracer scene has only " + std::to_string(array.size()));
    array[index] = value;
    changed = true;
  }
  return changed;
}

}  // namespace

ChangeSet apply_commit(const CommitBuffer& commit, TracerScene& scene, Skinning skinning) {
  ChangeSet changes;
  if (commit.is_full_resync()) {
    scene = *commit.full_scene();
    changes.full_resync = true;
  }
  if (!commit.blas_uploads().empty()) {
    changes.geometry = true;
    changes.vertices_from = scene.vertices.size();
    changes.triangles_from = scene.triangles.size();
    changes.blas_nodes_from = scene.blas_nodes.size();
    changes.blases_from = scene.blases.size();
    for (const BlasUpload& up : commit.blas_uploads()) {
      changes.vertices_from = std::min<size_t>(changes.vertices_from, up.vertex_offset);
      changes.triangles_from = std::min<size_t>(changes.triangles_from, up.triangle_offset);
      changes.blas_nodes_from = std::min<size_t>(changes.blas_nodes_from, up.node_offset);
      changes.blases_from = std::min<size_t>(changes.blases_from, up.blas_index);
      write_range(scene.vertices, up.vertex_offset, up.vertices);
      if (!up.vertex_colors.empty() && up.vertex_colors.size() != up.vertices.size())
        throw std::invalid_argument("commit uploads BLAS " + std::to_string(up.blas_index) + " with " +
                                    std::to_string(up.vertices.size()) + " vertices but " +
                                    std::to_string(up.vertex_colors.size()) + " vertex colours");
      write_range(scene.vertex_colors, up.vertex_offset,
                  up.vertex_colors.empty() ? std::vector<KVertexColor>(up.vertices.size(), K_VERTEX_COLOR_WHITE)
                                           : up.vertex_colors);
      write_range(scene.triangles, up.triangle_offset, up.triangles);
      write_range(scene.blas_nodes, up.node_offset, up.nodes);
      write_range(scene.blases, up.blas_index, std::vector<KBlas>{up.blas});
    }
  }
  // The colour pool follows the vertex pool: a scene written without colours (a full resync of an older
  // scene) is white.
  if (scene.vertex_colors.size() != scene.vertices.size()) scene.vertex_colors.resize(scene.vertices.size(), K_VERTEX_COLOR_WHITE);
  changes.instances = apply_elements(scene.instances, commit.instance_count(), commit.instances(), "instance");
  if (commit.tlas()) {
    scene.tlas_nodes = *commit.tlas();
    changes.tlas = true;
  }
  changes.lights = apply_elements(scene.lights, commit.light_count(), commit.lights(), "light");
  if (commit.light_tree()) {
    scene.light_nodes = *commit.light_tree();
    changes.light_tree = true;
  }
  if (commit.emissive_triangles()) {
    scene.emissive_triangles = *commit.emissive_triangles();
    changes.emissive = true;
  }
  changes.materials = apply_elements(scene.materials, commit.material_count(), commit.materials(), "material");
  for (const TexelUpload& up : commit.texel_uploads()) {
    write_range(scene.texels, up.offset, up.texels);
    changes.textures = true;
  }
  changes.textures |= apply_elements(scene.textures, commit.texture_count(), commit.textures(), "texture");
  for (const SkinUpload& up : commit.skin_uploads()) {
    write_range(scene.skin_vertices, up.skin.skin_vertex_offset, up.vertices);
    write_range(scene.skin_weights, up.weight_offset, up.weights);
    write_range(scene.skin_triangles, up.skin.triangle_offset, up.triangles);
    write_range(scene.skin_adjacency, up.adjacency_offset, up.adjacency);
    const size_t faces_end = size_t(up.skin.face_offset) + up.skin.triangle_count;
    if (scene.skin_faces.size() < faces_end) scene.skin_faces.resize(faces_end, KSkinFace{});
    write_range(scene.skins, up.skin_index, std::vector<KSkin>{up.skin});
    changes.skin_data = true;
  }
  for (const SkinUpload& up : commit.skin_uploads()) {
    try {
      check_skin(scene, up.skin_index);
    } catch (const std::out_of_range& e) {
      throw std::invalid_argument(std::string("commit: ") + e.what());
    }
  }
  for (const auto& [index, joints] : commit.skin_joints()) {
    if (index >= scene.skins.size() || joints.size() != scene.skins[index].joint_count)
      throw std::invalid_argument("commit poses skin " + std::to_string(index) + " with " +
                                  std::to_string(joints.size()) + " joints but the tracer scene has " +
                                  (index < scene.skins.size() ? std::to_string(scene.skins[index].joint_count) + " joints there"
                                                              : "only " + std::to_string(scene.skins.size()) + " skins"));
    write_range(scene.joints, scene.skins[index].joint_offset, joints);
    changes.posed_skins.push_back(index);
  }
  if (skinning == Skinning::on_host)
    for (uint32_t skin : changes.posed_skins) {
      try {
        skin_on_host(scene, skin);
      } catch (const std::out_of_range& e) {
        throw std::invalid_argument(std::string("commit: ") + e.what());
      }
    }
  if (commit.camera()) {
    scene.camera = *commit.camera();
    changes.camera = true;
  }
  scene.version = commit.frame();
  return changes;
}

}  // namespace cohort::commit
