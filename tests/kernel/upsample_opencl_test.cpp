// kernel/upsample.h compiled as OpenCL C 1.2 from its own text and run on the first OpenCL device: the
// joint-bilateral and nearest reconstructions must equal the same header compiled as C++ (the host's
// upsample_sparse runs that one).
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "cohort/kernel/upsample.h"

#ifdef COHORT_HAVE_OPENCL
#include <CL/cl.h>

#include "opencl_kernel_program.h"
#endif

namespace {

[[maybe_unused]] const char* kProgram = R"CL(
#include "cohort/kernel/upsample.h"
__kernel void demodulate(__global const float* in_rgba, __global const float* albedo, __global float* illumination,
                         KUpsampleParams params) {
  kint x = (kint)get_global_id(0), y = (kint)get_global_id(1);
  if (x < params.width && y < params.height) k_upsample_demodulate_pixel(in_rgba, albedo, illumination, &params, x, y);
}
__kernel void upsample_frame(__global const float* in_rgba, __global const float* illumination,
                             __global const float* depth, __global const float* normal, __global const float* albedo,
                             __global const uint* id, __global float* out_rgba, KUpsampleParams params, int method) {
  kint x = (kint)get_global_id(0), y = (kint)get_global_id(1);
  if (x < params.width && y < params.height)
    k_upsample_pixel(in_rgba, illumination, depth, normal, albedo, id, out_rgba, &params, method, x, y);
}
)CL";

}  // namespace

TEST(UpsampleOpenCL, ReconstructionMatchesTheCppBuildOfTheSameHeader) {
#ifndef COHORT_HAVE_OPENCL
  GTEST_SKIP() << "built without OpenCL (COHORT_WITH_OPENCL=OFF)";
#else
  OpenCLKernelProgram cl(kProgram);
  if (!cl.skip.empty()) GTEST_SKIP() << cl.skip;
  ASSERT_TRUE(cl.problem.empty()) << "upsample.h: " << cl.problem;
  cl_int err = CL_SUCCESS;
  cl_kernel kernel = clCreateKernel(cl.program, "upsample_frame", &err);
  ASSERT_EQ(err, CL_SUCCESS);
  cl_kernel demodulate = clCreateKernel(cl.program, "demodulate", &err);
  ASSERT_EQ(err, CL_SUCCESS);

  // Noisy light over a miss, two walls (a crease), a depth ramp, an object of its own and a texture.
  const int w = 40, h = 30;
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.0f, 2.0f);
  std::vector<float> rgba(4 * w * h), depth(w * h), normal(3 * w * h, 0.0f), albedo(3 * w * h);
  std::vector<kuint> id(w * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const int p = y * w + x;
      for (int k = 0; k < 3; ++k) rgba[4 * p + k] = u(rng), albedo[3 * p + k] = 0.5f * u(rng);
      rgba[4 * p + 3] = 1.0f;
      depth[p] = x < 4 ? 0.0f : 5.0f + 0.1f * float(x);
      normal[3 * p + (y < h / 2 ? 0 : 2)] = 1.0f;
      id[p] = x > 30 && y > 20 ? 5u : 0u;
    }
  for (int method : {K_UPSAMPLE_JOINT_BILATERAL, K_UPSAMPLE_NEAREST})
    for (kuint pixels : {1u, 4u, 8u}) {
      SCOPED_TRACE(testing::Message() << "method " << method << ", " << pixels << " pixels of 16");
      const KUpsampleParams params = k_upsample_params(w, h, pixels, 3u);
      std::vector<float> expected(4 * w * h), out(4 * w * h, -1.0f), illumination(4 * w * h, 0.0f),
          device_illumination(4 * w * h, 0.0f);
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) k_upsample_demodulate_pixel(rgba.data(), albedo.data(), illumination.data(), &params, x, y);
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
          k_upsample_pixel(rgba.data(), illumination.data(), depth.data(), normal.data(), albedo.data(), id.data(),
                           expected.data(), &params, method, x, y);
      auto buffer = [&](void* data, size_t bytes) {
        cl_mem m = clCreateBuffer(cl.context, CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR, bytes, data, &err);
        EXPECT_EQ(err, CL_SUCCESS);
        return m;
      };
      cl_mem mems[7] = {buffer(rgba.data(), rgba.size() * 4), buffer(device_illumination.data(), illumination.size() * 4),
                        buffer(depth.data(), depth.size() * 4), buffer(normal.data(), normal.size() * 4),
                        buffer(albedo.data(), albedo.size() * 4), buffer(id.data(), id.size() * 4),
                        buffer(out.data(), out.size() * 4)};
      cl_mem demodulate_args[3] = {mems[0], mems[4], mems[1]};
      for (cl_uint i = 0; i < 3; ++i)
        ASSERT_EQ(clSetKernelArg(demodulate, i, sizeof(cl_mem), &demodulate_args[i]), CL_SUCCESS);
      ASSERT_EQ(clSetKernelArg(demodulate, 3, sizeof(KUpsampleParams), &params), CL_SUCCESS);
      for (cl_uint i = 0; i < 7; ++i) ASSERT_EQ(clSetKernelArg(kernel, i, sizeof(cl_mem), &mems[i]), CL_SUCCESS);
      ASSERT_EQ(clSetKernelArg(kernel, 7, sizeof(KUpsampleParams), &params), CL_SUCCESS);
      ASSERT_EQ(clSetKernelArg(kernel, 8, sizeof(int), &method), CL_SUCCESS);
      const size_t global[2] = {size_t(w), size_t(h)};
      ASSERT_EQ(clEnqueueNDRangeKernel(cl.queue, demodulate, 2, nullptr, global, nullptr, 0, nullptr, nullptr),
                CL_SUCCESS);
      ASSERT_EQ(clEnqueueNDRangeKernel(cl.queue, kernel, 2, nullptr, global, nullptr, 0, nullptr, nullptr), CL_SUCCESS);
      ASSERT_EQ(clEnqueueReadBuffer(cl.queue, mems[6], CL_TRUE, 0, out.size() * sizeof(float), out.data(), 0, nullptr,
                                    nullptr),
                CL_SUCCESS);
      for (size_t i = 0; i < out.size(); ++i)
        ASSERT_NEAR(out[i], expected[i], 1e-4f * (1.0f + std::fabs(expected[i]))) << i;
      for (cl_mem m : mems) clReleaseMemObject(m);
    }
  clReleaseKernel(kernel);
  clReleaseKernel(demodulate);
#endif
}
