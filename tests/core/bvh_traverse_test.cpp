// kernel/bvh_traverse.h compiled as C++: closest/any/shadow queries over BLAS + TLAS from core/bvh.h
// against brute force over every instance's triangles (same triangle test, so t must match exactly).
// bvh_traverse_edges_test.cpp compiles this file again with K_BVH_TRIANGLE_EDGES (the CUDA build's
// leaves), as suite BvhTraverseEdges.
#ifndef BVH_TRAVERSE_SUITE
#define BVH_TRAVERSE_SUITE BvhTraverse
#endif
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "cohort/core/bvh.h"
#include "cohort/kernel/vec.h"

namespace {
// Test materials: 0 opaque, 1 tinted glass (lets some light through), 2 pass-through (invisible).
struct TestMaterials {
  const std::vector<KTriangle>* triangles;
};
KVec3 test_transmittance(const TestMaterials* m, kuint triangle);
float test_passes(const TestMaterials* m, kuint triangle);
}  // namespace

#define K_BVH_CONTEXT const TestMaterials*
#define K_BVH_HIT_PASSES(ctx, instance, triangle, u, v, shadow_ray) test_passes(ctx, triangle)
#define K_BVH_SHADOW_TRANSMITTANCE(ctx, instance, triangle, u, v) test_transmittance(ctx, triangle)
#include "cohort/kernel/bvh_traverse.h"

using namespace cohort::core;

namespace {

KVec3 test_transmittance(const TestMaterials* m, kuint triangle) {
  switch ((*m->triangles)[triangle].material) {
    case 1: return v3(0.5f, 0.25f, 0.75f);
    case 2: return v3s(1.0f);
    default: return v3s(0.0f);
  }
}
float test_passes(const TestMaterials* m, kuint triangle) {
  return (*m->triangles)[triangle].material == 2 ? 1.0f : 0.0f;
}

KVertex vtx(float x, float y, float z) {
  KVertex v{};
  v.pos[0] = x, v.pos[1] = y, v.pos[2] = z;
  return v;
}

KBvhNode empty_root() {
  KBvhNode n{};
  for (int a = 0; a < 3; ++a) n.bmin[a] = 1e30f, n.bmax[a] = -1e30f;
  return n;
}

struct Mesh {
  std::vector<KVertex> vertices;
  std::vector<KTriangle> triangles;   // indices local to `vertices`
};

Mesh random_soup(int count, uint32_t seed, float extent, float size, int material_kinds = 1) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> pos(-extent, extent), off(-size, size);
  Mesh m;
  for (int i = 0; i < count; ++i) {
    float c[3] = {pos(rng), pos(rng), pos(rng)};
    for (int k = 0; k < 3; ++k) {
      KVertex v{};
      for (int a = 0; a < 3; ++a) v.pos[a] = c[a] + off(rng);
      m.vertices.push_back(v);
    }
    m.triangles.push_back({kuint(3 * i), kuint(3 * i + 1), kuint(3 * i + 2), kuint(i % material_kinds)});
  }
  return m;
}

// A flat copy of everything the kernel reads, as a tracer would upload it.
struct FlatScene {
  std::vector<KVertex> vertices;
  std::vector<KTriangle> triangles;
  std::vector<KBvhNode> blas_nodes;
  std::vector<KBlas> blases;
  std::vector<KBvhNode> blas_roots;
  std::vector<KInstance> instances;
  std::vector<KBvhNode> tlas;
  TestMaterials materials{&triangles};

