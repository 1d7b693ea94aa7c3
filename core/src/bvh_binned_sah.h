// The binned-SAH builder shared by BLAS (boxes = triangles) and TLAS (boxes = instances).
#pragma once

#include <cstdint>
#include <vector>

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

struct BinnedBuild {
  std::vector<KBvhNode> nodes;
  std::vector<uint32_t> order;   // leaf order: order[i] is the input primitive at position i
};

// Builds over primitive boxes. Nodes: children of an interior node are adjacent and stored after it.
// Subtrees near the root are built on separate threads when `threads` > 1; the output is the same for
// any thread count. An empty input gives no nodes (traversal treats zero nodes as "nothing to hit").
BinnedBuild build_binned_sah(const std::vector<Box>& boxes, int bins, int max_leaf_size, int threads);

Box node_box(const KBvhNode& n);
void set_node_box(KBvhNode& n, const Box& b);

}  // namespace cohort::core::detail
