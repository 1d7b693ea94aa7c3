/* Which surfaces are light sources for next-event estimation, in one place for the core (which lists
 * them, core/light_sampling.h) and the kernel (which samples them and weighs bounce hits on them). */
#ifndef COHORT_KERNEL_EMITTERS_H
#define COHORT_KERNEL_EMITTERS_H
#include "layout.h"
#include "vec.h"

/* An opaque emissive material's power per unit area (luminance of its emissive colour; the emissive map
 * is left out, so picking by power is an estimate and the pdf stays exact); 0 for everything else. */
KFN float k_emitter_power_density(KGLOBAL const KMaterial* m) {
  if (!(m->flags & K_MAT_EMISSIVE) || m->blend != K_BLEND_OPAQUE) return 0.0f;
  float l = v3_luminance(v3(m->emissive_color[0], m->emissive_color[1], m->emissive_color[2]));
  return l > 0.0f ? l : 0.0f;
}

/* Twice the area of a world-space triangle (the length of its edge cross product). */
KFN float k_triangle_double_area(KVec3 p0, KVec3 p1, KVec3 p2) {
  return v3_length(v3_cross(v3_sub(p1, p0), v3_sub(p2, p0)));
}

#endif
