/* What a kernel sees of a TracerScene: pointers to its arrays plus their counts, and the record of a
 * ray hit. Every tracer builds it with k_scene_view (host pointers for the CPU tracer, device pointers
 * on GPUs), so the fields are filled in one place only. */
#ifndef COHORT_KERNEL_SCENE_VIEW_H
#define COHORT_KERNEL_SCENE_VIEW_H
#include "layout.h"
#include "vec.h"

typedef struct KSceneView {
  KGLOBAL const KVertex* vertices;
  KGLOBAL const KVertexColor* vertex_colors;  /* one per vertex (layout.h); read only for vertexColor materials */
  KGLOBAL const KTriangle* triangles;
  KGLOBAL const KBvhNode* blas_nodes;
  KGLOBAL const KBlas* blases;
  KGLOBAL const KInstance* instances;
  KGLOBAL const KBvhNode* tlas_nodes;
  KGLOBAL const KMaterial* materials;
  KGLOBAL const KTexture* textures;
  KGLOBAL const kuint* texels;
  KGLOBAL const KLight* lights;
  KGLOBAL const KLightNode* light_nodes;
  KGLOBAL const KEmissiveTriangle* emissive;
  /* Optional KTriangleEdges parallel to `triangles` (bvh_traverse.h); null unless a tracer sets it after
   * k_scene_view. */
  KGLOBAL const KTriangleEdges* triangle_edges;
  kuint instance_count;
  kuint tlas_node_count;
  kuint light_count;
  kuint light_node_count;
  kuint emissive_count;
  kuint volume_light_begin, volume_light_end;  /* fog and blend lights lie in this range (layout.h) */
} KSceneView;

/* The view over a scene's arrays, wherever they live. The counts come from the frame parameters,
 * which the host sets from the tracer's scene copy (tracers/common's TracerBase::frame_params): a
 * kernel that receives the arrays as separate buffers (OpenCL) learns their lengths that way. */
KFN KSceneView k_scene_view(KGLOBAL const KVertex* vertices, KGLOBAL const KVertexColor* vertex_colors,
                            KGLOBAL const KTriangle* triangles,
                            KGLOBAL const KBvhNode* blas_nodes, KGLOBAL const KBlas* blases,
                            KGLOBAL const KInstance* instances, KGLOBAL const KBvhNode* tlas_nodes,
                            KGLOBAL const KMaterial* materials, KGLOBAL const KTexture* textures,
                            KGLOBAL const kuint* texels, KGLOBAL const KLight* lights,
                            KGLOBAL const KLightNode* light_nodes, KGLOBAL const KEmissiveTriangle* emissive,
                            const KFrameParams* params) {
  KSceneView v;
  v.vertices = vertices;
  v.vertex_colors = vertex_colors;
  v.triangles = triangles;
  v.blas_nodes = blas_nodes;
  v.blases = blases;
  v.instances = instances;
  v.tlas_nodes = tlas_nodes;
  v.materials = materials;
  v.textures = textures;
  v.texels = texels;
  v.lights = lights;
  v.light_nodes = light_nodes;
  v.emissive = emissive;
  v.triangle_edges = 0;
  v.instance_count = params->instance_count;
  v.tlas_node_count = params->tlas_node_count;
  v.light_count = params->light_count;
  v.light_node_count = params->light_node_count;
  v.emissive_count = params->emissive_count;
  v.volume_light_begin = params->volume_light_begin;
  v.volume_light_end = params->volume_light_end < params->light_count ? params->volume_light_end : params->light_count;
  return v;
}

/* The light node array holds two trees (layout.h, KLightNode): the Doom 3 lights' tree from node 0, then
 * the emissive triangles' tree in the last 2E - 1 nodes (E = emissive_count; none when E = 0). */
KFN kuint k_emissive_tree_nodes(const KSceneView* scene) {
  kuint e = scene->emissive_count;
  return e > 0u && scene->light_node_count >= 2u * e - 1u ? 2u * e - 1u : 0u;
}

KFN kuint k_light_tree_nodes(const KSceneView* scene) {
  return scene->light_node_count - k_emissive_tree_nodes(scene);
}

/* A ray hit: triangle is an absolute index into the triangle array; (u, v) are the barycentrics of
 * v1 and v2 (p = (1-u-v) p0 + u p1 + v p2), as Embree and Moller-Trumbore both report them. */
typedef struct KHit {
  float t, u, v;
  kuint instance;
  kuint triangle;
  kuint cost;   /* traversal steps, for the BVH debug view; 0 where the tracer cannot count them */
  kuint pad0, pad1;
} KHit;

/* Ray masks (KInstance.mask bits a ray accepts). */
#define K_RAY_PRIMARY K_MASK_PRIMARY
#define K_RAY_SHADOW  K_MASK_SHADOW

#endif