  kuint add_mesh(const Mesh& mesh) {
    BlasBuild b = build_blas(mesh.vertices, mesh.triangles);
    KBlas blas{kuint(blas_nodes.size()), kuint(b.nodes.size()), kuint(triangles.size()), kuint(b.triangles.size())};
    const kuint vertex_offset = kuint(vertices.size());
    vertices.insert(vertices.end(), mesh.vertices.begin(), mesh.vertices.end());
    for (KTriangle t : b.triangles) {
      t.v0 += vertex_offset, t.v1 += vertex_offset, t.v2 += vertex_offset;
      triangles.push_back(t);
    }
    blas_nodes.insert(blas_nodes.end(), b.nodes.begin(), b.nodes.end());
    blas_roots.push_back(b.nodes.empty() ? empty_root() : b.nodes[0]);
    blases.push_back(blas);
    return kuint(blases.size() - 1);
  }

  void add_instance(kuint blas, const float object_to_world[12], kuint mask) {
    KInstance inst{};
    std::memcpy(inst.object_to_world, object_to_world, sizeof inst.object_to_world);
    invert_affine(object_to_world, inst.world_to_object);
    inst.blas = blas;
    inst.mask = mask;
    inst.entity = kuint(instances.size());
    inst.material_override = K_NONE;
    instances.push_back(inst);
  }

  std::vector<KTriangleEdges> triangle_edges;

  void build() {
    tlas = build_tlas(instances, blas_roots);
    triangle_edges.resize(triangles.size());
    for (size_t t = 0; t < triangles.size(); ++t) k_triangle_edges_write(&triangle_edges[t], vertices.data(), triangles[t]);
  }

  KSceneRef ref() const {
#ifdef K_BVH_TRIANGLE_EDGES
    return KSceneRef{triangle_edges.data(), blas_nodes.data(), blases.data(), instances.data(),
                     tlas.data(),           kuint(instances.size()), kuint(tlas.size())};
#else
    return KSceneRef{vertices.data(), triangles.data(), blas_nodes.data(), blases.data(), instances.data(),
                     tlas.data(),     kuint(instances.size()), kuint(tlas.size())};
#endif
  }

  static void invert_affine(const float* m, float* inv) {
    const float a = m[0], b = m[1], c = m[2], d = m[4], e = m[5], f = m[6], g = m[8], h = m[9], i = m[10];
    const float det = a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g);
    const float r[9] = {(e * i - f * h) / det, (c * h - b * i) / det, (b * f - c * e) / det,
                        (f * g - d * i) / det, (a * i - c * g) / det, (c * d - a * f) / det,
                        (d * h - e * g) / det, (b * g - a * h) / det, (a * e - b * d) / det};
    for (int row = 0; row < 3; ++row) {
      for (int col = 0; col < 3; ++col) inv[row * 4 + col] = r[row * 3 + col];
      inv[row * 4 + 3] = -(r[row * 3] * m[3] + r[row * 3 + 1] * m[7] + r[row * 3 + 2] * m[11]);
    }
  }
};

const float kIdentity[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};

// Brute force over every instance and triangle, with the kernel's own ray transform and triangle test.
struct Reference {
  float t = 0;
  kuint instance = K_NONE, triangle = K_NONE;
  bool any = false;
  KVec3 transmittance = v3s(1.0f);
};

Reference brute_force(const FlatScene& s, KVec3 o, KVec3 d, float tmin, float tmax, kuint mask) {
  const KSceneRef scene = s.ref();
  Reference ref;
  ref.t = tmax;
  for (kuint i = 0; i < s.instances.size(); ++i) {
    const KInstance& inst = s.instances[i];
    if ((inst.mask & mask) == 0) continue;
    KVec3 lo = xform_point_g(inst.world_to_object, o), ld = xform_vector_g(inst.world_to_object, d);
    const KBlas& b = s.blases[inst.blas];
    for (kuint tri = b.tri_offset; tri < b.tri_offset + b.tri_count; ++tri) {
      float t, u, v;
      if (!k_bvh_hit_triangle(scene, tri, lo, ld, tmin, tmax, &t, &u, &v)) continue;
      ref.transmittance = v3_mul(ref.transmittance, test_transmittance(&s.materials, tri));
      if (test_passes(&s.materials, tri) > 0.0f) continue;
      ref.any = true;
      if (t < ref.t) ref.t = t, ref.instance = i, ref.triangle = tri;
    }
  }
  return ref;
}

