// The Embree tracer's unit of work: a tile of the band, rendered one of two ways. Per sample the tile
// traces all its camera rays ahead in coherent 8-ray packets, then
// - render_tile: runs the shared integrator (k_trace_path) per pixel from those hits; shadow and bounce
//   rays are traced one by one as the integrator asks for them;
// - render_wave_tile (the default): runs the tile as a wavefront of the GPU tracers' stages
//   (kernel/wave_shade.h, wave_walk.h): every path's segment shaded, then all the tile's shadow rays
//   traced together in packets, then the live paths' bounce rays in packets, until no path is live.
// Both draw the same image. Everything a tile needs lives in a per-thread Arena, so rendering allocates
// nothing per tile or ray.
#pragma once

#include <embree3/rtcore.h>

#include <cstdint>

#include "cohort/core/band_buffer.h"
#include "cohort/kernel/rng.h"
#include "cohort/kernel/aux_history.h"
#include "cohort/kernel/emissive_tree.h"
#include "cohort/kernel/lit_vertex.h"
#include "cohort/kernel/path_state.h"
#include "cohort/kernel/shadow_ray.h"
#include "embree_kernel.h"

namespace cohort::tracers::embree_tiles {

constexpr int kTileWidth = 32;
constexpr int kTileHeight = 4;
constexpr int kTilePixels = kTileWidth * kTileHeight;
constexpr int kPacketSize = 8;  // rtcIntersect8: AVX2's native width
constexpr int kTilePackets = kTilePixels / kPacketSize;

// What every tile of one band shares.
struct Frame {
  KFrameParams params;
  KCamera camera;
  KCamera previous_camera;
  KAuxHistory history;  // the previous frame's transforms and joints (host pointers), for motion vectors
  bool write_aux;
  embree_kernel::TraceCtx base;
  core::BandBuffer* target;  // null: render without storing (recording rays)
  // The wavefront's shadow-ray slots a vertex gets (k_shadow_queue_slots; 0: past K_SHADOW_QUEUE_MAX, each
  // vertex's shadow rays traced one by one as it shades).
  kuint shadow_slots;
  // The wavefront's rays per packet: 16 where Embree traces 16-ray packets natively (AVX-512), else 8.
  int packet_width;
};

struct Tile {
  int x0, y0, x1, y1;  // [x0, x1) x [y0, y1), at most kTileWidth x kTileHeight
};

struct Arena {
  RTCRayHit8 packets[kTilePackets];
  KHit hits[kTilePixels];
  int found[kTilePixels];
  KVec3 dirs[kTilePixels];
  KRng rngs[kTilePixels];
  KVec3 sums[kTilePixels];
  int traced[kTilePixels];  // the tile's pixels that trace paths (kernel/path_pattern.h), packed
  float rgba[kTileWidth * 4];
  KAux aux[kTileWidth];
  KPathFirstHit first_hits[kTilePixels];  // K_AUX_PATH_FIRST_HIT: the first sample's first surfaces

  // The wavefront's paths between their stages, as the GPU tracers keep them in device memory
  // (kernel/path_state.h), indexed by the pixel's place in the tile.
  struct Wave {
    KPathState states[kTilePixels];
    KHit hits[kTilePixels];        // each shaded path's walked ray's hit (instance K_NONE: a miss)
    kuint active[kTilePixels];     // K_WAVE_LIVE, K_WAVE_SHADOWS_OUT
    KVertexLight vertices[kTilePixels];
    KShadowRay shadow_rays[K_SHADOW_QUEUE_MAX * kTilePixels];  // slot k of pixel p at [k * kTilePixels + p]
    kuint visible[kTilePixels];    // per pixel, bit k: slot k's shadow ray is unblocked
    float band[kTilePixels * 4];   // the pixels' sums of samples (k_wave_finish_sample), RGBA
    int pixels[kTilePixels];       // the paths a stage traces rays for
    uint16_t shadows[K_SHADOW_QUEUE_MAX * kTilePixels];  // the shadow rays to trace: pixel * 8 + slot
    // The opaque vertices a shade stage lit, waiting for their emissive picks (all of the stage's at once):
    // each as k_path_vertex_end takes it and the rays in its shadow queue; lit_paths: their places in the
    // tile's traced pixels, in order; then the picks' points, numbers and results, in the same order for those
    // of them that take an emissive sample.
    KLitVertex lit[kTilePixels];
    kuint queued[kTilePixels];
    int lit_paths[kTilePixels];
    KVec3 pick_points[kTilePixels];
    float pick_numbers[kTilePixels];
    KEmissivePick picks[kTilePixels];
  } wave;
};

// Renders the tile into frame.target and adds the rays traced per row to row_rays[y - tile.y0].
// log: null, or where every ray is recorded (the caller runs tiles one at a time then).
void render_tile(const Frame& frame, const Tile& tile, Arena& arena, embree_kernel::RayLog* log,
                 uint64_t row_rays[kTileHeight]);
// The same, compiled for x86-64-v3 (AVX2, FMA): faster shading where the CPU has it (has_x86_64_v3).
void render_tile_x86_64_v3(const Frame& frame, const Tile& tile, Arena& arena, embree_kernel::RayLog* log,
                           uint64_t row_rays[kTileHeight]);
// The same image as render_tile, rendered as a wavefront (embree_wave_tile.cpp); any mode but K_MODE_BVH.
void render_wave_tile(const Frame& frame, const Tile& tile, Arena& arena, embree_kernel::RayLog* log,
                      uint64_t row_rays[kTileHeight]);
void render_wave_tile_x86_64_v3(const Frame& frame, const Tile& tile, Arena& arena, embree_kernel::RayLog* log,
                                uint64_t row_rays[kTileHeight]);
// Whether this build has render_tile_x86_64_v3 and this CPU can run it.
bool has_x86_64_v3();

}  // namespace cohort::tracers::embree_tiles
