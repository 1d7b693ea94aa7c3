/* What a kernel sees of a TracerScene: device pointers to its arrays plus counts, and the record of
 * a ray hit. Built by each tracer (host pointers for the CPU tracer, device pointers on GPUs). */
#ifndef COHORT_KERNEL_SCENE_VIEW_H
#define COHORT_KERNEL_SCENE_VIEW_H
#include "layout.h"
#include "vec.h"

typedef struct KSceneView {
  KGLOBAL const KVertex* vertices;
  KGLOBAL const KTriangle* triangles;
  KGLOBAL const KBvhNode* blas_nodes;
  KGLOBAL const KBlas* blases;
  KGLOBAL const KInstance* instances;
  KGLOBAL const KBvhNode* tlas_nodes;
  KGLOBAL const KMaterial* materials;
  KGLOBAL const KTexture* textures;
  KGLOBAL const kuint* texels;
  KGLOBAL const KLight* lights;
  kuint instance_count;
  kuint light_count;
  kuint material_count;
  kuint texture_count;
} KSceneView;

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
