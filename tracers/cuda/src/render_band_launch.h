#pragma once

#include <cuda_runtime.h>

#include "cuda_check.h"
#include "cohort/kernel/aux_history.h"
#include "cohort/kernel/path_pattern.h"
#include "cohort/kernel/path_state.h"
#include "cohort/kernel/scene_view.h"
#include "cohort/kernel/shadow_ray.h"

namespace cohort::tracers {

void set_texel_texture(cudaTextureObject_t texture);

// The wavefront may run a band as lanes of rows, each lane's kernels on a stream of its own, so that one
// lane's kernels fill the GPU while another's drain: a kernel's last wave leaves SMs idle, and a GPU's share
// of a four-GPU frame is only about four waves a kernel (nvidia-h100-x4, large map 1080p: the four bands'
// kernels took 16 % more GPU time than one GPU's whole frame). The band's own stream runs lane 0;
// streams[i] lane i, forked from it and joined back with the events.
constexpr int kMaxWaveLanes = 4;
struct WaveLanes {
  int count = 1;
  cudaStream_t streams[kMaxWaveLanes] = {};
  cudaEvent_t forked = nullptr;
  cudaEvent_t joined[kMaxWaveLanes] = {};
  // Where the next band may start (CudaTracer's band overlap): each lane records released[lane] on its stream
  // before its last `release_before_end` kernels, so that the next band's first kernels fill the SMs while
  // this band's last ones drain. 0: nothing recorded (the next band waits for the whole band).
  int release_before_end = 0;
  cudaEvent_t released[kMaxWaveLanes] = {};
};

// The bounce rays' wavefront (render_band.cu): where paths wait between its kernels. Device pointers, each
// for at least the band's pixels (shadow_rays: shadow_slots times that).
struct WavefrontScratch {
  KPathState* states = nullptr;
  KHit* hits = nullptr;
  kuint* active = nullptr;  // K_WAVE_LIVE | K_WAVE_SHADOWS_OUT (kernel/path_state.h)
  // Next-event estimation's shadow rays, walked by a kernel of their own (wavefront_walk.cu) when
  // shadow_slots > 0; 0: the shading kernels walk them as they come. The shading kernel leaves a pixel's
  // vertex in vertices and its rays in slots k * shadow_stride + pixel (launch_render_band sets the stride).
  KVertexLight* vertices = nullptr;
  KShadowRay* shadow_rays = nullptr;
  kuint shadow_slots = 0u, shadow_stride = 0u;
  const WaveLanes* lanes = nullptr;  // null: one lane
};
// The wavefront's walks (wavefront_walk.cu): the camera rays of a sample (records: the
// first-hit records to clear, or null), and the live paths' bounce rays; each ray's hit into wave.hits.
void launch_wave_camera_walk(dim3 grid, dim3 block, const KSceneView& scene, const KFrameParams& params,
                             const KCamera& camera, kuint sample, const WavefrontScratch& wave, KPathFirstHit* records,
                             unsigned long long* ray_counts, unsigned* row_rays, cudaStream_t stream);
void launch_wave_bounce_walk(dim3 grid, dim3 block, const KSceneView& scene, const KFrameParams& params,
                             const KCamera& camera, const WavefrontScratch& wave, unsigned long long* ray_counts,
                             unsigned* row_rays, cudaStream_t stream);
// The shadow rays the shading kernel left (pixels flagged K_WAVE_SHADOWS_OUT): each walked, its vertex's light
// added to its path's radiance, and a path that ended there finished into the band.
void launch_wave_shadow_walk(dim3 grid, dim3 block, const KSceneView& scene, const KFrameParams& params,
                             const KCamera& camera, kuint sample, float4* band, const WavefrontScratch& wave,
                             unsigned long long* ray_counts, unsigned* row_rays, cudaStream_t stream);
// That translation unit's copy of the texel texture (its alpha-tested surfaces read it).
void set_walk_texel_texture(cudaTextureObject_t texture);

// One build's path kernels (render_band_kernels.cuh): render_band.cu's, `path_kernels` here, for every light
// sampling but K_LIGHTS_DENSE; render_band_dense.cu's, `dense::path_kernels`, for it. wave_shade: a wavefront
// step's shading kernel (the camera rays' segment, with first-hit records or without, or a bounce's; shadow
// rays left for the shadow walk or not); band_megakernel: the megakernel over a band (the sparse pattern's
// build, the first-hit records' or the plain one).
struct PathKernels {
  void (*wave_shade)(bool camera_rays, KPathFirstHit* records, bool shadow_walk, dim3 grid, dim3 block,
                     const KSceneView& scene, const KFrameParams& params, const KCamera& camera, kuint sample,
                     float4* band, const WavefrontScratch& scratch, unsigned long long* ray_counts,
                     unsigned* row_rays, cudaStream_t stream);
  void (*band_megakernel)(bool sparse, KPathFirstHit* first_hits, dim3 grid, dim3 block, const KSceneView& scene,
                          const KFrameParams& params, const KCamera& camera, float4* band,
                          unsigned long long* ray_counts, unsigned* row_rays, cudaStream_t stream);
};
extern const PathKernels path_kernels;
namespace dense {
extern const PathKernels path_kernels;
void set_texel_texture(cudaTextureObject_t texture);
}  // namespace dense
// The scene view holds device pointers (built on the host with k_scene_view, passed by value).
// ray_counts (closest, occlusion) and row_rays (one per band row, zeroed by the caller) may be null.
// first_hits (may be null; only for bands where every pixel traces paths): each pixel's record of its first
// sample's first surface, for launch_aux_from_first_hits. wave (may be null): scratch for the wavefront;
// given, the band renders as one, so the caller gives it only where k_wavefront_renders (path_state.h: lit
// paths that bounce, the sparse pattern too), and the megakernel renders the rest. Returns how many lanes
// recorded their `released` event (WaveLanes::release_before_end; 0: none, e.g. for the megakernel).
int launch_render_band(const KSceneView& scene, const KFrameParams& params, const KCamera& camera, float4* band,
                        unsigned long long* ray_counts, unsigned* row_rays, KPathFirstHit* first_hits,
                        const WavefrontScratch* wave, cudaStream_t stream);
// The band's auxiliary planes (kernel/aux_outputs.h) as the 32-byte KAuxTexel the host's BandBuffer
// keeps (halves for normal and albedo); history: the previous frame's transforms and joints (device
// pointers, kernel/aux_history.h).
void launch_aux_band(const KSceneView& scene, const KFrameParams& params, const KCamera& camera,
                     const KCamera& previous_camera, const KAuxHistory& history, KAuxTexel* band_aux,
                     cudaStream_t stream);
// The same planes from the band's first-hit records (K_AUX_PATH_FIRST_HIT), after the band's kernel.
void launch_aux_from_first_hits(const KSceneView& scene, const KFrameParams& params, const KCamera& camera,
                                const KCamera& previous_camera, const KAuxHistory& history,
                                const KPathFirstHit* first_hits, KAuxTexel* band_aux, cudaStream_t stream);
// Converts a rendered band (float4 per pixel) to RGB halves (3 x 16 bits per pixel) on the stream.
void launch_band_to_rgb16f(const float4* band, unsigned short* rgb, size_t pixels, cudaStream_t stream);
// Converts it to RGB9E5 words (kernel/band_pack.h), dithered by pixel (first_pixel + i over the whole
// frame) and frame.
void launch_band_to_rgb9e5(const float4* band, unsigned* packed, size_t pixels, unsigned first_pixel, unsigned frame,
                           cudaStream_t stream);

}  // namespace cohort::tracers
