/* Per-pixel random numbers: a PCG hash of (pixel, frame, sample) seeds a PCG-style LCG, so every
 * tracer draws exactly the same sequence for the same pixel and sample, whatever the device. */
#ifndef COHORT_KERNEL_RNG_H
#define COHORT_KERNEL_RNG_H
#include "portable.h"

typedef struct KRng { kuint state; } KRng;

KFN kuint k_pcg_hash(kuint v) {
  kuint state = v * 747796405u + 2891336453u;
  kuint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
  return (word >> 22u) ^ word;
}

KFN KRng k_rng_seed(kuint x, kuint y, kuint frame, kuint sample) {
  KRng r;
  r.state = k_pcg_hash(x ^ k_pcg_hash(y ^ k_pcg_hash(frame ^ k_pcg_hash(sample))));
  return r;
}

/* Uniform in [0, 1): the top 24 bits of the hashed state, so the value is exact in a float. */
KFN float k_rng_next(KRng* r) {
  r->state = r->state * 747796405u + 2891336453u;
  kuint word = ((r->state >> ((r->state >> 28u) + 4u)) ^ r->state) * 277803737u;
  word = (word >> 22u) ^ word;
  return (float)(word >> 8) * (1.0f / 16777216.0f);
}

#endif
