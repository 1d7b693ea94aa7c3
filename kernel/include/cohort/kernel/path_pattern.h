/* Sparse paths for dynamic resolution (docs/denoising.md, "Dynamic resolution"): every pixel keeps its
 * unjittered primary ray and aux planes (aux_outputs.h) at the output resolution, but only path_pixels
 * of each 4x4 block trace paths (KFrameParams.path_pixels; 0 or 16: every pixel). A render scale s
 * traces about s^2 of the pixels, as a frame of s * width x s * height would.
 *
 * Which pixels: those whose rank in a 4x4 Bayer matrix, rotated by path_phase, is below path_pixels.
 * Bayer ranks spread any count evenly over the block (4 of 16 is a lattice of stride 2, 8 a
 * checkerboard), and the host advances path_phase by path_pixels a frame, so consecutive frames trace
 * disjoint sets and 16 / path_pixels frames cover every pixel once (temporal reprojection then gathers
 * full resolution). The reconstruction (upsample.h) asks the same predicate which pixels hold a path. */
#ifndef COHORT_KERNEL_PATH_PATTERN_H
#define COHORT_KERNEL_PATH_PATTERN_H
#include "portable.h"

#define K_PATH_PATTERN_PIXELS 16u /* pixels of the pattern's 4x4 block */

/* The 4x4 Bayer (ordered dither) rank of pixel (x, y): 0..15, each once per block. */
KFN kuint k_bayer4_rank(kuint x, kuint y) {
  /* 4 * bayer2(x, y) + bayer2(x / 2, y / 2), where bayer2 ranks (0,0) 0, (1,1) 1, (1,0) 2, (0,1) 3: the
   * first four ranks are a lattice of stride 2, the first eight a checkerboard. */
  kuint x0 = x & 1u, y0 = y & 1u, x1 = (x >> 1) & 1u, y1 = (y >> 1) & 1u;
  return 4u * (2u * (x0 ^ y0) + y0) + 2u * (x1 ^ y1) + y1;
}

/* Paths each traced pixel takes a frame: KFrameParams.spp, at least one. */
KFN kuint k_paths_per_pixel(kuint spp) { return spp > 0u ? spp : 1u; }

/* Whether pixel (x, y) traces paths this frame. */
KFN int k_pixel_traces_path(kuint path_pixels, kuint path_phase, kuint x, kuint y) {
  if (path_pixels == 0u || path_pixels >= K_PATH_PATTERN_PIXELS) return 1;
  kuint rank = (k_bayer4_rank(x, y) + K_PATH_PATTERN_PIXELS - (path_phase % K_PATH_PATTERN_PIXELS)) %
               K_PATH_PATTERN_PIXELS;
  return rank < path_pixels;
}

#endif
