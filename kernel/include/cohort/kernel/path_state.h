/* A path between two of its rays: all the integrator (integrator.h's k_path_hit_lit and k_path_vertex_end)
 * carries from one surface to the next. Plain data, so that a wavefront tracer keeps it in memory between the
 * kernel that walks a path's next ray and the one that shades what it met (tracers/cuda, tracers/opencl),
 * where the megakernel keeps it in registers. */
#ifndef COHORT_KERNEL_PATH_STATE_H
#define COHORT_KERNEL_PATH_STATE_H
#include "layout.h"
#include "path_pattern.h"
#include "portable.h"
#include "rng.h"
#include "vec.h"

typedef struct KPathState {
  KVec3 radiance, throughput;
  KVec3 org, dir;          /* the next ray */
  KVec3 vertex_position;   /* the last opaque vertex, for weighing emission a bounce from it finds (MIS) */
  float cone_width, spread, vertex_brdf_pdf;
  kuint bounce, layers;
  KRng rng;
  kuint pad;
} KPathState;

/* A pixel's flags in a wavefront's `active` scratch: its path goes on; its last vertex waits for its shadow
 * rays (wave_shade.h sets them, wave_walk.h's walks read them). */
#define K_WAVE_LIVE 1u
#define K_WAVE_SHADOWS_OUT 2u

/* Whether a wavefront tracer renders a frame with these parameters as a wavefront: lit paths that bounce
 * (dynamic resolution's sparse pattern too); the debug views and frames without a bounce take its
 * megakernel. */
KFN int k_wavefront_renders(const KFrameParams* params) {
  return params->mode == K_MODE_PATH && params->max_bounces > 0u;
}

/* A finished path's radiance into its pixel of a wavefront's band (RGBA floats). The band holds the sum of
 * the pixel's samples so far, scaled by 1 / spp when the last one is in: the megakernel's order of float
 * operations (k_render_pixel_paths), so the pixel is its value bit for bit whatever the sample count. */
KFN void k_wave_finish_sample(KGLOBAL float* band, size_t p, KVec3 radiance, kuint sample, const KFrameParams* params) {
  kuint spp = k_paths_per_pixel(params->spp);
  KGLOBAL float* out = band + p * 4u;
  KVec3 sum = sample > 0u ? v3(out[0], out[1], out[2]) : v3s(0.0f);
  sum = v3_add(sum, radiance);
  if (sample + 1u == spp) sum = v3_scale(sum, 1.0f / (float)spp);
  out[0] = sum.x;
  out[1] = sum.y;
  out[2] = sum.z;
  out[3] = 1.0f;
}

#if defined(__cplusplus) && !defined(__CUDACC_RTC__)
static_assert(sizeof(KPathState) == 88, "KPathState layout");
#endif

#endif
