// CUDA entry point: one thread per pixel of the band, running the shared integrator over the portable
// two-level BVH, exactly as the OpenCL kernel does. Texels are read through a texture object (the
// read-only texture cache); everything else through plain global loads.
#include <cuda_fp16.h>
#include <cuda_runtime.h>

#define K_CUDA_DEVICE_ONLY 1
#define K_BVH_TRIANGLE_EDGES 1  // leaves read KTriangleEdges (CudaTracer keeps them with the triangles)
__constant__ cudaTextureObject_t cohort_texel_texture;
#define K_TEXEL_LOAD(texels, index) tex1Dfetch<unsigned int>(cohort_texel_texture, (int)(index))

#include "cohort/kernel/trace_bvh.h"
#include "cohort/kernel/integrator.h"
#include "cohort/kernel/aux_outputs.h"
#include "cohort/tracers/wave_lanes.h"
#include "band_samples.cuh"
#include "ray_counting.cuh"
#include "render_band_launch.h"

namespace cohort::tracers {

// At least 4 blocks of 128 threads per SM: caps the kernel at 128 registers (25% occupancy) instead of
// 164. Measured on one H100 (docs/integrator.md, "CUDA kernel shape"): 3 blocks 15.8 ms, 4 blocks 13.7 ms,
// 5-6 blocks 13.2-13.4 ms on the large map at 1080p but slower on the test map, where spills cost more.
// Two builds: with every pixel tracing paths the sparse pattern's test is compiled out, since in this
// 128-register kernel even that early exit cost 1.5-2% of a full frame (nvidia-h100-x1, docs/integrator.md).
// kFirstHit: the first sample's first surface is recorded for the aux planes (K_AUX_PATH_FIRST_HIT), a
// build of its own so that the kernel without it stays as it was.
template <bool kSparse, bool kFirstHit>
__global__ void __launch_bounds__(128, 4) render_band_kernel(KSceneView scene, KFrameParams params, KCamera camera,
                                                          float4* band, unsigned long long* ray_counts,
                                                          unsigned* row_rays, KPathFirstHit* first_hits) {
  const BandPixel px = band_pixel(params, camera);
  KTraceCtx ctx = fresh_trace_ctx(scene);
  if (px.inside) {
    const size_t p = px.index(camera);
    KVec3 c = kSparse ? k_render_pixel(&ctx, &params, &camera, px.x, px.y)
                      : k_render_pixel_paths(&ctx, &params, &camera, px.x, px.y, kFirstHit ? first_hits + p : nullptr);
    band[p] = make_float4(c.x, c.y, c.z, 1.0f);
  }
  count_rays(ctx, px.inside, px.row, px.y < params.row_end, ray_counts, row_rays);
}

// The wavefront. The megakernel above keeps a whole path in one thread of a 128-register kernel at a
// quarter occupancy, where an incoherent bounce ray's walk waits on memory with few warps to hide it. Here
// the camera rays and each bounce's rays are walked by small kernels of their own (wavefront_walk.cu, at
// twice the occupancy), and a path's segments (what its camera ray meets up to the first bounce; then, per
// bounce, what the bounce ray meets up to the next) are shaded by kernels like the megakernel. The paths
// wait in memory between them (KPathState, kernel/path_state.h): same integrator, same random numbers, the
// megakernel's image. Transparent layers are walked inline by the shading kernels; next-event estimation's
// shadow rays are left in memory for a walk of their own (wavefront_walk.cu's shadow_walk_kernel), unless a
// vertex may emit more than its slots or COHORT_CUDA_SHADOW_WALK=0 (then walked inline too).

// k_path_segment (kernel/path_segment.h) behind a call of default inlining: forced inline into the shading
// kernels, their spill stores moved by -48 to +24 bytes (ptxas, sm_90); through this they are as they were.
__device__ bool path_segment(KTraceCtx* ctx, const KFrameParams* params, KPathState* s, const KHit* traced,
                             KPathFirstHit* first_hit, KShadowQueue* shadows, KVertexLight* vertex) {
  return k_path_segment(ctx, params, s, traced, first_hit, shadows, vertex) != 0;
}

// Pixel p's slots for its vertex's shadow rays (kShadowWalk; else none: walked as they come). The
// capacity is a constant, so that each build keeps one way (the launch gives a vertex all the slots it
// needs, k_shadow_queue_slots).
template <bool kShadowWalk>
__device__ KShadowQueue shadow_slots(const WavefrontScratch& wave, size_t p) {
  KShadowQueue q = k_shadow_queue_inline();
  if (kShadowWalk) {
    q.rays = wave.shadow_rays + p;
    q.stride = wave.shadow_stride;
    q.capacity = K_SHADOW_QUEUE_MAX;
  }
  return q;
}

// What the live paths' rays (walked by wavefront_walk.cu's kernels) met, shaded, and the paths on to their
// next bounce. kCameraRays: the camera rays' segment, whose paths begin here from the pixel (the walk kept
// only the hits: 88 bytes a pixel less each way); kFirstHit: that segment of the frame's first sample,
// which records first hits. kShadowWalk: the shadow rays left in their slots for the shadow walk (else
// walked here). With the shadow rays out, six blocks an SM (80 registers): 6.94-7.02 ms a 1080p frame of the
// large map on one H100 against 7.12-7.16 at five and 7.33-7.35 at four (docs/integrator.md); with them in
// (`every` past the slots, COHORT_CUDA_SHADOW_WALK=0) four, as the megakernel (at six that build spills 2.5 KB).
template <bool kCameraRays, bool kFirstHit, bool kShadowWalk>
__global__ void __launch_bounds__(128, kShadowWalk ? 6 : 4) wave_shade_kernel(KSceneView scene, KFrameParams params, KCamera camera,
                                                         kuint sample, float4* band, WavefrontScratch wave,
                                                         unsigned long long* ray_counts, unsigned* row_rays,
                                                         KPathFirstHit* first_hits) {
  const BandPixel px = band_pixel(params, camera);
  const size_t p = px.index(camera);
  bool inside = px.inside && (kCameraRays || (wave.active[p] & kWaveLive));
  KTraceCtx ctx = fresh_trace_ctx(scene);
  if (kCameraRays && inside && !k_pixel_traces_path(params.path_pixels, params.path_phase, px.x, px.y)) {
    // Dynamic resolution's sparse pattern leaves this pixel out: black, at no cost (k_render_pixel's way).
    wave.active[p] = 0u;
    finish_sample(band, p, v3s(0.0f), sample, params);
    inside = false;
  }
  if (inside) {
    KPathState s;
    if (kCameraRays) {
      KRng rng;
      const KVec3 dir = k_camera_sample(&params, &camera, px.x, px.y, sample, &rng);
      k_path_begin(&s, v3_load(camera.origin), dir, k_pixel_spread(&camera), rng);
    } else {
      s = wave.states[p];
    }
    const KHit hit = wave.hits[p];
    KShadowQueue shadows = shadow_slots<kShadowWalk>(wave, p);
    KVertexLight vertex;
    const bool goes_on =
        path_segment(&ctx, &params, &s, &hit, kFirstHit ? first_hits + p : nullptr, &shadows, &vertex);
    // A vertex whose shadow rays are out waits for the shadow walk, which adds its light and finishes the
    // sample of a path that ended there.
    const bool shadows_out = shadows.count > 0u;
    if (goes_on || shadows_out) wave.states[p] = s;
    if (shadows_out) wave.vertices[p] = vertex;
    if (kCameraRays || !goes_on || shadows_out)
      wave.active[p] = (goes_on ? kWaveLive : 0u) | (shadows_out ? kWaveShadowsOut : 0u);
    if (!goes_on && !shadows_out)
      finish_sample(band, p, s.radiance, sample, params);
  }
  count_rays(ctx, inside, px.row, px.y < params.row_end, ray_counts, row_rays);
}

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
}

