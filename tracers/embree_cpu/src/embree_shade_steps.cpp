// The shading steps both tile renderers call (embree_shade_steps.h), compiled once per build so that both run
// the same machine code: built twice like the renderers (CMakeLists.txt), the x86-64-v3 copy in namespace
// steps_x86_64_v3.
#include "embree_shade_steps.h"

#include "cohort/tracers/embree_emissive_picks.h"
#include "cohort/tracers/embree_emissive_samples.h"

namespace cohort::tracers::embree_tiles::COHORT_EMBREE_STEPS {

int path_segment_lit(KTraceCtx* ctx, const KFrameParams* params, KPathState* s, const KHit* traced,
                     KPathFirstHit* first_hit, KShadowQueue* shadows, KVertexLight* vertex, KLitVertex* lit) {
  return k_path_segment_lit(ctx, params, s, traced, first_hit, shadows, vertex, lit);
}

int path_vertex_end(KTraceCtx* ctx, const KFrameParams* params, KPathState* s, const KLitVertex* lit,
                    const KEmissiveSample* sampled, KShadowQueue* shadows, KVertexLight* vertex) {
  return k_path_vertex_end(ctx, params, s, lit, sampled, shadows, vertex);
}

void emissive_samples(const KSceneView* scene, int n, const KLitVertex* const* vertices, const KVec3* points,
                      const float* u_picks, const float* u1s, const float* u2s, KEmissivePick* picks,
                      KEmissiveSample* out) {
  embree_emissive::picks(scene, n, points, u_picks, picks);
  embree_emissive::samples(scene, n, vertices, picks, u1s, u2s, out);
}

}  // namespace cohort::tracers::embree_tiles::COHORT_EMBREE_STEPS
