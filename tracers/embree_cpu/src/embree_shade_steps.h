// The shading steps both tile renderers call (embree_shade_steps.cpp): declared apart from embree_tile_steps.h,
// whose static helpers the file that defines them does not use.
#pragma once

#include "embree_kernel.h"  // before the kernel headers: KTraceCtx

#include "cohort/kernel/emissive_sample.h"
#include "cohort/kernel/integrator.h"

namespace cohort::tracers::embree_tiles {

// The halves of k_path_segment (kernel/path_segment.h) and the stage's emissive samples, the same machine code
// in both renderers: compiled once per build (embree_shade_steps.cpp; the x86-64-v3 build's under other names),
// not inlined into each. Inlined, the compiler contracted different multiply-adds into FMAs in the two files
// (x86-64-v3), and inlined different kernel functions as each file's size let it, so their images differed in
// the last bits.
#ifndef COHORT_EMBREE_STEPS
#define COHORT_EMBREE_STEPS steps_baseline
#endif
namespace COHORT_EMBREE_STEPS {

int path_segment_lit(KTraceCtx* ctx, const KFrameParams* params, KPathState* s, const KHit* traced,
                     KPathFirstHit* first_hit, KShadowQueue* shadows, KVertexLight* vertex, KLitVertex* lit);

int path_vertex_end(KTraceCtx* ctx, const KFrameParams* params, KPathState* s, const KLitVertex* lit,
                    const KEmissiveSample* sampled, KShadowQueue* shadows, KVertexLight* vertex);

// The emissive samples of n lit vertices, their picks (embree_emissive_picks.h) then their points
// (embree_emissive_samples.h), eight at a time. picks: room for n.
void emissive_samples(const KSceneView* scene, int n, const KLitVertex* const* vertices, const KVec3* points,
                      const float* u_picks, const float* u1s, const float* u2s, KEmissivePick* picks,
                      KEmissiveSample* out);

}  // namespace COHORT_EMBREE_STEPS
}  // namespace cohort::tracers::embree_tiles