struct TestRay {
  KVec3 o, d;
};

TestRay random_ray(std::mt19937& rng, float extent) {
  std::uniform_real_distribution<float> pos(-extent, extent), dir(-1.0f, 1.0f);
  TestRay r{v3(pos(rng), pos(rng), pos(rng)), v3(dir(rng), dir(rng), dir(rng))};
  r.d = v3_normalize(r.d);
  return r;
}

// Closest and any-hit queries agree with brute force; returns how many rays hit.
int expect_matches_brute_force(const FlatScene& s, int rays, uint32_t seed, float extent, kuint mask) {
  std::mt19937 rng(seed);
  int hits = 0;
  for (int i = 0; i < rays; ++i) {
    TestRay r = random_ray(rng, extent);
    const float tmax = (i % 3 == 0) ? extent * 0.5f : 1e30f;
    Reference ref = brute_force(s, r.o, r.d, 1e-4f, tmax, mask);
    KHit hit;
    int found = k_bvh_closest(s.ref(), &s.materials, r.o, r.d, 1e-4f, tmax, mask, &hit);
    EXPECT_EQ(found, ref.instance != K_NONE ? 1 : 0) << "ray " << i;
    if (found && ref.instance != K_NONE) {
      ++hits;
      EXPECT_EQ(hit.t, ref.t) << "ray " << i;
      if (hit.t == ref.t && (hit.instance != ref.instance || hit.triangle != ref.triangle)) {
        // Only a tie at exactly the same distance may pick another triangle.
        KVec3 lo = xform_point_g(s.instances[hit.instance].world_to_object, r.o);
        KVec3 ld = xform_vector_g(s.instances[hit.instance].world_to_object, r.d);
        float t, u, v;
        EXPECT_TRUE(k_bvh_hit_triangle(s.ref(), hit.triangle, lo, ld, 1e-4f, 1e30f, &t, &u, &v) && t == ref.t);
      }
      EXPECT_GT(hit.cost, 0u);
    }
    EXPECT_EQ(k_bvh_any(s.ref(), &s.materials, r.o, r.d, 1e-4f, tmax, mask), ref.any ? 1 : 0) << "ray " << i;
  }
  return hits;
}

float random_transform(std::mt19937& rng, float* m, float spread) {
  std::uniform_real_distribution<float> pos(-spread, spread), ang(0.0f, 6.2832f), scale(0.3f, 3.0f);
  // Rz(a) * Rx(b) * diag(sx, sy, sz) + t: rotation, non-uniform scale, translation.
  float a = ang(rng), b = ang(rng), sx = scale(rng), sy = scale(rng), sz = scale(rng);
  float ca = std::cos(a), sa = std::sin(a), cb = std::cos(b), sb = std::sin(b);
  float r[9] = {ca, -sa * cb, sa * sb, sa, ca * cb, -ca * sb, 0, sb, cb};
  for (int row = 0; row < 3; ++row) {
    m[row * 4 + 0] = r[row * 3 + 0] * sx;
    m[row * 4 + 1] = r[row * 3 + 1] * sy;
    m[row * 4 + 2] = r[row * 3 + 2] * sz;
    m[row * 4 + 3] = pos(rng);
  }
  return std::max(sx, std::max(sy, sz));
}

}  // namespace

TEST(BVH_TRAVERSE_SUITE, RandomSoupMatchesBruteForce) {
  FlatScene s;
  s.add_instance(s.add_mesh(random_soup(3000, 7, 100.0f, 4.0f)), kIdentity, K_MASK_PRIMARY | K_MASK_SHADOW);
  s.build();
  EXPECT_GT(expect_matches_brute_force(s, 3000, 11, 120.0f, K_MASK_PRIMARY), 300);
}

