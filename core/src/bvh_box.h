// An axis-aligned box for the BVH builders and refit. Growing by a NaN coordinate leaves the box as it
// was, so a triangle with NaN vertices cannot poison its parents' boxes.
#pragma once

#include "cohort/kernel/layout.h"

namespace cohort::core::detail {

struct Box {
  float lo[3] = {1e30f, 1e30f, 1e30f};
  float hi[3] = {-1e30f, -1e30f, -1e30f};
  void grow(const float p[3]) {
    for (int a = 0; a < 3; ++a) {
      lo[a] = p[a] < lo[a] ? p[a] : lo[a];
      hi[a] = p[a] > hi[a] ? p[a] : hi[a];
    }
  }
  void grow(const Box& b) {
    if (!b.empty()) grow(b.lo), grow(b.hi);
  }
  bool empty() const { return lo[0] > hi[0]; }
  float half_area() const {
    if (empty()) return 0.0f;
    float d0 = hi[0] - lo[0], d1 = hi[1] - lo[1], d2 = hi[2] - lo[2];
    return d0 * d1 + d1 * d2 + d2 * d0;
  }
};

inline Box node_box(const KBvhNode& n) {
  Box b;
  for (int a = 0; a < 3; ++a) {
    b.lo[a] = n.bmin[a];
    b.hi[a] = n.bmax[a];
  }
  return b;
}

inline void set_node_box(KBvhNode& n, const Box& b) {
  for (int a = 0; a < 3; ++a) {
    n.bmin[a] = b.lo[a];
    n.bmax[a] = b.hi[a];
  }
}

}  // namespace cohort::core::detail
