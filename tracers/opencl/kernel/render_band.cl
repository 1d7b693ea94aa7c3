/* OpenCL entry point: one work item per pixel of the band, running the shared integrator over the
 * portable two-level BVH. The build inlines the #includes (embed_kernel.cmake). */
#include "cohort/kernel/trace_bvh.h"
#include "cohort/kernel/integrator.h"

__kernel void cohort_render_band(__global const KVertex* vertices, __global const KTriangle* triangles,
                                 __global const KBvhNode* blas_nodes, __global const KBlas* blases,
                                 __global const KInstance* instances, __global const KBvhNode* tlas_nodes,
                                 __global const KMaterial* materials, __global const KTexture* textures,
                                 __global const kuint* texels, __global const KLight* lights,
                                 __global const KFrameParams* params_in, __global const KCamera* camera_in,
                                 __global float* band_rgba) {
  KFrameParams params = *params_in;
  KCamera camera = *camera_in;
  kuint x = (kuint)get_global_id(0);
  kuint row = (kuint)get_global_id(1);
  kuint y = params.row_begin + row;
  if (x >= camera.width || y >= params.row_end) return;
  KTraceCtx ctx;
  ctx.scene.vertices = vertices;
  ctx.scene.triangles = triangles;
  ctx.scene.blas_nodes = blas_nodes;
  ctx.scene.blases = blases;
  ctx.scene.instances = instances;
  ctx.scene.tlas_nodes = tlas_nodes;
  ctx.scene.materials = materials;
  ctx.scene.textures = textures;
  ctx.scene.texels = texels;
  ctx.scene.lights = lights;
  ctx.scene.instance_count = params.instance_count;
  ctx.scene.light_count = params.light_count;
  ctx.scene.material_count = 0u;
  ctx.scene.texture_count = 0u;
  ctx.tlas_node_count = params.tlas_node_count;
  ctx.closest_rays = 0u;
  ctx.occlusion_rays = 0u;
  KVec3 c = k_render_pixel(&ctx, &params, &camera, x, y);
  __global float* out = band_rgba + ((size_t)row * camera.width + x) * 4u;
  out[0] = c.x;
  out[1] = c.y;
  out[2] = c.z;
  out[3] = 1.0f;
}
