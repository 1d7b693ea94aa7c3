/* OpenCL entry point: one work item per pixel of the band, running the shared integrator over the
 * portable two-level BVH. The build inlines the #includes (embed_kernel.cmake). */
#include "cohort/kernel/trace_bvh.h"
#include "cohort/kernel/integrator.h"
#include "cohort/kernel/aux_outputs.h"
#include "cohort/kernel/band_pack.h"

#include "band_params.cl"

/* The band's pixels, recording first hits where first_hits is not null (the kernels below). */
KFN void render_band_pixels(COHORT_BAND_KERNEL_PARAMS, __global KPathFirstHit* first_hits,
                            __local uint* group_row_rays) {
  /* Rays traced per row of the band (the balancer's per-row work), summed in local memory first so
   * that each work group adds once per row. The host launches 8x8 work groups. */
  KFrameParams params = *params_in;
  KCamera camera = *camera_in;
  kuint x = (kuint)get_global_id(0);
  kuint row = (kuint)get_global_id(1);
  kuint y = params.row_begin + row;
  kuint lx = (kuint)get_local_id(0), ly = (kuint)get_local_id(1);
  if (lx == 0u) group_row_rays[ly] = 0u;
  barrier(CLK_LOCAL_MEM_FENCE);
  if (x < camera.width && y < params.row_end) {
    KTraceCtx ctx;
    ctx.scene = k_scene_view(vertices, vertex_colors, triangles, blas_nodes, blases, instances, tlas_nodes, materials, textures, texels,
                             lights, light_nodes, emissive, &params);
    ctx.closest_rays = 0u;
    ctx.occlusion_rays = 0u;
    KVec3 c = first_hits ? k_render_pixel_paths(&ctx, &params, &camera, x, y,
                                                first_hits + (size_t)row * camera.width + x)
                         : k_render_pixel(&ctx, &params, &camera, x, y);
    __global float* out = band_rgba + ((size_t)row * camera.width + x) * 4u;
    out[0] = c.x;
    out[1] = c.y;
    out[2] = c.z;
    out[3] = 1.0f;
    atomic_add(&group_row_rays[ly], ctx.closest_rays + ctx.occlusion_rays);
  }
  barrier(CLK_LOCAL_MEM_FENCE);
  if (lx == 0u && y < params.row_end && group_row_rays[ly] != 0u) atomic_add(&row_rays[row], group_row_rays[ly]);
}

__kernel void cohort_render_band(COHORT_BAND_KERNEL_PARAMS) {
  __local uint group_row_rays[8];
  render_band_pixels(COHORT_BAND_KERNEL_ARGS, 0, group_row_rays);
}

/* The same, recording each pixel's first sample's first surface for the aux planes (K_AUX_PATH_FIRST_HIT):
 * a kernel of its own, so that the one without it compiles as before. */
__kernel void cohort_render_band_first_hits(COHORT_BAND_KERNEL_PARAMS, __global KPathFirstHit* first_hits) {
  __local uint group_row_rays[8];
  render_band_pixels(COHORT_BAND_KERNEL_ARGS, first_hits, group_row_rays);
}

/* Auxiliary outputs (aux_outputs.h), launched only for frames that ask for them: one work item per
 * pixel of the band, writing a KAux each, from a centre ray or (k_aux_from_paths) from the band kernel's
 * first-hit records. prev_transforms: 12 floats per instance (the host always
 * passes one; with no instance moved it equals the current transforms); prev_joints: the joint pool of
 * the previous frame, read when skin_count > 0 (aux_history.h). */
