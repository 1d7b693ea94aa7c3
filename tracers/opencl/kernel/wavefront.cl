/* What the OpenCL wavefront's kernels share: the shading kernels (wavefront_shade.cl, in the main program)
 * and the walks (wavefront_walk.cl, a program of its own, built with a register cap on NVIDIA). The CUDA
 * tracer's wavefront (tracers/cuda/src/render_band.cu, wavefront_walk.cu) in OpenCL C: per sample the
 * camera walk, a shading kernel, then per bounce the bounce walk and a shading kernel; after each shading
 * kernel that left shadow rays in their slots, the shadow walk. The paths wait in memory between kernels
 * (KPathState), one entry a band pixel. Needs the integrator (integrator.h) included before it. */
#include "band_params.cl"

/* Every wavefront kernel's parameters: the band kernels', then the paths' scratch, one entry a band pixel
 * (shadow-ray slot k of pixel p at shadow_rays[k * shadow_stride + p]; vertex_lights and shadow_rays null
 * where the shading kernels walk the shadow rays), the frame's sample, and the first-hit records of the
 * aux planes (null unless the frame's aux planes come from its paths). */
#define COHORT_WAVE_KERNEL_PARAMS                                                                              \
  COHORT_BAND_KERNEL_PARAMS, __global KPathState* states, __global KHit* hits, __global uint* active,             \
      __global KVertexLight* vertex_lights, __global KShadowRay* shadow_rays, kuint shadow_stride, kuint sample,   \
      __global KPathFirstHit* first_hits
#define COHORT_WAVE_KERNEL_ARGS                                                                                \
  COHORT_BAND_KERNEL_ARGS, states, hits, active, vertex_lights, shadow_rays, shadow_stride, sample, first_hits

/* The host sizes the scratch with its own sizeof: the device's structs must be the same. */
typedef char k_wave_path_state_size[sizeof(KPathState) == 88 ? 1 : -1];
typedef char k_wave_hit_size[sizeof(KHit) == 32 ? 1 : -1];
typedef char k_wave_vertex_light_size[sizeof(KVertexLight) == 64 ? 1 : -1];
typedef char k_wave_shadow_ray_size[sizeof(KShadowRay) == 48 ? 1 : -1];

/* A work item's pixel: x, its band row (the global ids run over the band, offset for a piece of it), its
 * row in the frame, and where the band holds it. */
typedef struct KWavePixel {
  kuint x, row, y;
  int inside;
  size_t index;   /* into the band and the scratch */
} KWavePixel;

KFN KWavePixel k_wave_pixel(const KFrameParams* params, const KCamera* camera) {
  KWavePixel p;
  p.x = (kuint)get_global_id(0);
  p.row = (kuint)get_global_id(1);
  p.y = params->row_begin + p.row;
  p.inside = p.x < camera->width && p.y < params->row_end;
  p.index = (size_t)p.row * camera->width + p.x;
  return p;
}

KFN KTraceCtx k_wave_trace_ctx(COHORT_BAND_KERNEL_PARAMS, const KFrameParams* params) {
  KTraceCtx ctx;
  ctx.scene = k_scene_view(vertices, vertex_colors, triangles, blas_nodes, blases, instances, tlas_nodes, materials,
                           textures, texels, lights, light_nodes, emissive, params);
  ctx.closest_rays = 0u;
  ctx.occlusion_rays = 0u;
  return ctx;
}

/* The rays a work item traced, into its band row's count (the balancer's per-row work), summed in the
 * work group's local memory first (8x8 groups, group_rows[local y]) as the megakernel sums them: the counts
 * of all kernels of a frame add up to the megakernel's. Every work item of the group calls it. */
KFN void k_wave_count_rays(__local uint* group_rows, __global uint* row_rays, const KTraceCtx* ctx, int inside,
                           const KWavePixel* px, const KFrameParams* params) {
  kuint lx = (kuint)get_local_id(0), ly = (kuint)get_local_id(1);
  if (lx == 0u) group_rows[ly] = 0u;
  barrier(CLK_LOCAL_MEM_FENCE);
  kuint rays = inside ? ctx->closest_rays + ctx->occlusion_rays : 0u;
  if (rays != 0u) atomic_add(&group_rows[ly], rays);
  barrier(CLK_LOCAL_MEM_FENCE);
  if (lx == 0u && px->y < params->row_end && group_rows[ly] != 0u) atomic_add(&row_rays[px->row], group_rows[ly]);
}

