#include "cohort/core/bvh.h"

#include <stdexcept>
#include <string>

#include <tbb/parallel_for.h>

#include "bvh_box.h"
#include "bvh_embree_build.h"

namespace cohort::core {
namespace {

using detail::Box;

Box triangle_box(const std::vector<KVertex>& vertices, const KTriangle& t) {
  if (t.v0 >= vertices.size() || t.v1 >= vertices.size() || t.v2 >= vertices.size()) {
    throw std::out_of_range("BVH: triangle (" + std::to_string(t.v0) + ", " + std::to_string(t.v1) + ", " +
                            std::to_string(t.v2) + ") indexes past the " + std::to_string(vertices.size()) +
                            " vertices");
  }
  Box b;
  b.grow(vertices[t.v0].pos);
  b.grow(vertices[t.v1].pos);
  b.grow(vertices[t.v2].pos);
  return b;
}

Box instance_world_box(const KInstance& inst, const KBvhNode& blas_root) {
  Box world;
  const float* m = inst.object_to_world;
  for (int corner = 0; corner < 8; ++corner) {
    float p[3] = {corner & 1 ? blas_root.bmax[0] : blas_root.bmin[0], corner & 2 ? blas_root.bmax[1] : blas_root.bmin[1],
                  corner & 4 ? blas_root.bmax[2] : blas_root.bmin[2]};
    float w[3];
    for (int r = 0; r < 3; ++r) w[r] = m[r * 4 + 0] * p[0] + m[r * 4 + 1] * p[1] + m[r * 4 + 2] * p[2] + m[r * 4 + 3];
    world.grow(w);
  }
  return world;
}

// An empty box (NaN vertices, an instance of an empty BLAS) becomes a point at the origin: Embree needs
// ordered bounds, and the primitive still has its place in a leaf, where it is never hit.
RTCBuildPrimitive build_primitive(const Box& b, uint32_t id) {
  RTCBuildPrimitive p{};
  const bool empty = b.empty();
  p.lower_x = empty ? 0.0f : b.lo[0], p.lower_y = empty ? 0.0f : b.lo[1], p.lower_z = empty ? 0.0f : b.lo[2];
  p.upper_x = empty ? 0.0f : b.hi[0], p.upper_y = empty ? 0.0f : b.hi[1], p.upper_z = empty ? 0.0f : b.hi[2];
  p.geomID = 0;
  p.primID = id;
  return p;
}

// Refit in place: leaves get the union of primitive_box(j) over their primitives, inner nodes the union of
// their children. Children are always stored after their parent, so a reverse sweep sees children first.
template <typename PrimitiveBox>
void refit_bottom_up(std::vector<KBvhNode>& nodes, PrimitiveBox primitive_box) {
  for (size_t i = nodes.size(); i-- > 0;) {
    KBvhNode& n = nodes[i];
    Box b;
    if (n.count > 0) {
      for (uint32_t j = n.left_first; j < n.left_first + n.count; ++j) b.grow(primitive_box(j));
    } else {
      b = detail::node_box(nodes[n.left_first]);
      b.grow(detail::node_box(nodes[n.left_first + 1]));
    }
    detail::set_node_box(n, b);
  }
}

}  // namespace

BlasBuild build_blas(const std::vector<KVertex>& vertices, const std::vector<KTriangle>& triangles,
                     const BvhBuildOptions& options) {
  BlasBuild out;
  if (triangles.empty()) return out;
  std::vector<RTCBuildPrimitive> prims(triangles.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, triangles.size(), 16384), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t i = r.begin(); i < r.end(); ++i) prims[i] = build_primitive(triangle_box(vertices, triangles[i]), uint32_t(i));
  });
  detail::BuildSettings settings;
  settings.quality = detail::BuildQuality::binned_sah;
  settings.max_leaf_size = uint32_t(std::max(1, options.max_leaf_size));
  settings.threads = options.threads;
  detail::FlatBuild built = detail::build_flat_bvh(prims, settings);
  out.nodes = std::move(built.nodes);
  out.triangles.resize(triangles.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, built.order.size(), 16384), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t i = r.begin(); i < r.end(); ++i) out.triangles[i] = triangles[built.order[i]];
  });
  out.sah_cost = sah_cost(out.nodes);
  return out;
}

float refit_blas(const std::vector<KVertex>& vertices, BlasBuild& blas) {
  refit_bottom_up(blas.nodes, [&](uint32_t t) { return triangle_box(vertices, blas.triangles[t]); });
  blas.sah_cost = sah_cost(blas.nodes);
  return blas.sah_cost;
}

bool blas_needs_rebuild(float built_sah, float refit_sah, float threshold) {
  return built_sah > 0.0f && refit_sah > built_sah * threshold;
}

constexpr size_t kSerialTlasInstances = 4096;

std::vector<KBvhNode> build_tlas(std::vector<KInstance>& instances, const std::vector<KBvhNode>& blas_roots) {
  if (instances.empty()) return {};
  std::vector<RTCBuildPrimitive> prims(instances.size());
  std::vector<Box> boxes(instances.size());
  for (size_t i = 0; i < instances.size(); ++i) {
    const KInstance& inst = instances[i];
    if (inst.blas < blas_roots.size()) boxes[i] = instance_world_box(inst, blas_roots[inst.blas]);
    prims[i] = build_primitive(boxes[i], uint32_t(i));
  }
  // One instance per leaf keeps instance tests (a ray transform each) to the minimum. A TLAS is rebuilt
  // every frame: Embree's Morton builder takes about a third of the binned SAH's time for an SAH about
  // 7% higher (bench_bvh, docs/bvh.md), and the thread's build memory is kept for the next frame.
  detail::BuildSettings settings;
  settings.quality = detail::BuildQuality::morton;
  settings.max_leaf_size = 1;
  settings.keep_memory = true;
  // Below a few thousand instances the build is a fraction of a millisecond and handing its steps to
  // every core costs more than it saves (measured on 16 cores, docs/bvh.md): one thread builds it.
  if (instances.size() < kSerialTlasInstances) settings.threads = 1;
  detail::FlatBuild built = detail::build_flat_bvh(prims, settings);
  // An instance of an empty BLAS keeps an empty leaf box: rays never test it.
  for (KBvhNode& n : built.nodes)
    if (n.count > 0 && boxes[built.order[n.left_first]].empty()) detail::set_node_box(n, Box());
  std::vector<KInstance> ordered(instances.size());
  for (size_t i = 0; i < built.order.size(); ++i) ordered[i] = instances[built.order[i]];
  instances = std::move(ordered);
  return std::move(built.nodes);
}

float refit_tlas(const std::vector<KInstance>& instances, const std::vector<KBvhNode>& blas_roots,
                 std::vector<KBvhNode>& nodes) {
  refit_bottom_up(nodes, [&](uint32_t j) {
    const KInstance& inst = instances[j];
    return inst.blas < blas_roots.size() ? instance_world_box(inst, blas_roots[inst.blas]) : Box();
  });
  return sah_cost(nodes);
}

float sah_cost(const std::vector<KBvhNode>& nodes) {
  if (nodes.empty()) return 0.0f;
  const float root_area = detail::node_box(nodes[0]).half_area();
  if (root_area <= 0.0f) return float(nodes[0].count);
  float cost = 0.0f;
  for (const KBvhNode& n : nodes) {
    float a = detail::node_box(n).half_area() / root_area;
    cost += n.count > 0 ? a * float(n.count) : a;
  }
  return cost;
}

}  // namespace cohort::core
