// The CUDA tracer's path kernels (the megakernel render_band_kernel and the wavefront's wave_shade_kernel),
// compiled twice: by render_band.cu into namespace cohort::tracers, with K_LIGHTS_DENSE_BUILD 0, for every
// light sampling but K_LIGHTS_DENSE, and by render_band_dense.cu into cohort::tracers::dense, with
// K_LIGHTS_DENSE_BUILD 2, for K_LIGHTS_DENSE alone. The dense pick's code is not in the first build at all,
// so in-range's kernels keep their registers and spills (docs/integrator.md, "Dense rooms": a bounded pick
// that shared them made the default 8-11 % slower on one H100). The includer includes integrator.h,
// ray_counting.cuh and render_band_launch.h first, and includes this inside its namespace.

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

#include "cohort/kernel/wave_shade.h"

// What the live paths' rays (walked by wavefront_walk.cu's kernels) met, shaded, and the paths on to their
// next bounce (kernel/wave_shade.h, the OpenCL tracer's too). kCameraRays: the camera rays' segment, whose
// paths begin here from the pixel (the walk kept only the hits: 88 bytes a pixel less each way); kFirstHit:
// that segment of the frame's first sample, which records first hits. kShadowWalk: the shadow rays left in
// their slots for the shadow walk (else walked here). With the shadow rays out, six blocks an SM (80
// registers): 6.94-7.02 ms a 1080p frame of the large map on one H100 against 7.12-7.16 at five and
// 7.33-7.35 at four (docs/integrator.md); with them in (`every` past the slots, COHORT_CUDA_SHADOW_WALK=0)
// four, as the megakernel (at six that build spills 2.5 KB).
template <bool kCameraRays, bool kFirstHit, bool kShadowWalk>
__global__ void __launch_bounds__(128, kShadowWalk ? 6 : 4) wave_shade_kernel(KSceneView scene, KFrameParams params, KCamera camera,
                                                         kuint sample, float4* band, WavefrontScratch wave,
                                                         unsigned long long* ray_counts, unsigned* row_rays,
                                                         KPathFirstHit* first_hits) {
  const BandPixel px = band_pixel(params, camera);
  const size_t p = px.index(camera);
  float* const band_floats = reinterpret_cast<float*>(band);
  bool inside = k_wave_shades(px.inside, p, wave.active, kCameraRays);
  KTraceCtx ctx = fresh_trace_ctx(scene);
  inside = k_wave_shade_begin(&params, px.x, px.y, inside, p, sample, band_floats, wave.active, kCameraRays);
  if (inside) {
    KPathState s;
    KHit hit;
    KShadowQueue shadows;
    k_wave_path_load(&params, &camera, px.x, px.y, p, sample, wave.states, wave.hits, wave.shadow_rays,
                     wave.shadow_stride, kCameraRays, kShadowWalk, &s, &hit, &shadows);
    KVertexLight vertex;
    const bool goes_on =
        path_segment(&ctx, &params, &s, &hit, kFirstHit ? first_hits + p : nullptr, &shadows, &vertex);
    k_wave_path_store(&params, p, sample, goes_on, &s, &shadows, &vertex, band_floats, wave.states, wave.active,
                      wave.vertices, kCameraRays);
  }
  count_rays(ctx, inside, px.row, px.y < params.row_end, ray_counts, row_rays);
}

// PathKernels::wave_shade (render_band_launch.h) for this build.
static void launch_wave_shade(bool camera_rays, KPathFirstHit* records, bool shadow_walk, dim3 grid, dim3 block,
                              const KSceneView& scene, const KFrameParams& params, const KCamera& camera,
                              kuint sample, float4* band, const WavefrontScratch& scratch,
                              unsigned long long* ray_counts, unsigned* row_rays, cudaStream_t stream) {
  auto launch = [&](auto kernel) {
    kernel<<<grid, block, 0, stream>>>(scene, params, camera, sample, band, scratch, ray_counts, row_rays, records);
  };
  if (!camera_rays)
    shadow_walk ? launch(wave_shade_kernel<false, false, true>) : launch(wave_shade_kernel<false, false, false>);
  else if (records)
    shadow_walk ? launch(wave_shade_kernel<true, true, true>) : launch(wave_shade_kernel<true, true, false>);
  else
    shadow_walk ? launch(wave_shade_kernel<true, false, true>) : launch(wave_shade_kernel<true, false, false>);
}

// PathKernels::band_megakernel for this build.
static void launch_band_megakernel(bool sparse, KPathFirstHit* first_hits, dim3 grid, dim3 block,
                                   const KSceneView& scene, const KFrameParams& params, const KCamera& camera,
                                   float4* band, unsigned long long* ray_counts, unsigned* row_rays,
                                   cudaStream_t stream) {
  if (sparse)
    render_band_kernel<true, false><<<grid, block, 0, stream>>>(scene, params, camera, band, ray_counts, row_rays, nullptr);
  else if (first_hits)
    render_band_kernel<false, true><<<grid, block, 0, stream>>>(scene, params, camera, band, ray_counts, row_rays,
                                                                first_hits);
  else
    render_band_kernel<false, false><<<grid, block, 0, stream>>>(scene, params, camera, band, ray_counts, row_rays,
                                                                 nullptr);
}

const PathKernels path_kernels = {launch_wave_shade, launch_band_megakernel};
