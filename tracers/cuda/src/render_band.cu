// CUDA entry point: one thread per pixel of the band, running the shared integrator over the portable
// two-level BVH, exactly as the OpenCL kernel does. Texels are read through a texture object (the
// read-only texture cache); everything else through plain global loads.
#include <cuda_fp16.h>
#include <cuda_runtime.h>

#define K_CUDA_DEVICE_ONLY 1
#define K_BVH_TRIANGLE_EDGES 1  // leaves read KTriangleEdges (CudaTracer keeps them with the triangles)
#define K_LIGHTS_DENSE_BUILD 0  // K_LIGHTS_DENSE's kernels are render_band_dense.cu's (render_band_kernels.cuh)
__constant__ cudaTextureObject_t cohort_texel_texture;
#define K_TEXEL_LOAD(texels, index) tex1Dfetch<unsigned int>(cohort_texel_texture, (int)(index))

#include "cohort/kernel/trace_bvh.h"
#include "cohort/kernel/integrator.h"
#include "cohort/kernel/aux_outputs.h"
#include "cohort/tracers/wave_lanes.h"
#include "ray_counting.cuh"
#include "render_band_launch.h"

namespace cohort::tracers {

#include "render_band_kernels.cuh"

// The 32-byte texel the host's BandBuffer keeps (halves for normal and albedo).
__device__ void store_aux_texel(const KAux& a, KAuxTexel* out) {
  KAuxTexel t;
  t.depth = a.depth;
  t.prev_depth = a.prev_depth;
  t.motion[0] = a.motion[0];
  t.motion[1] = a.motion[1];
  for (int k = 0; k < 3; ++k) {
    t.normal[k] = __half_as_ushort(__float2half_rn(a.normal[k]));
    t.albedo[k] = __half_as_ushort(__float2half_rn(a.albedo[k]));
  }
  t.id = a.id;
  *out = t;
}

// Auxiliary outputs (aux_outputs.h), launched only for frames that ask for them: K_AUX_CENTRE_RAY, a ray
// of their own through each pixel's centre.
__global__ void aux_band_kernel(KSceneView scene, KFrameParams params, KCamera camera, KCamera previous_camera,
                                KAuxHistory history, KAuxTexel* band_aux) {
  const kuint x = blockIdx.x * blockDim.x + threadIdx.x;
  const kuint row = blockIdx.y * blockDim.y + threadIdx.y;
  const kuint y = params.row_begin + row;
  if (x >= camera.width || y >= params.row_end) return;
  KTraceCtx ctx;
  ctx.scene = scene;
  ctx.closest_rays = 0u;
  ctx.occlusion_rays = 0u;
  KAux a;
  k_pixel_aux(&ctx, &camera, &previous_camera, &history, x, y, &a);
  store_aux_texel(a, band_aux + size_t(row) * camera.width + x);
}

// K_AUX_PATH_FIRST_HIT: the planes finished from what the band's paths recorded (no ray of their own).
__global__ void aux_from_first_hits_kernel(KSceneView scene, KFrameParams params, KCamera camera,
                                           KCamera previous_camera, KAuxHistory history,
                                           const KPathFirstHit* first_hits, KAuxTexel* band_aux) {
  const kuint x = blockIdx.x * blockDim.x + threadIdx.x;
  const kuint row = blockIdx.y * blockDim.y + threadIdx.y;
  const kuint y = params.row_begin + row;
  if (x >= camera.width || y >= params.row_end) return;
  const size_t p = size_t(row) * camera.width + x;
  KAux a;
  k_aux_from_first_hit(&scene, &params, &camera, &previous_camera, &history, x, y, first_hits[p], &a);
  store_aux_texel(a, band_aux + p);
}

void launch_aux_band(const KSceneView& scene, const KFrameParams& params, const KCamera& camera,
                     const KCamera& previous_camera, const KAuxHistory& history, KAuxTexel* band_aux,
                     cudaStream_t stream) {
  const kuint rows = params.row_end - params.row_begin;
  const dim3 block(16, 8);
  const dim3 grid((camera.width + block.x - 1) / block.x, (rows + block.y - 1) / block.y);
  aux_band_kernel<<<grid, block, 0, stream>>>(scene, params, camera, previous_camera, history, band_aux);
  COHORT_CUDA(cudaGetLastError());
}

void launch_aux_from_first_hits(const KSceneView& scene, const KFrameParams& params, const KCamera& camera,
                                const KCamera& previous_camera, const KAuxHistory& history,
                                const KPathFirstHit* first_hits, KAuxTexel* band_aux, cudaStream_t stream) {
  const kuint rows = params.row_end - params.row_begin;
  const dim3 block(16, 8);
  const dim3 grid((camera.width + block.x - 1) / block.x, (rows + block.y - 1) / block.y);
  aux_from_first_hits_kernel<<<grid, block, 0, stream>>>(scene, params, camera, previous_camera, history, first_hits,
                                                         band_aux);
  COHORT_CUDA(cudaGetLastError());
}

void set_texel_texture(cudaTextureObject_t texture) {
  COHORT_CUDA(cudaMemcpyToSymbol(cohort_texel_texture, &texture, sizeof texture));
  set_walk_texel_texture(texture);
  dense::set_texel_texture(texture);
}

namespace {

// Whether the band's frame runs K_LIGHTS_DENSE's kernels (render_band_dense.cu): with light_samples 0 every
// way is `every`, which only the other build compiles.
bool dense_lights(const KFrameParams& params) {
  return params.light_sampling == K_LIGHTS_DENSE && params.light_samples > 0u;
}

// One lane of a band (all of it, or launch_render_band's rows of it) as a wavefront on `stream`: per sample
// the camera walk, then per bounce a shading kernel, its shadow walk and the next bounce's walk.
// released (may be null): recorded on `stream` before the last release_before_end kernels.
void render_wavefront(const KSceneView& scene, const KFrameParams& params, const KCamera& camera, float4* band,
                      unsigned long long* ray_counts, unsigned* row_rays, KPathFirstHit* first_hits,
                      const WavefrontScratch& scratch, cudaStream_t stream, cudaEvent_t released,
                      int release_before_end) {
  const kuint rows = params.row_end - params.row_begin;
  const dim3 block(16, 8);  // 16 wide: the row ray counts rely on two rows per warp
  const dim3 grid((camera.width + block.x - 1) / block.x, (rows + block.y - 1) / block.y);
  const kuint spp = params.spp > 0u ? params.spp : 1u;  // k_paths_per_pixel (device-only in this translation unit)
  const bool shadow_walk = scratch.shadow_slots > 0u;
  const PathKernels& kernels = dense_lights(params) ? dense::path_kernels : path_kernels;
  // The kernels in order: per sample the camera walk, then per stage a shading kernel (and its shadow walk).
  const kuint per_stage = shadow_walk ? 2u : 1u;
  const kuint total = spp * (1u + per_stage + params.max_bounces * (1u + per_stage));
  const kuint release_at = total > kuint(release_before_end) ? total - kuint(release_before_end) : 0u;
  kuint launched = 0u;
  auto next_launch = [&] {
    if (released && launched == release_at) COHORT_CUDA(cudaEventRecord(released, stream));
    ++launched;
  };
  // A shading kernel and, after it, the shadow rays it left, before the next one shades the paths further.
  auto shade = [&](kuint sample, bool camera_rays, KPathFirstHit* records) {
    next_launch();
    kernels.wave_shade(camera_rays, records, shadow_walk, grid, block, scene, params, camera, sample, band, scratch,
                       ray_counts, row_rays, stream);
    if (shadow_walk) {
      next_launch();
      launch_wave_shadow_walk(grid, block, scene, params, camera, sample, band, scratch, ray_counts, row_rays, stream);
    }
  };
  for (kuint sample = 0u; sample < spp; ++sample) {
    KPathFirstHit* records = sample == 0u ? first_hits : nullptr;
    next_launch();
    launch_wave_camera_walk(grid, block, scene, params, camera, sample, scratch, records, ray_counts, row_rays, stream);
    shade(sample, true, records);
    for (kuint bounce = 1u; bounce <= params.max_bounces; ++bounce) {
      next_launch();
      launch_wave_bounce_walk(grid, block, scene, params, camera, scratch, ray_counts, row_rays, stream);
      shade(sample, false, nullptr);
    }
  }
}

}  // namespace

int launch_render_band(const KSceneView& scene, const KFrameParams& params, const KCamera& camera, float4* band,
                       unsigned long long* ray_counts, unsigned* row_rays, KPathFirstHit* first_hits,
                       const WavefrontScratch* wave, cudaStream_t stream) {
  const kuint rows = params.row_end - params.row_begin;
  const dim3 block(16, 8);
  const dim3 grid((camera.width + block.x - 1) / block.x, (rows + block.y - 1) / block.y);
  const bool sparse = params.path_pixels != 0u && params.path_pixels < K_PATH_PATTERN_PIXELS;
  int released_lanes = 0;
  if (wave) {
    // Every kernel indexes its lane's pixels from the lane's first row: each lane gets the band's buffers
    // from its first pixel on (shadow slots keep the whole band's stride, so lanes never share one).
    WavefrontScratch whole = *wave;
    whole.shadow_stride = camera.width * rows;
    const int lanes = wave->lanes ? wave_lane_count(wave->lanes->count, rows) : 1;
    if (lanes > 1) {
      COHORT_CUDA(cudaEventRecord(wave->lanes->forked, stream));
      for (int lane = 1; lane < lanes; ++lane)
        COHORT_CUDA(cudaStreamWaitEvent(wave->lanes->streams[lane], wave->lanes->forked, 0));
    }
    for (int lane = 0; lane < lanes; ++lane) {
      const kuint first = wave_lane_first_row(rows, lanes, lane), last = wave_lane_first_row(rows, lanes, lane + 1);
      KFrameParams lane_params = params;
      lane_params.row_begin = params.row_begin + first;
      lane_params.row_end = params.row_begin + last;
      const size_t offset = size_t(first) * camera.width;
      WavefrontScratch s = whole;
      s.states += offset;
      s.hits += offset;
      s.active += offset;
      if (s.vertices) s.vertices += offset;
      if (s.shadow_rays) s.shadow_rays += offset;
      const bool release = wave->lanes && wave->lanes->release_before_end > 0;
      render_wavefront(scene, lane_params, camera, band + offset, ray_counts, row_rays ? row_rays + first : nullptr,
                       first_hits ? first_hits + offset : nullptr, s, lane == 0 ? stream : wave->lanes->streams[lane],
                       release ? wave->lanes->released[lane] : nullptr, release ? wave->lanes->release_before_end : 0);
      if (release) released_lanes = lane + 1;
    }
    for (int lane = 1; lane < lanes; ++lane) {
      COHORT_CUDA(cudaEventRecord(wave->lanes->joined[lane], wave->lanes->streams[lane]));
      COHORT_CUDA(cudaStreamWaitEvent(stream, wave->lanes->joined[lane], 0));
    }
  } else {
    const PathKernels& kernels = dense_lights(params) ? dense::path_kernels : path_kernels;
    kernels.band_megakernel(sparse, first_hits, grid, block, scene, params, camera, band, ray_counts, row_rays,
                            stream);
  }
  COHORT_CUDA(cudaGetLastError());
  return released_lanes;
}

}  // namespace cohort::tracers