TEST(BVH_TRAVERSE_SUITE, InstancesWithRotationScaleTranslationAndMasks) {
  FlatScene s;
  kuint meshes[3] = {s.add_mesh(random_soup(400, 1, 10.0f, 2.0f)), s.add_mesh(random_soup(50, 2, 3.0f, 1.0f)),
                     s.add_mesh(random_soup(1500, 3, 20.0f, 1.5f))};
  std::mt19937 rng(5);
  for (int i = 0; i < 120; ++i) {
    float m[12];
    random_transform(rng, m, 150.0f);
    // Every fifth instance is a noShadows entity; every seventh is a shadow-only caster.
    kuint mask = i % 5 == 0 ? K_MASK_PRIMARY : i % 7 == 0 ? K_MASK_SHADOW : K_MASK_PRIMARY | K_MASK_SHADOW;
    s.add_instance(meshes[i % 3], m, mask);
  }
  s.build();
  EXPECT_GT(expect_matches_brute_force(s, 500, 21, 160.0f, K_MASK_PRIMARY), 50);
  EXPECT_GT(expect_matches_brute_force(s, 500, 22, 160.0f, K_MASK_SHADOW), 50);
}

TEST(BVH_TRAVERSE_SUITE, ShadowRaysIgnoreNoShadowInstances) {
  FlatScene s;
  kuint wall = s.add_mesh(Mesh{{vtx(-1, -1, 0), vtx(1, -1, 0), vtx(0, 1, 0)}, {{0, 1, 2, 0}}});
  s.add_instance(wall, kIdentity, K_MASK_PRIMARY);  // noShadows: visible, casts no shadow
  s.build();
  const KVec3 o = v3(0, 0, -5), d = v3(0, 0, 1);
  KHit hit;
  EXPECT_TRUE(k_bvh_closest(s.ref(), &s.materials, o, d, 0.0f, 100.0f, K_MASK_PRIMARY, &hit));
  EXPECT_FLOAT_EQ(hit.t, 5.0f);
  EXPECT_FALSE(k_bvh_any(s.ref(), &s.materials, o, d, 0.0f, 100.0f, K_MASK_SHADOW));
  KVec3 T;
  EXPECT_FALSE(k_bvh_shadow(s.ref(), &s.materials, o, d, 0.0f, 100.0f, K_MASK_SHADOW, &T));
  EXPECT_EQ(T.x, 1.0f);
}

TEST(BVH_TRAVERSE_SUITE, ShadowTransmittanceIsTheProductOverSurfaces) {
  // Materials 0 (opaque), 1 (tinted) and 2 (pass-through) mixed; the transmittance must equal the
  // product over every surface brute force finds, and an opaque surface must stop the query.
  FlatScene s;
  kuint mesh = s.add_mesh(random_soup(2000, 13, 60.0f, 6.0f, 3));
  s.add_instance(mesh, kIdentity, K_MASK_PRIMARY | K_MASK_SHADOW);
  float m[12] = {0.5f, 0, 0, 40, 0, 0.5f, 0, 0, 0, 0, 0.5f, 0};
  s.add_instance(mesh, m, K_MASK_PRIMARY | K_MASK_SHADOW);
  s.build();
  std::mt19937 rng(17);
  int partial = 0, blocked = 0;
  for (int i = 0; i < 2000; ++i) {
    TestRay r = random_ray(rng, 70.0f);
    const float tmax = 20.0f + float(i % 50);
    Reference ref = brute_force(s, r.o, r.d, 1e-4f, tmax, K_MASK_SHADOW);
    KVec3 T;
    int fully_blocked = k_bvh_shadow(s.ref(), &s.materials, r.o, r.d, 1e-4f, tmax, K_MASK_SHADOW, &T);
    EXPECT_EQ(fully_blocked, v3_max_component(ref.transmittance) <= 0.0f ? 1 : 0) << "ray " << i;
    EXPECT_NEAR(T.x, ref.transmittance.x, 1e-5f) << "ray " << i;
    EXPECT_NEAR(T.y, ref.transmittance.y, 1e-5f) << "ray " << i;
    EXPECT_NEAR(T.z, ref.transmittance.z, 1e-5f) << "ray " << i;
    blocked += fully_blocked;
    partial += !fully_blocked && T.x < 1.0f;
  }
  EXPECT_GT(blocked, 50);
  EXPECT_GT(partial, 50) << "the test must see rays through tinted surfaces";
}