__kernel void cohort_aux_band(__global const KVertex* vertices, __global const KVertexColor* vertex_colors,
                                 __global const KTriangle* triangles,
                              __global const KBvhNode* blas_nodes, __global const KBlas* blases,
                              __global const KInstance* instances, __global const KBvhNode* tlas_nodes,
                              __global const KMaterial* materials, __global const KTexture* textures,
                              __global const kuint* texels, __global const KLight* lights,
                              __global const KLightNode* light_nodes, __global const KEmissiveTriangle* emissive,
                              __global const KFrameParams* params_in, __global const KCamera* camera_in,
                              __global const KCamera* prev_camera_in, __global const float* prev_transforms,
                              __global const KSkin* skins, __global const KSkinVertex* skin_vertices,
                              __global const KSkinWeight* skin_weights, __global const KJoint* prev_joints,
                              kuint skin_count, __global const KPathFirstHit* first_hits,
                              __global KAux* band_aux) {
  KFrameParams params = *params_in;
  KCamera camera = *camera_in;
  KCamera prev_camera = *prev_camera_in;
  kuint x = (kuint)get_global_id(0);
  kuint row = (kuint)get_global_id(1);
  kuint y = params.row_begin + row;
  if (x >= camera.width || y >= params.row_end) return;
  KTraceCtx ctx;
  ctx.scene = k_scene_view(vertices, vertex_colors, triangles, blas_nodes, blases, instances, tlas_nodes, materials, textures, texels,
                           lights, light_nodes, emissive, &params);
  ctx.closest_rays = 0u;
  ctx.occlusion_rays = 0u;
  KAuxHistory history;
  history.object_to_world = params.instance_count > 0u ? prev_transforms : 0;
  history.skins = skins;
  history.skin_vertices = skin_vertices;
  history.skin_weights = skin_weights;
  history.joints = skin_count > 0u ? prev_joints : 0;
  history.skin_count = skin_count;
  KAux a;
  if (k_aux_from_paths(&params))
    k_aux_from_first_hit(&ctx.scene, &params, &camera, &prev_camera, &history, x, y,
                         first_hits[(size_t)row * camera.width + x], &a);
  else
    k_pixel_aux(&ctx, &camera, &prev_camera, &history, x, y, &a);
  band_aux[(size_t)row * camera.width + x] = a;
}

/* What crosses the bus: the band as RGB half floats (core's BandFormat::rgb16f, 6 bytes a pixel instead
 * of 16) and the aux records packed to KAuxTexel (32 bytes instead of 48), converted here so the host
 * reads them straight into its band buffer. vstore_half_rte rounds as the host's and CUDA's conversions. */
__kernel void cohort_band_to_rgb16f(__global const float* band, __global half* rgb, kuint pixels) {
  kuint p = (kuint)get_global_id(0);
  if (p >= pixels) return;
  vstore_half_rte(band[4 * p + 0], 3 * p + 0, rgb);
  vstore_half_rte(band[4 * p + 1], 3 * p + 1, rgb);
  vstore_half_rte(band[4 * p + 2], 3 * p + 2, rgb);
}

/* Or as RGB9E5 words (BandFormat::rgb9e5, 4 bytes a pixel, kernel/band_pack.h), dithered by the pixel's
 * place in the frame (band_first_pixel + p) and the frame, as every other producer dithers it. */
__kernel void cohort_band_to_rgb9e5(__global const float* band, __global kuint* packed, kuint pixels,
                                    kuint band_first_pixel, kuint frame) {
  kuint p = (kuint)get_global_id(0);
  if (p >= pixels) return;
  packed[p] = k_rgb9e5_encode(band[4 * p + 0], band[4 * p + 1], band[4 * p + 2],
                              k_rgb9e5_dither(band_first_pixel + p, frame));
}

__kernel void cohort_aux_to_texels(__global const KAux* aux, __global KAuxTexel* texels, kuint pixels) {
  kuint p = (kuint)get_global_id(0);
  if (p >= pixels) return;
  KAux a = aux[p];
  __global KAuxTexel* t = texels + p;
  t->depth = a.depth;
  t->prev_depth = a.prev_depth;
  t->motion[0] = a.motion[0];
  t->motion[1] = a.motion[1];
  for (int k = 0; k < 3; ++k) {
    vstore_half_rte(a.normal[k], 0, (__global half*)&t->normal[k]);
    vstore_half_rte(a.albedo[k], 0, (__global half*)&t->albedo[k]);
  }
  t->id = a.id;
}

/* The wavefront's shading kernels (its walks are a program of their own: wavefront_walk.cl). */
#include "wavefront_shade.cl"

/* Skinned characters: the skinning kernels share the program. */
#include "skinning.cl"
