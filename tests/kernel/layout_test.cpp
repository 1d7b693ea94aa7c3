#include <cstddef>

#include <gtest/gtest.h>

#include "cohort/kernel/layout.h"
#include "cohort/kernel/vec.h"

// The layouts must not depend on the compiler: fields sit where the OpenCL and CUDA sides expect.
TEST(KernelLayout, FieldOffsetsArePacked) {
  EXPECT_EQ(offsetof(KBvhNode, left_first), 12u);
  EXPECT_EQ(offsetof(KBvhNode, count), 28u);
  EXPECT_EQ(offsetof(KInstance, blas), 96u);
  EXPECT_EQ(offsetof(KLight, plane_s), 112u);
  EXPECT_EQ(offsetof(KFrameParams, row_begin), 32u);
  EXPECT_EQ(offsetof(KFrameParams, light_sampling), 56u);
  EXPECT_EQ(offsetof(KFrameParams, light_node_count), 60u);
  EXPECT_EQ(offsetof(KFrameParams, emissive_count), 64u);
  EXPECT_EQ(offsetof(KFrameParams, emissive_samples), 68u);
  EXPECT_EQ(sizeof(KFrameParams), 96u);
  EXPECT_EQ(offsetof(KLightNode, left_first), 12u);
  EXPECT_EQ(offsetof(KLightNode, count), 28u);
  EXPECT_EQ(offsetof(KLightNode, power), 32u);
  EXPECT_EQ(offsetof(KLightNode, light_count), 36u);
  EXPECT_EQ(sizeof(KLightNode), 48u);
  EXPECT_EQ(offsetof(KEmissiveTriangle, instance), 12u);
  EXPECT_EQ(offsetof(KEmissiveTriangle, triangle), 28u);
  EXPECT_EQ(offsetof(KEmissiveTriangle, leaf), 44u);
  EXPECT_EQ(sizeof(KEmissiveTriangle), 48u);
}

TEST(KernelVec, CrossFollowsRightHandRule) {
  KVec3 z = v3_cross(v3(1, 0, 0), v3(0, 1, 0));
  EXPECT_FLOAT_EQ(z.x, 0.0f);
  EXPECT_FLOAT_EQ(z.y, 0.0f);
  EXPECT_FLOAT_EQ(z.z, 1.0f);
  EXPECT_FLOAT_EQ(v3_length(v3_normalize(v3(3, 4, 12))), 1.0f);
}
