#include "cohort/commit/host_skinning.h"

#include <algorithm>
#include <stdexcept>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace cohort::commit {
namespace {

void check_range(size_t first, size_t count, size_t size, uint32_t skin, const char* what) {
  if (first + count > size)
    throw std::out_of_range("skin " + std::to_string(skin) + ": " + what + " [" + std::to_string(first) + ", +" +
                            std::to_string(count) + ") past the " + std::to_string(size) + " the scene holds");
}

}  // namespace

void check_skin(const TracerScene& scene, uint32_t index) {
  if (index >= scene.skins.size()) throw std::out_of_range("skin " + std::to_string(index) + " is not in the scene");
  const KSkin skin = scene.skins[index];
  check_range(skin.vertex_offset, skin.vertex_count, scene.vertices.size(), index, "vertices");
  check_range(skin.skin_vertex_offset, skin.vertex_count, scene.skin_vertices.size(), index, "skin vertices");
  check_range(skin.blas, 1, scene.blases.size(), index, "BLAS");
  const KBlas blas = scene.blases[skin.blas];
  check_range(blas.node_offset, blas.node_count, scene.blas_nodes.size(), index, "BLAS nodes");
  check_range(blas.tri_offset, blas.tri_count, scene.triangles.size(), index, "BLAS triangles");
  for (uint32_t t = blas.tri_offset; t < blas.tri_offset + blas.tri_count; ++t) {
    const KTriangle& tri = scene.triangles[t];
    if (std::max({tri.v0, tri.v1, tri.v2}) >= scene.vertices.size())
      throw std::out_of_range("skin " + std::to_string(index) + ": its BLAS indexes past the vertices");
  }
  check_range(skin.triangle_offset, skin.triangle_count, scene.skin_triangles.size(), index, "skin triangles");
  check_range(skin.face_offset, skin.triangle_count, scene.skin_faces.size(), index, "faces");
  for (uint32_t t = skin.triangle_offset; t < skin.triangle_offset + skin.triangle_count; ++t) {
    const KSkinTriangle& tri = scene.skin_triangles[t];
    if (std::max({tri.v0, tri.v1, tri.v2}) >= skin.vertex_count)
      throw std::out_of_range("skin " + std::to_string(index) + ": a triangle names a vertex past its " +
                              std::to_string(skin.vertex_count));
  }
  for (uint32_t i = 0; i < skin.vertex_count; ++i) {
    const KSkinVertex& v = scene.skin_vertices[skin.skin_vertex_offset + i];
    check_range(v.first_weight, v.weight_count, scene.skin_weights.size(), index, "weights");
    check_range(v.first_adjacent, v.adjacent_count, scene.skin_adjacency.size(), index, "adjacency");
    for (uint32_t a = v.first_adjacent; a < v.first_adjacent + v.adjacent_count; ++a)
      if (scene.skin_adjacency[a] >= skin.triangle_count)
        throw std::out_of_range("skin " + std::to_string(index) + ": an adjacent triangle past its " +
                                std::to_string(skin.triangle_count));
  }
}

void skin_on_host(TracerScene& scene, uint32_t index) {
  if (index >= scene.skins.size()) throw std::out_of_range("skin " + std::to_string(index) + " is not in the scene");
  const KSkin skin = scene.skins[index];
  // The per-vertex ranges were checked when the skin arrived (check_skin); these may change per commit.
  check_range(skin.vertex_offset, skin.vertex_count, scene.vertices.size(), index, "vertices");
  check_range(skin.skin_vertex_offset, skin.vertex_count, scene.skin_vertices.size(), index, "skin vertices");
  check_range(skin.joint_offset, skin.joint_count, scene.joints.size(), index, "joints");
  check_range(skin.triangle_offset, skin.triangle_count, scene.skin_triangles.size(), index, "skin triangles");
  check_range(skin.face_offset, skin.triangle_count, scene.skin_faces.size(), index, "faces");
  check_range(skin.blas, 1, scene.blases.size(), index, "BLAS");
  const KBlas blas = scene.blases[skin.blas];
  check_range(blas.node_offset, blas.node_count, scene.blas_nodes.size(), index, "BLAS nodes");
  check_range(blas.tri_offset, blas.tri_count, scene.triangles.size(), index, "BLAS triangles");

  constexpr size_t kGrain = 1024;
  const tbb::blocked_range<uint32_t> all(0, skin.vertex_count, kGrain);
  tbb::parallel_for(all, [&](const tbb::blocked_range<uint32_t>& r) {
    for (uint32_t i = r.begin(); i < r.end(); ++i)
      k_skin_position(scene.vertices.data(), scene.skin_vertices.data(), scene.skin_weights.data(), scene.joints.data(),
                      skin, i);
  });
  tbb::parallel_for(tbb::blocked_range<uint32_t>(0, skin.triangle_count, kGrain), [&](const tbb::blocked_range<uint32_t>& r) {
    for (uint32_t t = r.begin(); t < r.end(); ++t)
      k_skin_face(scene.vertices.data(), scene.skin_triangles.data(), scene.skin_faces.data(), skin, t);
  });
  tbb::parallel_for(all, [&](const tbb::blocked_range<uint32_t>& r) {
    for (uint32_t i = r.begin(); i < r.end(); ++i)
      k_skin_normal(scene.vertices.data(), scene.skin_vertices.data(), scene.skin_adjacency.data(),
                    scene.skin_triangles.data(), scene.skin_faces.data(), skin, i);
  });
  KBvhNode* nodes = scene.blas_nodes.data() + blas.node_offset;
  const KTriangle* triangles = scene.triangles.data() + blas.tri_offset;
  for (uint32_t n = blas.node_count; n-- > 0;) k_refit_blas_node(nodes, triangles, scene.vertices.data(), n);
}

}  // namespace cohort::commit
