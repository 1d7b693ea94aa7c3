// A tracer's own copy of everything its kernels read, as flat arrays of the portable layouts. Each
// tracer keeps one, changes it only by applying commit buffers at frame start, and uploads what the
// ChangeSet names.
#pragma once

#include <cstdint>
#include <vector>

#include "cohort/kernel/layout.h"
#include "cohort/kernel/skinning.h"

namespace cohort::commit {

struct TracerScene {
  // Geometry pools: BLASes are appended; a rebuilt BLAS gets a new slot (old one freed on resync).
  std::vector<KVertex> vertices;
  std::vector<KVertexColor> vertex_colors;  // one per vertex (RGBA8), white where a mesh has none
  std::vector<KTriangle> triangles;   // in BLAS leaf order
  std::vector<KBvhNode> blas_nodes;
  std::vector<KBlas> blases;
  // Rebuilt every frame by the core.
  std::vector<KInstance> instances;   // in TLAS leaf order
  std::vector<KBvhNode> tlas_nodes;
  std::vector<KMaterial> materials;
  std::vector<KTexture> textures;
  std::vector<uint32_t> texels;       // RGBA8, all textures and their mip levels
  std::vector<KLight> lights;
  // Derived by the core from the arrays above (core/light_sampling.h), sent whole when they change.
  std::vector<KLightNode> light_nodes;                // the light tree over `lights`
  std::vector<KEmissiveTriangle> emissive_triangles;  // every emitting triangle, world space
  // Skinned characters (kernel/skinning.h): the bind-pose data is appended once per skin; each frame
  // only a skin's joints change, and the tracer writes that skin's vertices and refits its BLAS.
  std::vector<KSkin> skins;
  std::vector<KSkinVertex> skin_vertices;
  std::vector<KSkinWeight> skin_weights;
  std::vector<KSkinTriangle> skin_triangles;
  std::vector<uint32_t> skin_adjacency;    // triangle indices relative to a skin's triangle_offset
  std::vector<KJoint> joints;
  std::vector<KSkinFace> skin_faces;       // per posed character, written with its vertices
  KCamera camera{};
  uint64_t version = 0;               // frame number of the last commit applied
};

// What applying a commit changed, so a GPU tracer uploads only that.
struct ChangeSet {
  bool full_resync = false;
  bool geometry = false;              // vertices/triangles/blas_nodes/blases grew or changed
  size_t vertices_from = 0, triangles_from = 0, blas_nodes_from = 0, blases_from = 0;  // first changed element
  bool instances = false, tlas = false, materials = false, textures = false, lights = false, camera = false;
  bool light_tree = false, emissive = false;
  bool skin_data = false;             // skins / skin vertices / weights / triangles / adjacency / faces grew
  std::vector<uint32_t> posed_skins;  // skins whose joints changed: their vertices and BLAS follow them
  bool any() const {
    return full_resync || geometry || instances || tlas || materials || textures || lights || light_tree || emissive ||
           camera || skin_data || !posed_skins.empty();
  }
};

}  // namespace cohort::commit
