#include "cohort/commit/array_diff.h"

#include <cstring>
#include <string>

namespace cohort::commit {
namespace {

template <class T>
bool same_bytes(const T& a, const T& b) {
  return std::memcmp(&a, &b, sizeof(T)) == 0;
}

// Records into `out` through its setters for this array: set_count when the size changed, set for each
// element that is new or whose bytes differ.
template <class T>
void diff_array(const std::vector<T>& before, const std::vector<T>& after, CommitBuffer& out,
                void (CommitBuffer::*set_count)(uint32_t), void (CommitBuffer::*set)(uint32_t, const T&)) {
  if (before.size() != after.size()) (out.*set_count)(static_cast<uint32_t>(after.size()));
  for (size_t i = 0; i < after.size(); ++i)
    if (i >= before.size() || !same_bytes(before[i], after[i])) (out.*set)(static_cast<uint32_t>(i), after[i]);
}

template <class T>
bool same_array(const std::vector<T>& a, const std::vector<T>& b, const char* name, std::string* where) {
  if (a.size() != b.size()) {
    if (where) *where = std::string(name) + ".size() " + std::to_string(a.size()) + " vs " + std::to_string(b.size());
    return false;
  }
  for (size_t i = 0; i < a.size(); ++i) {
    if (!same_bytes(a[i], b[i])) {
      if (where) *where = std::string(name) + "[" + std::to_string(i) + "]";
      return false;
    }
  }
  return true;
}

}  // namespace

void diff_instances(const std::vector<KInstance>& before, const std::vector<KInstance>& after, CommitBuffer& out) {
  diff_array(before, after, out, &CommitBuffer::set_instance_count, &CommitBuffer::set_instance);
}
void diff_lights(const std::vector<KLight>& before, const std::vector<KLight>& after, CommitBuffer& out) {
  diff_array(before, after, out, &CommitBuffer::set_light_count, &CommitBuffer::set_light);
}
void diff_materials(const std::vector<KMaterial>& before, const std::vector<KMaterial>& after, CommitBuffer& out) {
  diff_array(before, after, out, &CommitBuffer::set_material_count, &CommitBuffer::set_material);
}
void diff_textures(const std::vector<KTexture>& before, const std::vector<KTexture>& after, CommitBuffer& out) {
  diff_array(before, after, out, &CommitBuffer::set_texture_count, &CommitBuffer::set_texture);
}

void diff_tlas(const std::vector<KBvhNode>& before, const std::vector<KBvhNode>& after, CommitBuffer& out) {
  if (!same_array(before, after, "tlas", nullptr)) out.set_tlas(after);
}

void diff_light_tree(const std::vector<KLightNode>& before, const std::vector<KLightNode>& after, CommitBuffer& out) {
  if (!same_array(before, after, "light_nodes", nullptr)) out.set_light_tree(after);
}

void diff_emissive_triangles(const std::vector<KEmissiveTriangle>& before, const std::vector<KEmissiveTriangle>& after,
                             CommitBuffer& out) {
  if (!same_array(before, after, "emissive_triangles", nullptr)) out.set_emissive_triangles(after);
}

bool same_tracer_scene(const TracerScene& a, const TracerScene& b, std::string* where) {
  return same_array(a.vertices, b.vertices, "vertices", where) &&
         same_array(a.vertex_colors, b.vertex_colors, "vertex_colors", where) &&
         same_array(a.triangles, b.triangles, "triangles", where) &&
         same_array(a.blas_nodes, b.blas_nodes, "blas_nodes", where) &&
         same_array(a.blases, b.blases, "blases", where) &&
         same_array(a.instances, b.instances, "instances", where) &&
         same_array(a.tlas_nodes, b.tlas_nodes, "tlas_nodes", where) &&
         same_array(a.materials, b.materials, "materials", where) &&
         same_array(a.textures, b.textures, "textures", where) &&
         same_array(a.texels, b.texels, "texels", where) &&
         same_array(a.lights, b.lights, "lights", where) &&
         same_array(a.light_nodes, b.light_nodes, "light_nodes", where) &&
         same_array(a.emissive_triangles, b.emissive_triangles, "emissive_triangles", where) &&
         same_array(a.skins, b.skins, "skins", where) &&
         same_array(a.skin_vertices, b.skin_vertices, "skin_vertices", where) &&
         same_array(a.skin_weights, b.skin_weights, "skin_weights", where) &&
         same_array(a.skin_triangles, b.skin_triangles, "skin_triangles", where) &&
         same_array(a.skin_adjacency, b.skin_adjacency, "skin_adjacency", where) &&
         same_array(a.joints, b.joints, "joints", where) &&
         same_array(a.skin_faces, b.skin_faces, "skin_faces", where) &&
         same_array(std::vector<KCamera>{a.camera}, std::vector<KCamera>{b.camera}, "camera", where);
}

}  // namespace cohort::commit
