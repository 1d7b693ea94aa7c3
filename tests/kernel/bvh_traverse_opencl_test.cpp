// kernel/bvh_traverse.h compiled as OpenCL C 1.2 from its own text (clBuildProgram with -I) and run
// on the first OpenCL device; closest hits and occlusion must equal the same header compiled as C++.
#include <cmath>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cohort/core/bvh.h"
#include "cohort/kernel/bvh_traverse.h"

#ifdef COHORT_HAVE_OPENCL
#include <CL/cl.h>

#include "opencl_kernel_program.h"
#endif

using namespace cohort::core;

namespace {

const char* kProgram = R"CL(
#include "cohort/kernel/bvh_traverse.h"
__kernel void trace(__global const KVertex* vertices, __global const KTriangle* triangles,
                    __global const KBvhNode* blas_nodes, __global const KBlas* blases,
                    __global const KInstance* instances, __global const KBvhNode* tlas_nodes,
                    kuint instance_count, kuint tlas_node_count, __global const float* rays, kuint ray_count,
                    __global KHit* hits, __global kuint* occluded) {
  kuint i = (kuint)get_global_id(0);
  if (i >= ray_count) return;
  KSceneRef scene;
  scene.vertices = vertices;
  scene.triangles = triangles;
  scene.blas_nodes = blas_nodes;
  scene.blases = blases;
  scene.instances = instances;
  scene.tlas_nodes = tlas_nodes;
  scene.instance_count = instance_count;
  scene.tlas_node_count = tlas_node_count;
  KVec3 o = v3(rays[8 * i], rays[8 * i + 1], rays[8 * i + 2]);
  KVec3 d = v3(rays[8 * i + 4], rays[8 * i + 5], rays[8 * i + 6]);
  float tmax = rays[8 * i + 3];
  KHit hit;
  k_bvh_closest(scene, 0, o, d, 0.0f, tmax, K_MASK_PRIMARY, &hit);
  hits[i] = hit;
  occluded[i] = (kuint)k_bvh_any(scene, 0, o, d, 0.0f, tmax, K_MASK_SHADOW);
}
)CL";

struct Scene {
  std::vector<KVertex> vertices;
  std::vector<KTriangle> triangles;
  std::vector<KBvhNode> blas_nodes;
  std::vector<KBlas> blases;
  std::vector<KInstance> instances;
  std::vector<KBvhNode> tlas;
  KSceneRef ref() const {
    return KSceneRef{vertices.data(), triangles.data(), blas_nodes.data(), blases.data(), instances.data(),
                     tlas.data(),     kuint(instances.size()), kuint(tlas.size())};
  }
};

// One random soup, instanced with uniform scale + rotation about z + translation; some instances are
// noShadows (primary mask only).
Scene make_scene() {
  Scene s;
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> pos(-20.0f, 20.0f), off(-2.0f, 2.0f);
  std::vector<KVertex> vertices;
  std::vector<KTriangle> triangles;
  for (int i = 0; i < 500; ++i) {
    float c[3] = {pos(rng), pos(rng), pos(rng)};
    for (int k = 0; k < 3; ++k) {
      KVertex v{};
      for (int a = 0; a < 3; ++a) v.pos[a] = c[a] + off(rng);
      vertices.push_back(v);
    }
    triangles.push_back({kuint(3 * i), kuint(3 * i + 1), kuint(3 * i + 2), 0});
  }
  BlasBuild blas = build_blas(vertices, triangles);
  s.vertices = vertices;
  s.triangles = blas.triangles;
  s.blas_nodes = blas.nodes;
  s.blases.push_back(KBlas{0, kuint(blas.nodes.size()), 0, kuint(blas.triangles.size())});
  std::uniform_real_distribution<float> place(-60.0f, 60.0f), angle(0.0f, 6.2832f), scale(0.5f, 2.0f);
  for (int i = 0; i < 20; ++i) {
    float a = angle(rng), k = scale(rng), c = std::cos(a), sn = std::sin(a);
    float tx = place(rng), ty = place(rng), tz = place(rng);
    KInstance inst{};
    float o2w[12] = {k * c, -k * sn, 0, tx, k * sn, k * c, 0, ty, 0, 0, k, tz};
    float w2o[12] = {c / k, sn / k, 0, -(c * tx + sn * ty) / k, -sn / k, c / k, 0, -(-sn * tx + c * ty) / k,
                     0, 0, 1 / k, -tz / k};
    std::memcpy(inst.object_to_world, o2w, sizeof o2w);
    std::memcpy(inst.world_to_object, w2o, sizeof w2o);
    inst.blas = 0;
    inst.mask = i % 4 == 0 ? K_MASK_PRIMARY : K_MASK_PRIMARY | K_MASK_SHADOW;
    inst.entity = kuint(i);
    inst.material_override = K_NONE;
    s.instances.push_back(inst);
  }
  s.tlas = build_tlas(s.instances, {blas.nodes[0]});
  return s;
}

std::vector<float> make_rays(int count) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> pos(-80.0f, 80.0f), dir(-1.0f, 1.0f);
  std::vector<float> rays(8 * size_t(count), 0.0f);
  for (int i = 0; i < count; ++i) {
    float d[3] = {dir(rng), dir(rng), dir(rng)};
    float l = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    rays[8 * i] = pos(rng), rays[8 * i + 1] = pos(rng), rays[8 * i + 2] = pos(rng);
    rays[8 * i + 3] = i % 2 ? 1e30f : 60.0f;
    for (int a = 0; a < 3; ++a) rays[8 * i + 4 + a] = d[a] / l;
  }
  return rays;
}

}  // namespace