TEST(BVH_TRAVERSE_SUITE, RefitAfterDeformationStaysCorrect) {
  Mesh mesh = random_soup(2500, 31, 80.0f, 3.0f);
  FlatScene s;
  s.add_instance(s.add_mesh(mesh), kIdentity, K_MASK_PRIMARY);
  // Deform the flat copy (the BLAS triangles index it) and refit the uploaded nodes in place.
  std::mt19937 rng(4);
  std::uniform_real_distribution<float> wobble(-15.0f, 15.0f);
  for (KVertex& v : s.vertices)
    for (float& c : v.pos) c += wobble(rng);
  BlasBuild blas;
  blas.nodes = s.blas_nodes;
  blas.triangles = s.triangles;
  blas.sah_cost = sah_cost(blas.nodes);
  const float built = blas.sah_cost;
  const float refit = refit_blas(s.vertices, blas);
  s.blas_nodes = blas.nodes;
  s.blas_roots[0] = blas.nodes[0];
  s.build();
  EXPECT_GT(refit, built);
  EXPECT_EQ(blas_needs_rebuild(built, refit, 1.01f), refit > built * 1.01f);
  EXPECT_GT(expect_matches_brute_force(s, 1500, 41, 100.0f, K_MASK_PRIMARY), 100);
}

TEST(BVH_TRAVERSE_SUITE, EmptyAndSingleInstanceScenes) {
  FlatScene empty;
  empty.build();
  EXPECT_TRUE(empty.tlas.empty());
  KHit hit;
  EXPECT_FALSE(k_bvh_closest(empty.ref(), &empty.materials, v3(0, 0, 0), v3(0, 0, 1), 0.0f, 1e30f, ~0u, &hit));
  EXPECT_EQ(hit.instance, K_NONE);
  EXPECT_FALSE(k_bvh_any(empty.ref(), &empty.materials, v3(0, 0, 0), v3(0, 0, 1), 0.0f, 1e30f, ~0u));

  FlatScene one;
  float m[12] = {2, 0, 0, 10, 0, 2, 0, 0, 0, 0, 2, 0};
  one.add_instance(one.add_mesh(random_soup(300, 3, 10.0f, 2.0f)), m, K_MASK_PRIMARY);
  one.build();
  ASSERT_EQ(one.tlas.size(), 1u);
  EXPECT_EQ(one.tlas[0].count, 1u);
  EXPECT_GT(expect_matches_brute_force(one, 1000, 9, 40.0f, K_MASK_PRIMARY), 50);

  // An instance of an empty BLAS next to a real one: never hit, never crashes.
  FlatScene with_empty = one;
  with_empty.add_instance(with_empty.add_mesh(Mesh{}), kIdentity, K_MASK_PRIMARY);
  with_empty.instances = one.instances;
  with_empty.add_instance(kuint(with_empty.blases.size() - 1), kIdentity, K_MASK_PRIMARY);
  with_empty.build();
  expect_matches_brute_force(with_empty, 300, 10, 40.0f, K_MASK_PRIMARY);
}

