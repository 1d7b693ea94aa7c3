/* Which way a frame's aux planes are made (KFrameParams.aux_outputs, layout.h), for the tracers' host code
 * and kernels alike. */
#ifndef COHORT_KERNEL_AUX_MODE_H
#define COHORT_KERNEL_AUX_MODE_H
#include "layout.h"
#include "path_pattern.h"

/* Whether a frame's aux planes come from its paths' first hits: asked for, every pixel traces paths (not
 * the sparse pattern of dynamic resolution, whose other pixels need planes too) and the mode reaches
 * surfaces (not the BVH or triangle views). Otherwise aux_outputs != 0 means centre rays. */
KFN int k_aux_from_paths(const KFrameParams* params) {
  return params->aux_outputs == K_AUX_PATH_FIRST_HIT &&
         (params->path_pixels == 0u || params->path_pixels >= K_PATH_PATTERN_PIXELS) && params->mode != K_MODE_BVH &&
         params->mode != K_MODE_TRIANGLES;
}

#endif
