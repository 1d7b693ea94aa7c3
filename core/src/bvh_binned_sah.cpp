#include "bvh_binned_sah.h"

#include <algorithm>
#include <future>
#include <thread>

namespace cohort::core::detail {
namespace {

constexpr int kMaxBins = 64;
constexpr uint32_t kParallelMinPrims = 4096;   // smaller subtrees are not worth a thread

struct Input {
  const std::vector<Box>& boxes;
  std::vector<float> centroids;   // 3 per primitive
  int bins;
  uint32_t max_leaf;
};

struct Split {
  int axis = -1;
  int bin = 0;          // primitives in bins [0, bin] go left
  float cost = 1e30f;
  float lo = 0, scale = 0;
};

Split find_split(const Input& in, const uint32_t* prims, uint32_t count, const Box& centroid_bounds) {
  Split best;
  for (int axis = 0; axis < 3; ++axis) {
    float lo = centroid_bounds.lo[axis], hi = centroid_bounds.hi[axis];
    if (!(hi > lo)) continue;
    float scale = float(in.bins) / (hi - lo);
    Box bin_box[kMaxBins];
    uint32_t bin_count[kMaxBins] = {};
    for (uint32_t i = 0; i < count; ++i) {
      uint32_t p = prims[i];
      int b = std::min(in.bins - 1, int((in.centroids[p * 3 + axis] - lo) * scale));
      bin_box[b].grow(in.boxes[p]);
      ++bin_count[b];
    }
    // Sweep from the right to get the cost of every right side, then from the left.
    float right_area[kMaxBins];
    uint32_t right_count[kMaxBins];
    Box acc;
    uint32_t n = 0;
    for (int b = in.bins - 1; b > 0; --b) {
      acc.grow(bin_box[b]);
      n += bin_count[b];
      right_area[b] = acc.half_area();
      right_count[b] = n;
    }
    acc = Box();
    n = 0;
    for (int b = 0; b < in.bins - 1; ++b) {
      acc.grow(bin_box[b]);
      n += bin_count[b];
      if (n == 0 || right_count[b + 1] == 0) continue;
      float cost = float(n) * acc.half_area() + float(right_count[b + 1]) * right_area[b + 1];
      if (cost < best.cost) best = Split{axis, b, cost, lo, scale};
    }
  }
  return best;
}

// Builds the subtree whose root is nodes[root] over prims [first, first + count).
void build_subtree(const Input& in, std::vector<uint32_t>& order, std::vector<KBvhNode>& nodes, uint32_t root,
                   uint32_t first, uint32_t count, int parallel_depth) {
  Box bounds, centroid_bounds;
  for (uint32_t i = first; i < first + count; ++i) {
    bounds.grow(in.boxes[order[i]]);
    centroid_bounds.grow(&in.centroids[order[i] * 3]);
  }
  set_node_box(nodes[root], bounds);
  if (count <= in.max_leaf) {
    nodes[root].left_first = first;
    nodes[root].count = count;
    return;
  }
  uint32_t* prims = order.data() + first;
  Split split = find_split(in, prims, count, centroid_bounds);
  uint32_t left_count;
  if (split.axis < 0) {
    // All centroids coincide: any division is as good; halve so leaves stay small.
    left_count = count / 2;
  } else {
    uint32_t* mid = std::partition(prims, prims + count, [&](uint32_t p) {
      int b = std::min(in.bins - 1, int((in.centroids[p * 3 + split.axis] - split.lo) * split.scale));
      return b <= split.bin;
    });
    left_count = uint32_t(mid - prims);
  }
  const uint32_t left = uint32_t(nodes.size());
  nodes.resize(nodes.size() + 2);
  nodes[root].left_first = left;
  nodes[root].count = 0;

  const uint32_t right_count = count - left_count;
  if (parallel_depth > 0 && right_count >= kParallelMinPrims) {
    // The right subtree goes into its own array on another thread, then is appended with its child
    // indices shifted. The serial path below produces the identical layout, so threads never change
    // the result.
    std::vector<KBvhNode> right_nodes(1);
    auto right_job = std::async(std::launch::async, [&] {
      build_subtree(in, order, right_nodes, 0, first + left_count, right_count, parallel_depth - 1);
    });
    build_subtree(in, order, nodes, left, first, left_count, parallel_depth - 1);
    right_job.get();
    const uint32_t base = uint32_t(nodes.size()) - 1;   // right_nodes[i >= 1] lands at base + i
    for (KBvhNode& n : right_nodes)
      if (n.count == 0) n.left_first += base;
    nodes[left + 1] = right_nodes[0];
    nodes.insert(nodes.end(), right_nodes.begin() + 1, right_nodes.end());
    return;
  }
  build_subtree(in, order, nodes, left, first, left_count, parallel_depth);
  build_subtree(in, order, nodes, left + 1, first + left_count, right_count, parallel_depth);
}

}  // namespace

Box node_box(const KBvhNode& n) {
  Box b;
  for (int a = 0; a < 3; ++a) {
    b.lo[a] = n.bmin[a];
    b.hi[a] = n.bmax[a];
  }
  return b;
}

void set_node_box(KBvhNode& n, const Box& b) {
  for (int a = 0; a < 3; ++a) {
    n.bmin[a] = b.lo[a];
    n.bmax[a] = b.hi[a];
  }
}

BinnedBuild build_binned_sah(const std::vector<Box>& boxes, int bins, int max_leaf_size, int threads) {
  BinnedBuild out;
  if (boxes.empty()) return out;
  Input in{boxes, std::vector<float>(boxes.size() * 3), std::clamp(bins, 2, kMaxBins),
           uint32_t(std::max(1, max_leaf_size))};
  for (size_t i = 0; i < boxes.size(); ++i)
    for (int a = 0; a < 3; ++a) in.centroids[i * 3 + a] = 0.5f * (boxes[i].lo[a] + boxes[i].hi[a]);
  out.order.resize(boxes.size());
  for (uint32_t i = 0; i < out.order.size(); ++i) out.order[i] = i;
  out.nodes.reserve(2 * boxes.size());
  out.nodes.resize(1);
  if (threads <= 0) threads = int(std::max(1u, std::thread::hardware_concurrency()));
  int parallel_depth = 0;
  while ((1 << parallel_depth) < threads) ++parallel_depth;
  if (threads > 1) parallel_depth += 2;   // a few more subtrees than threads to even out imbalance
  build_subtree(in, out.order, out.nodes, 0, 0, uint32_t(boxes.size()), parallel_depth);
  return out;
}

}  // namespace cohort::core::detail
