/* What the auxiliary outputs need of the previous frame to find where a point was (aux_outputs.h):
 * instances' transforms and skinned characters' joints as they were. Plain pointers and a count, so that
 * a tracer can hold one beside its frame (device pointers on GPUs, host pointers on the CPU). */
#ifndef COHORT_KERNEL_AUX_HISTORY_H
#define COHORT_KERNEL_AUX_HISTORY_H
#include "skinning.h"

typedef struct KAuxHistory {
  KGLOBAL const float* object_to_world;   /* 12 floats per instance, or null */
  KGLOBAL const KSkin* skins;
  KGLOBAL const KSkinVertex* skin_vertices;
  KGLOBAL const KSkinWeight* skin_weights;
  KGLOBAL const KJoint* joints;           /* the previous frame's joint pool, or null */
  kuint skin_count;
} KAuxHistory;

#endif
