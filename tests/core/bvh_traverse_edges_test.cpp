// bvh_traverse_test.cpp's cases again with K_BVH_TRIANGLE_EDGES: leaves read KTriangleEdges, as the CUDA
// build's walk does, against brute force through the same test; and those edges give the vertices' hits
// bit for bit.
#define K_BVH_TRIANGLE_EDGES 1
#define BVH_TRAVERSE_SUITE BvhTraverseEdges
#include "bvh_traverse_test.cpp"

TEST(BvhTraverseEdges, EdgesHitExactlyWhereTheVerticesDo) {
  FlatScene s;
  s.add_instance(s.add_mesh(random_soup(2000, 19, 50.0f, 4.0f)), kIdentity, K_MASK_PRIMARY);
  s.build();
  std::mt19937 rng(23);
  int hits = 0;
  for (int i = 0; i < 20000; ++i) {
    const TestRay r = random_ray(rng, 60.0f);
    const kuint tri = kuint(i) % kuint(s.triangles.size());
    const KTriangle& t = s.triangles[tri];
    auto p = [&](kuint v) { return v3(s.vertices[v].pos[0], s.vertices[v].pos[1], s.vertices[v].pos[2]); };
    // Aim every other ray at the triangle's centre, so that many hit.
    const KVec3 d = i % 2 ? r.d : v3_normalize(v3_sub(v3_scale(v3_add(v3_add(p(t.v0), p(t.v1)), p(t.v2)), 1.0f / 3.0f), r.o));
    float t0 = 0, u0 = 0, v0 = 0, t1 = 0, u1 = 0, v1 = 0;
    const int by_vertices = k_bvh_ray_triangle(r.o, d, p(t.v0), p(t.v1), p(t.v2), 0.0f, 1e30f, &t0, &u0, &v0);
    const int by_edges = k_bvh_hit_triangle(s.ref(), tri, r.o, d, 0.0f, 1e30f, &t1, &u1, &v1);
    ASSERT_EQ(by_vertices, by_edges) << "ray " << i;
    if (!by_vertices) continue;
    ++hits;
    EXPECT_EQ(t0, t1);
    EXPECT_EQ(u0, u1);
    EXPECT_EQ(v0, v1);
  }
  EXPECT_GT(hits, 5000);
}
