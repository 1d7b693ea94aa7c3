#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>

#include <gtest/gtest.h>

#include "cohort/core/bvh.h"

using namespace cohort::core;

namespace {

struct Soup {
  std::vector<KVertex> vertices;
  std::vector<KTriangle> triangles;
};

Soup random_soup(int count, uint32_t seed, float extent = 100.0f, float size = 4.0f) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> pos(-extent, extent), off(-size, size);
  Soup s;
  for (int i = 0; i < count; ++i) {
    float c[3] = {pos(rng), pos(rng), pos(rng)};
    for (int k = 0; k < 3; ++k) {
      KVertex v{};
      for (int a = 0; a < 3; ++a) v.pos[a] = c[a] + off(rng);
      s.vertices.push_back(v);
    }
    s.triangles.push_back({uint32_t(3 * i), uint32_t(3 * i + 1), uint32_t(3 * i + 2), uint32_t(i)});
  }
  return s;
}

struct Ray {
  float o[3], d[3];
};

bool intersect(const Ray& r, const float* p0, const float* p1, const float* p2, float& t) {
  float e1[3], e2[3], pv[3], tv[3], qv[3];
  for (int a = 0; a < 3; ++a) e1[a] = p1[a] - p0[a], e2[a] = p2[a] - p0[a], tv[a] = r.o[a] - p0[a];
  auto cross = [](const float* a, const float* b, float* c) {
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
  };
  auto dot = [](const float* a, const float* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; };
  cross(r.d, e2, pv);
  float det = dot(e1, pv);
  if (std::fabs(det) < 1e-12f) return false;
  float u = dot(tv, pv) / det;
  if (u < 0 || u > 1) return false;
  cross(tv, e1, qv);
  float v = dot(r.d, qv) / det;
  if (v < 0 || u + v > 1) return false;
  t = dot(e2, qv) / det;
  return t > 0;
}

bool box_hit(const KBvhNode& n, const Ray& r, float tmax) {
  float tn = 0, tf = tmax;
  for (int a = 0; a < 3; ++a) {
    float inv = 1.0f / r.d[a];
    float t0 = (n.bmin[a] - r.o[a]) * inv, t1 = (n.bmax[a] - r.o[a]) * inv;
    if (t0 > t1) std::swap(t0, t1);
    tn = std::max(tn, t0);
    tf = std::min(tf, t1);
  }
  return tn <= tf;
}

// Reference traversal of the built layout (the portable kernel header has its own test).
void traverse(const BlasBuild& b, const std::vector<KVertex>& v, const Ray& r, uint32_t node, float& best,
              uint32_t& best_material) {
  const KBvhNode& n = b.nodes[node];
  if (!box_hit(n, r, best)) return;
  if (n.count > 0) {
    for (uint32_t i = n.left_first; i < n.left_first + n.count; ++i) {
      const KTriangle& t = b.triangles[i];
      float th;
      if (intersect(r, v[t.v0].pos, v[t.v1].pos, v[t.v2].pos, th) && th < best) best = th, best_material = t.material;
    }
    return;
  }
  traverse(b, v, r, n.left_first, best, best_material);
  traverse(b, v, r, n.left_first + 1, best, best_material);
}

Ray random_ray(std::mt19937& rng) {
  std::uniform_real_distribution<float> pos(-120.0f, 120.0f), dir(-1.0f, 1.0f);
  Ray r{{pos(rng), pos(rng), pos(rng)}, {dir(rng), dir(rng), dir(rng)}};
  float l = std::sqrt(r.d[0] * r.d[0] + r.d[1] * r.d[1] + r.d[2] * r.d[2]);
  for (float& c : r.d) c /= l;
  return r;
}

bool contains(const KBvhNode& outer, const KBvhNode& inner) {
  for (int a = 0; a < 3; ++a)
    if (inner.bmin[a] < outer.bmin[a] || inner.bmax[a] > outer.bmax[a]) return false;
  return true;
}

void expect_valid_tree(const BlasBuild& b, const std::vector<KVertex>& v, size_t triangle_count) {
  std::vector<int> seen(triangle_count, 0);
  for (size_t i = 0; i < b.nodes.size(); ++i) {
    const KBvhNode& n = b.nodes[i];
    if (n.count > 0) {
      for (uint32_t t = n.left_first; t < n.left_first + n.count; ++t) {
        ASSERT_LT(t, b.triangles.size());
        ++seen[t];
        const KTriangle& tri = b.triangles[t];
        for (uint32_t vi : {tri.v0, tri.v1, tri.v2})
          for (int a = 0; a < 3; ++a) {
            EXPECT_GE(v[vi].pos[a], n.bmin[a]);
            EXPECT_LE(v[vi].pos[a], n.bmax[a]);
          }
      }
    } else {
      ASSERT_GT(n.left_first, i) << "children must follow their parent";
      ASSERT_LT(n.left_first + 1, b.nodes.size());
      EXPECT_TRUE(contains(n, b.nodes[n.left_first]));
      EXPECT_TRUE(contains(n, b.nodes[n.left_first + 1]));
    }
  }
  for (int s : seen) ASSERT_EQ(s, 1) << "every triangle sits in exactly one leaf";
}

}  // namespace