namespace {

// One lane of a band (all of it, or launch_render_band's rows of it) as a wavefront on `stream`: per sample
// the camera walk, then per bounce a shading kernel, its shadow walk and the next bounce's walk.
void render_wavefront(const KSceneView& scene, const KFrameParams& params, const KCamera& camera, float4* band,
                      unsigned long long* ray_counts, unsigned* row_rays, KPathFirstHit* first_hits,
                      const WavefrontScratch& scratch, cudaStream_t stream) {
  const kuint rows = params.row_end - params.row_begin;
  const dim3 block(16, 8);  // 16 wide: the row ray counts rely on two rows per warp
  const dim3 grid((camera.width + block.x - 1) / block.x, (rows + block.y - 1) / block.y);
  const kuint spp = params.spp > 0u ? params.spp : 1u;  // k_paths_per_pixel (device-only in this translation unit)
  const bool shadow_walk = scratch.shadow_slots > 0u;
  // A shading kernel and, after it, the shadow rays it left, before the next one shades the paths further.
  auto shade = [&](kuint sample, bool camera_rays, KPathFirstHit* records) {
    auto launch = [&](auto kernel) {
      kernel<<<grid, block, 0, stream>>>(scene, params, camera, sample, band, scratch, ray_counts, row_rays, records);
    };
    if (!camera_rays)
      shadow_walk ? launch(wave_shade_kernel<false, false, true>) : launch(wave_shade_kernel<false, false, false>);
    else if (records)
      shadow_walk ? launch(wave_shade_kernel<true, true, true>) : launch(wave_shade_kernel<true, true, false>);
    else
      shadow_walk ? launch(wave_shade_kernel<true, false, true>) : launch(wave_shade_kernel<true, false, false>);
    if (shadow_walk)
      launch_wave_shadow_walk(grid, block, scene, params, camera, sample, band, scratch, ray_counts, row_rays, stream);
  };
  for (kuint sample = 0u; sample < spp; ++sample) {
    KPathFirstHit* records = sample == 0u ? first_hits : nullptr;
    launch_wave_camera_walk(grid, block, scene, params, camera, sample, scratch, records, ray_counts, row_rays, stream);
    shade(sample, true, records);
    for (kuint bounce = 1u; bounce <= params.max_bounces; ++bounce) {
      launch_wave_bounce_walk(grid, block, scene, params, camera, scratch, ray_counts, row_rays, stream);
      shade(sample, false, nullptr);
    }
  }
}

}  // namespace