TEST(BvhTraverseOpenCL, ClosestHitsMatchTheCppBuildOfTheSameHeader) {
#ifndef COHORT_HAVE_OPENCL
  GTEST_SKIP() << "built without OpenCL (COHORT_WITH_OPENCL=OFF)";
#else
  OpenCLKernelProgram cl(kProgram);
  if (!cl.skip.empty()) GTEST_SKIP() << cl.skip;
  ASSERT_TRUE(cl.problem.empty()) << "bvh_traverse.h: " << cl.problem;
  cl_context context = cl.context;
  cl_command_queue queue = cl.queue;
  cl_program program = cl.program;
  cl_int err = CL_SUCCESS;
  cl_kernel kernel = clCreateKernel(program, "trace", &err);
  ASSERT_EQ(err, CL_SUCCESS);

  const Scene s = make_scene();
  const int ray_count = 4000;
  const std::vector<float> rays = make_rays(ray_count);
  auto buffer = [&](const void* data, size_t bytes) {
    cl_mem m = clCreateBuffer(context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, bytes, const_cast<void*>(data), &err);
    EXPECT_EQ(err, CL_SUCCESS);
    return m;
  };
  cl_mem mems[7] = {buffer(s.vertices.data(), s.vertices.size() * sizeof(KVertex)),
                    buffer(s.triangles.data(), s.triangles.size() * sizeof(KTriangle)),
                    buffer(s.blas_nodes.data(), s.blas_nodes.size() * sizeof(KBvhNode)),
                    buffer(s.blases.data(), s.blases.size() * sizeof(KBlas)),
                    buffer(s.instances.data(), s.instances.size() * sizeof(KInstance)),
                    buffer(s.tlas.data(), s.tlas.size() * sizeof(KBvhNode)),
                    buffer(rays.data(), rays.size() * sizeof(float))};
  cl_mem hits_mem = clCreateBuffer(context, CL_MEM_WRITE_ONLY, ray_count * sizeof(KHit), nullptr, &err);
  cl_mem occluded_mem = clCreateBuffer(context, CL_MEM_WRITE_ONLY, ray_count * sizeof(kuint), nullptr, &err);
  const kuint instance_count = kuint(s.instances.size()), tlas_count = kuint(s.tlas.size()), n = ray_count;
  for (int i = 0; i < 6; ++i) clSetKernelArg(kernel, i, sizeof(cl_mem), &mems[i]);
  clSetKernelArg(kernel, 6, sizeof(kuint), &instance_count);
  clSetKernelArg(kernel, 7, sizeof(kuint), &tlas_count);
  clSetKernelArg(kernel, 8, sizeof(cl_mem), &mems[6]);
  clSetKernelArg(kernel, 9, sizeof(kuint), &n);
  clSetKernelArg(kernel, 10, sizeof(cl_mem), &hits_mem);
  clSetKernelArg(kernel, 11, sizeof(cl_mem), &occluded_mem);
  const size_t global = ray_count;
  ASSERT_EQ(clEnqueueNDRangeKernel(queue, kernel, 1, nullptr, &global, nullptr, 0, nullptr, nullptr), CL_SUCCESS);
  std::vector<KHit> hits(ray_count);
  std::vector<kuint> occluded(ray_count);
  ASSERT_EQ(clEnqueueReadBuffer(queue, hits_mem, CL_TRUE, 0, hits.size() * sizeof(KHit), hits.data(), 0, nullptr,
                                nullptr), CL_SUCCESS);
  ASSERT_EQ(clEnqueueReadBuffer(queue, occluded_mem, CL_TRUE, 0, occluded.size() * sizeof(kuint), occluded.data(), 0,
                                nullptr, nullptr), CL_SUCCESS);

  int hit_count = 0, occluded_count = 0;
  for (int i = 0; i < ray_count; ++i) {
    KVec3 o = v3(rays[8 * i], rays[8 * i + 1], rays[8 * i + 2]), d = v3(rays[8 * i + 4], rays[8 * i + 5], rays[8 * i + 6]);
    KHit cpu;
    k_bvh_closest(s.ref(), 0, o, d, 0.0f, rays[8 * i + 3], K_MASK_PRIMARY, &cpu);
    ASSERT_EQ(hits[i].instance, cpu.instance) << "ray " << i;
    if (cpu.instance == K_NONE) continue;
    ++hit_count;
    EXPECT_EQ(hits[i].triangle, cpu.triangle) << "ray " << i;
    // Device maths may contract to FMA: allow a few ulps.
    EXPECT_NEAR(hits[i].t, cpu.t, 1e-4f * std::max(1.0f, cpu.t)) << "ray " << i;
    EXPECT_NEAR(hits[i].u, cpu.u, 1e-3f) << "ray " << i;
    const kuint cpu_occluded = kuint(k_bvh_any(s.ref(), 0, o, d, 0.0f, rays[8 * i + 3], K_MASK_SHADOW));
    EXPECT_EQ(occluded[i], cpu_occluded) << "ray " << i;
    occluded_count += int(cpu_occluded);
  }
  EXPECT_GT(hit_count, 200);
  EXPECT_GT(occluded_count, 100);

  for (cl_mem m : mems) clReleaseMemObject(m);
  clReleaseMemObject(hits_mem);
  clReleaseMemObject(occluded_mem);
  clReleaseKernel(kernel);
#endif
}