TEST(BlasBuilder, TreeIsValidAndHitsMatchBruteForce) {
  Soup soup = random_soup(3000, 7);
  BlasBuild b = build_blas(soup.vertices, soup.triangles);
  expect_valid_tree(b, soup.vertices, soup.triangles.size());
  std::mt19937 rng(11);
  int hits = 0;
  for (int i = 0; i < 2000; ++i) {
    Ray r = random_ray(rng);
    float brute = 1e30f;
    uint32_t brute_material = K_NONE;
    for (const KTriangle& t : soup.triangles) {
      float th;
      if (intersect(r, soup.vertices[t.v0].pos, soup.vertices[t.v1].pos, soup.vertices[t.v2].pos, th) && th < brute)
        brute = th, brute_material = t.material;
    }
    float best = 1e30f;
    uint32_t material = K_NONE;
    traverse(b, soup.vertices, r, 0, best, material);
    ASSERT_EQ(material, brute_material) << "ray " << i;
    if (brute < 1e30f) {
      ++hits;
      ASSERT_FLOAT_EQ(best, brute);
    }
  }
  EXPECT_GT(hits, 100) << "the test must exercise hits, not only misses";
  EXPECT_GT(b.sah_cost, 0.0f);
}

TEST(BlasBuilder, SameTreeForAnyThreadCount) {
  Soup soup = random_soup(40000, 3);
  BvhBuildOptions one, many;
  one.threads = 1;
  many.threads = 8;
  BlasBuild a = build_blas(soup.vertices, soup.triangles, one);
  BlasBuild b = build_blas(soup.vertices, soup.triangles, many);
  ASSERT_EQ(a.nodes.size(), b.nodes.size());
  EXPECT_EQ(0, std::memcmp(a.nodes.data(), b.nodes.data(), a.nodes.size() * sizeof(KBvhNode)));
  EXPECT_EQ(0, std::memcmp(a.triangles.data(), b.triangles.data(), a.triangles.size() * sizeof(KTriangle)));
}

TEST(BlasBuilder, SahBeatsAMedianSplitOnClusteredInput) {
  // Two dense clusters far apart: SAH must separate them at the root.
  Soup a = random_soup(500, 1, 5.0f, 0.5f), b = random_soup(500, 2, 5.0f, 0.5f);
  for (auto& v : b.vertices) v.pos[0] += 1000.0f;
  for (auto& t : b.triangles) t.v0 += 1500, t.v1 += 1500, t.v2 += 1500;
  a.vertices.insert(a.vertices.end(), b.vertices.begin(), b.vertices.end());
  a.triangles.insert(a.triangles.end(), b.triangles.begin(), b.triangles.end());
  BlasBuild built = build_blas(a.vertices, a.triangles);
  const KBvhNode& left = built.nodes[built.nodes[0].left_first];
  const KBvhNode& right = built.nodes[built.nodes[0].left_first + 1];
  EXPECT_TRUE(left.bmax[0] < 100.0f || right.bmax[0] < 100.0f);
  EXPECT_TRUE(left.bmin[0] > 900.0f || right.bmin[0] > 900.0f);
}

TEST(BlasBuilder, DegenerateInputs) {
  Soup none;
  EXPECT_TRUE(build_blas(none.vertices, none.triangles).nodes.empty());
  Soup one = random_soup(1, 5);
  BlasBuild b1 = build_blas(one.vertices, one.triangles);
  ASSERT_EQ(b1.nodes.size(), 1u);
  EXPECT_EQ(b1.nodes[0].count, 1u);
  // 100 identical triangles: centroids coincide, the builder must still terminate with small leaves.
  Soup same;
  for (int i = 0; i < 100; ++i) {
    for (int k = 0; k < 3; ++k) {
      KVertex v{};
      v.pos[k] = 1.0f;
      same.vertices.push_back(v);
    }
    same.triangles.push_back({uint32_t(3 * i), uint32_t(3 * i + 1), uint32_t(3 * i + 2), 0});
  }
  BlasBuild bs = build_blas(same.vertices, same.triangles);
  expect_valid_tree(bs, same.vertices, 100);
  for (const auto& n : bs.nodes) EXPECT_LE(n.count, 4u);
}

