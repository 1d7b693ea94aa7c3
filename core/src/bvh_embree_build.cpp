#include "bvh_embree_build.h"

#include <algorithm>
#include <new>
#include <stdexcept>
#include <string>

#include <tbb/parallel_invoke.h>
#include <tbb/task_arena.h>

namespace cohort::core::detail {
namespace {

// Embree's tree while it is being built, in memory from its thread-local allocator (freed with the
// RTCBVH). Counts of what lies below each node let the flattening place every subtree without a
// second pass: they are summed bottom-up in set_children, which Embree calls once a node's children
// are complete.
struct TempNode {
  uint32_t nodes_below = 0;   // flat nodes under this one, not counting itself
  uint32_t prims_below = 0;
  uint32_t leaf_prims = 0;    // 0: interior
};

struct TempInner : TempNode {
  TempNode* child[2] = {nullptr, nullptr};
  RTCBounds child_bounds[2] = {};
};

struct TempLeaf : TempNode {
  uint32_t* ids() { return reinterpret_cast<uint32_t*>(this + 1); }
};

// Subtrees over fewer primitives are flattened on the thread that reaches them.
constexpr uint32_t kParallelFlattenPrims = 16384;

// maxBranchingFactor is 2: every interior node has exactly two children.
void* create_node(RTCThreadLocalAllocator alloc, unsigned int, void*) {
  return new (rtcThreadLocalAlloc(alloc, sizeof(TempInner), 16)) TempInner;
}

void set_children(void* node, void** children, unsigned int child_count, void*) {
  auto* inner = static_cast<TempInner*>(node);
  for (unsigned i = 0; i < child_count && i < 2; ++i) {
    inner->child[i] = static_cast<TempNode*>(children[i]);
    inner->nodes_below += 1 + inner->child[i]->nodes_below;
    inner->prims_below += inner->child[i]->prims_below;
  }
}

void set_bounds(void* node, const RTCBounds** bounds, unsigned int child_count, void*) {
  auto* inner = static_cast<TempInner*>(node);
  for (unsigned i = 0; i < child_count && i < 2; ++i) inner->child_bounds[i] = *bounds[i];
}

void* create_leaf(RTCThreadLocalAllocator alloc, const RTCBuildPrimitive* prims, size_t count, void*) {
  auto* leaf = new (rtcThreadLocalAlloc(alloc, sizeof(TempLeaf) + count * sizeof(uint32_t), 16)) TempLeaf;
  leaf->prims_below = leaf->leaf_prims = uint32_t(count);
  for (size_t i = 0; i < count; ++i) leaf->ids()[i] = prims[i].primID;
  return leaf;
}

void set_box(KBvhNode& n, const RTCBounds& b) {
  n.bmin[0] = b.lower_x, n.bmin[1] = b.lower_y, n.bmin[2] = b.lower_z;
  n.bmax[0] = b.upper_x, n.bmax[1] = b.upper_y, n.bmax[2] = b.upper_z;
}

// Writes `node` at nodes[index]; its children go to child_base and child_base + 1, then the left
// child's subtree, then the right one's. Its primitives take order[prim_base, prim_base + prims_below).
void flatten(const TempNode* node, const RTCBounds& bounds, uint32_t index, uint32_t child_base, uint32_t prim_base,
             FlatBuild& out) {
  KBvhNode& n = out.nodes[index];
  set_box(n, bounds);
  if (node->leaf_prims > 0) {
    const auto* leaf = static_cast<const TempLeaf*>(node);
    n.left_first = prim_base;
    n.count = leaf->leaf_prims;
    std::copy(const_cast<TempLeaf*>(leaf)->ids(), const_cast<TempLeaf*>(leaf)->ids() + leaf->leaf_prims,
              out.order.begin() + prim_base);
    return;
  }
  const auto* inner = static_cast<const TempInner*>(node);
  n.left_first = child_base;
  n.count = 0;
  const TempNode* left = inner->child[0];
  const TempNode* right = inner->child[1];
  auto flatten_left = [&] {
    flatten(left, inner->child_bounds[0], child_base, child_base + 2, prim_base, out);
  };
  auto flatten_right = [&] {
    flatten(right, inner->child_bounds[1], child_base + 1, child_base + 2 + left->nodes_below,
            prim_base + left->prims_below, out);
  };
  if (node->prims_below >= kParallelFlattenPrims) {
    tbb::parallel_invoke(flatten_left, flatten_right);
  } else {
    flatten_left();
    flatten_right();
  }
}

RTCBounds union_of(const std::vector<RTCBuildPrimitive>& prims) {
  RTCBounds b{1e30f, 1e30f, 1e30f, 0.0f, -1e30f, -1e30f, -1e30f, 0.0f};
  for (const RTCBuildPrimitive& p : prims) {
    b.lower_x = std::min(b.lower_x, p.lower_x), b.upper_x = std::max(b.upper_x, p.upper_x);
    b.lower_y = std::min(b.lower_y, p.lower_y), b.upper_y = std::max(b.upper_y, p.upper_y);
    b.lower_z = std::min(b.lower_z, p.lower_z), b.upper_z = std::max(b.upper_z, p.upper_z);
  }
  return b;
}

RTCBounds union_of(const RTCBounds& a, const RTCBounds& b) {
  return RTCBounds{std::min(a.lower_x, b.lower_x), std::min(a.lower_y, b.lower_y), std::min(a.lower_z, b.lower_z),
                   0.0f, std::max(a.upper_x, b.upper_x), std::max(a.upper_y, b.upper_y),
                   std::max(a.upper_z, b.upper_z), 0.0f};
}

// One device for every build in the process: creating one costs far more than a small build.
RTCDevice builder_device() {
  struct Holder {
    RTCDevice device = rtcNewDevice(nullptr);
    ~Holder() {
      if (device) rtcReleaseDevice(device);
    }
  };
  static Holder holder;
  if (!holder.device) throw std::runtime_error("BVH build: Embree device creation failed");
  return holder.device;
}

// An RTCBVH kept per thread, for builds with keep_memory (one build at a time may use an RTCBVH).
struct ThreadBvh {
  RTCBVH bvh = nullptr;
  ~ThreadBvh() {
    if (bvh) rtcReleaseBVH(bvh);
  }
};

FlatBuild build_in_current_arena(std::vector<RTCBuildPrimitive>& primitives, const BuildSettings& settings) {
  RTCDevice device = builder_device();
  thread_local ThreadBvh kept;
  if (settings.keep_memory && !kept.bvh) kept.bvh = rtcNewBVH(device);
  RTCBVH bvh = settings.keep_memory ? kept.bvh : rtcNewBVH(device);
  auto release = [&] {
    if (!settings.keep_memory) rtcReleaseBVH(bvh);
  };
  RTCBuildArguments args = rtcDefaultBuildArguments();
  args.buildQuality = settings.quality == BuildQuality::morton ? RTC_BUILD_QUALITY_LOW : RTC_BUILD_QUALITY_MEDIUM;
  args.maxBranchingFactor = 2;
  args.maxDepth = K_BVH_MAX_DEPTH;   // Embree's root is level 1
  // Leaves of up to max_leaf_size, where Embree's SAH finds a leaf cheaper than a split. (Forcing every
  // split down to max_leaf_size, as minLeafSize = maxLeafSize would, builds ~10% faster but gives a
  // worse SAH than the former hand-written builder.)
  args.minLeafSize = 1;
  args.maxLeafSize = std::clamp<uint32_t>(settings.max_leaf_size, 1, RTC_BUILD_MAX_PRIMITIVES_PER_LEAF);
  // The same unit costs as sah_cost(), so Embree's leaf-or-split choices minimise what we report.
  args.traversalCost = 1.0f;
  args.intersectionCost = 1.0f;
  args.bvh = bvh;
  args.primitives = primitives.data();
  args.primitiveCount = primitives.size();
  args.primitiveArrayCapacity = primitives.size();   // no spatial splits: a triangle sits in one leaf
  args.createNode = create_node;
  args.setNodeChildren = set_children;
  args.setNodeBounds = set_bounds;
  args.createLeaf = create_leaf;
  const size_t count = primitives.size();
  const auto* root = static_cast<const TempNode*>(rtcBuildBVH(&args));
  if (!root) {
    const RTCError error = rtcGetDeviceError(device);
    release();
    throw std::runtime_error("BVH build over " + std::to_string(count) + " primitives failed (Embree error " +
                             std::to_string(int(error)) + ")");
  }
  FlatBuild out;
  out.nodes.resize(size_t(root->nodes_below) + 1);
  out.order.resize(count);
  const RTCBounds root_bounds =
      root->leaf_prims > 0 ? union_of(primitives)
                           : union_of(static_cast<const TempInner*>(root)->child_bounds[0],
                                      static_cast<const TempInner*>(root)->child_bounds[1]);
  flatten(root, root_bounds, 0, 1, 0, out);
  release();
  return out;
}

}  // namespace

FlatBuild build_flat_bvh(std::vector<RTCBuildPrimitive>& primitives, const BuildSettings& settings) {
  if (primitives.empty()) return {};
  if (settings.threads <= 0) return build_in_current_arena(primitives, settings);
  tbb::task_arena arena(settings.threads);
  return arena.execute([&] { return build_in_current_arena(primitives, settings); });
}

}  // namespace cohort::core::detail