void launch_render_band(const KSceneView& scene, const KFrameParams& params, const KCamera& camera, float4* band,
                        unsigned long long* ray_counts, unsigned* row_rays, KPathFirstHit* first_hits,
                        const WavefrontScratch* wave, cudaStream_t stream) {
  const kuint rows = params.row_end - params.row_begin;
  const dim3 block(16, 8);
  const dim3 grid((camera.width + block.x - 1) / block.x, (rows + block.y - 1) / block.y);
  const bool sparse = params.path_pixels != 0u && params.path_pixels < K_PATH_PATTERN_PIXELS;
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
      render_wavefront(scene, lane_params, camera, band + offset, ray_counts, row_rays ? row_rays + first : nullptr,
                       first_hits ? first_hits + offset : nullptr, s, lane == 0 ? stream : wave->lanes->streams[lane]);
    }
    for (int lane = 1; lane < lanes; ++lane) {
      COHORT_CUDA(cudaEventRecord(wave->lanes->joined[lane], wave->lanes->streams[lane]));
      COHORT_CUDA(cudaStreamWaitEvent(stream, wave->lanes->joined[lane], 0));
    }
  } else if (sparse)
    render_band_kernel<true, false><<<grid, block, 0, stream>>>(scene, params, camera, band, ray_counts, row_rays, nullptr);
  else if (first_hits)
    render_band_kernel<false, true><<<grid, block, 0, stream>>>(scene, params, camera, band, ray_counts, row_rays,
                                                                first_hits);
  else
    render_band_kernel<false, false><<<grid, block, 0, stream>>>(scene, params, camera, band, ray_counts, row_rays,
                                                                 nullptr);
  COHORT_CUDA(cudaGetLastError());
}

}  // namespace cohort::tracers