int tree_depth(const std::vector<KBvhNode>& nodes, uint32_t node = 0) {
  const KBvhNode& n = nodes[node];
  if (n.count > 0) return 1;
  return 1 + std::max(tree_depth(nodes, n.left_first), tree_depth(nodes, n.left_first + 1));
}

TEST(BlasBuilder, DepthStaysWithinTheTraversalStackOnSkewedInput) {
  // 3000 triangles on one spot and 100 spread over exponentially growing distances: SAH splits peel the
  // far ones off one level at a time, the worst case for depth.
  Soup skewed = random_soup(3000, 12, 0.01f, 0.01f);
  for (int i = 0; i < 100; ++i) {
    const float x = std::pow(1.6f, float(i));
    for (int k = 0; k < 3; ++k) {
      KVertex v{};
      v.pos[0] = x + float(k);
      v.pos[1] = float(k == 1);
      skewed.vertices.push_back(v);
    }
    const uint32_t base = uint32_t(skewed.vertices.size()) - 3;
    skewed.triangles.push_back({base, base + 1, base + 2, 0});
  }
  BlasBuild b = build_blas(skewed.vertices, skewed.triangles);
  expect_valid_tree(b, skewed.vertices, skewed.triangles.size());
  EXPECT_LE(tree_depth(b.nodes), K_BVH_MAX_DEPTH);
}

TEST(BlasRefit, StaysCorrectAfterDeformationAndReportsDecay) {
  Soup soup = random_soup(2000, 9);
  BlasBuild b = build_blas(soup.vertices, soup.triangles);
  const float built = b.sah_cost;
  std::mt19937 rng(4);
  std::uniform_real_distribution<float> wobble(-30.0f, 30.0f);
  for (auto& v : soup.vertices)
    for (float& c : v.pos) c += wobble(rng);
  float refit = refit_blas(soup.vertices, b);
  expect_valid_tree(b, soup.vertices, soup.triangles.size());
  EXPECT_GT(refit, built) << "scrambling vertices must degrade the tree";
  EXPECT_TRUE(blas_needs_rebuild(built, refit, 1.2f));
  EXPECT_FALSE(blas_needs_rebuild(built, built, 1.2f));
  std::mt19937 rays(5);
  for (int i = 0; i < 500; ++i) {
    Ray r = random_ray(rays);
    float brute = 1e30f;
    for (const KTriangle& t : soup.triangles) {
      float th;
      if (intersect(r, soup.vertices[t.v0].pos, soup.vertices[t.v1].pos, soup.vertices[t.v2].pos, th))
        brute = std::min(brute, th);
    }
    float best = 1e30f;
    uint32_t m;
    traverse(b, soup.vertices, r, 0, best, m);
    ASSERT_FLOAT_EQ(best, brute);
  }
}

TEST(TlasBuilder, InstanceBoxesCoverTransformedBlas) {
  Soup soup = random_soup(200, 2, 10.0f, 1.0f);
  BlasBuild blas = build_blas(soup.vertices, soup.triangles);
  std::vector<KInstance> instances;
  std::mt19937 rng(8);
  std::uniform_real_distribution<float> pos(-500.0f, 500.0f), ang(0.0f, 6.28f);
  for (uint32_t i = 0; i < 300; ++i) {
    KInstance inst{};
    float c = std::cos(ang(rng)), s = std::sin(ang(rng)), scale = 0.5f + float(i % 4);
    float m[12] = {c * scale, -s * scale, 0, pos(rng), s * scale, c * scale, 0, pos(rng), 0, 0, scale, pos(rng)};
    std::memcpy(inst.object_to_world, m, sizeof m);
    inst.entity = i;
    instances.push_back(inst);
  }
  auto ordered = instances;
  std::vector<KBvhNode> tlas = build_tlas(ordered, {blas.nodes[0]});
  ASSERT_EQ(ordered.size(), instances.size());
  std::vector<int> seen(instances.size(), 0);
  for (const auto& n : tlas) {
    if (n.count == 0) continue;
    for (uint32_t i = n.left_first; i < n.left_first + n.count; ++i) {
      ++seen[ordered[i].entity];
      // Every transformed vertex of the instance lies in its leaf's box.
      const float* m = ordered[i].object_to_world;
      for (const auto& v : soup.vertices)
        for (int r = 0; r < 3; ++r) {
          float w = m[r * 4] * v.pos[0] + m[r * 4 + 1] * v.pos[1] + m[r * 4 + 2] * v.pos[2] + m[r * 4 + 3];
          EXPECT_GE(w, n.bmin[r] - 1e-3f);
          EXPECT_LE(w, n.bmax[r] + 1e-3f);
        }
    }
  }
  for (int s : seen) EXPECT_EQ(s, 1);
  std::vector<KInstance> empty;
  EXPECT_TRUE(build_tlas(empty, {blas.nodes[0]}).empty());
}