TEST(BVH_TRAVERSE_SUITE, PassThroughSurfacesAreSkippedByClosestHit) {
  FlatScene s;
  // Two parallel quads' worth of triangles: the nearer is pass-through (material 2).
  Mesh mesh{{vtx(-1, -1, 1), vtx(1, -1, 1), vtx(0, 1, 1), vtx(-1, -1, 2), vtx(1, -1, 2),
             vtx(0, 1, 2)},
            {{0, 1, 2, 2}, {3, 4, 5, 0}}};
  s.add_instance(s.add_mesh(mesh), kIdentity, K_MASK_PRIMARY);
  s.build();
  KHit hit;
  ASSERT_TRUE(k_bvh_closest(s.ref(), &s.materials, v3(0, 0, 0), v3(0, 0, 1), 0.0f, 100.0f, K_MASK_PRIMARY, &hit));
  EXPECT_FLOAT_EQ(hit.t, 2.0f);
}

TEST(BVH_TRAVERSE_SUITE, DepthStaysBoundedOnPathologicalInput) {
  // Geometrically spaced triangles make every SAH split peel off one triangle: without the depth
  // bound this tree would be ~300 levels deep and overflow the traversal stacks.
  Mesh mesh;
  for (int i = 0; i < 300; ++i) {
    float x = std::pow(1.15f, float(i));
    kuint b = kuint(mesh.vertices.size());
    mesh.vertices.push_back(vtx(x, 0, 0));
    mesh.vertices.push_back(vtx(x, 1, 0));
    mesh.vertices.push_back(vtx(x, 0, 1));
    mesh.triangles.push_back({b, b + 1, b + 2, 0});
  }
  BlasBuild b = build_blas(mesh.vertices, mesh.triangles);
  std::vector<int> depth(b.nodes.size(), 1);
  int max_depth = 1;
  for (size_t i = 0; i < b.nodes.size(); ++i) {
    if (b.nodes[i].count > 0) continue;
    depth[b.nodes[i].left_first] = depth[b.nodes[i].left_first + 1] = depth[i] + 1;
    max_depth = std::max(max_depth, depth[i] + 1);
  }
  EXPECT_LE(max_depth, K_BVH_MAX_DEPTH);
  FlatScene s;
  s.add_instance(s.add_mesh(mesh), kIdentity, K_MASK_PRIMARY);
  s.build();
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> x(0.0f, 1.0e18f), yz(0.05f, 0.45f);
  for (int i = 0; i < 500; ++i) {
    KVec3 o = v3(x(rng), yz(rng), yz(rng));
    o.x = std::pow(1.15f, std::floor(std::log(std::max(o.x, 1.0f)) / std::log(1.15f)));  // on a triangle
    Reference ref = brute_force(s, v3(o.x, o.y, -1.0f), v3(0, 0, 1), 0.0f, 1e30f, K_MASK_PRIMARY);
    KHit hit;
    ASSERT_EQ(k_bvh_closest(s.ref(), &s.materials, v3(o.x, o.y, -1.0f), v3(0, 0, 1), 0.0f, 1e30f, K_MASK_PRIMARY, &hit),
              ref.instance != K_NONE ? 1 : 0);
    if (ref.instance != K_NONE) {
      EXPECT_EQ(hit.triangle, ref.triangle);
    }
  }
}

TEST(BVH_TRAVERSE_SUITE, CoplanarMeshMatchesBruteForce) {
  // A flat grid: every box is flat in z, every centroid shares z.
  Mesh grid;
  const int n = 40;
  for (int y = 0; y <= n; ++y)
    for (int x = 0; x <= n; ++x) grid.vertices.push_back(vtx(float(x) - n / 2, float(y) - n / 2, 0.0f));
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      kuint a = kuint(y * (n + 1) + x), b = a + 1, c = a + kuint(n + 1), d = c + 1;
      grid.triangles.push_back({a, c, b, 0});
      grid.triangles.push_back({b, c, d, 0});
    }
  FlatScene s;
  s.add_instance(s.add_mesh(grid), kIdentity, K_MASK_PRIMARY);
  s.build();
  EXPECT_GT(expect_matches_brute_force(s, 2000, 5, 30.0f, K_MASK_PRIMARY), 200);
}
