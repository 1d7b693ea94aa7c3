// kernel/atrous.h compiled as OpenCL C 1.2 from its own text and run on the first OpenCL device: one
// filter pass must equal the same header compiled as C++ (the host's AtrousFilter runs that one).
// kernel/reproject.h is built into the same program, so a construct OpenCL C refuses fails here too;
// kernel/svgf.h's variance estimate and variance-guided pass must equal their C++ build as well.
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cohort/kernel/atrous.h"
#include "cohort/kernel/svgf.h"

#ifdef COHORT_HAVE_OPENCL
#include <CL/cl.h>

#include "opencl_kernel_program.h"
#endif

namespace {

[[maybe_unused]] const char* kProgram = R"CL(
#include "cohort/kernel/atrous.h"
__kernel void atrous(__global const float* in_rgba, __global float* out_rgba, __global const float* geometry,
                     KAtrousParams params) {
  kint x = (kint)get_global_id(0), y = (kint)get_global_id(1);
  if (x < params.width && y < params.height) k_atrous_pixel(in_rgba, out_rgba, geometry, &params, x, y);
}
/* kernel/reproject.h goes through the same OpenCL C compiler here (its planes travel in private structs
   of __global pointers, which OpenCL C 1.2 allows inside a kernel but not as arguments). */
#include "cohort/kernel/reproject.h"
__kernel void reproject(KReprojectParams params, __global const float* rgba, __global float* ycocgw,
                        __global const float* depth, __global const float* prev_depth, __global const float* motion,
                        __global const float* normal, __global const uint* id, __global const float* albedo,
                        __global const float* h_rgba, __global const float* h_length, __global const float* h_depth,
                        __global const float* h_normal, __global const uint* h_id, __global const float* h_moments,
                        __global float* n_rgba, __global float* n_length, __global float* n_depth,
                        __global float* n_normal, __global uint* n_id, __global float* n_moments) {
  kint x = (kint)get_global_id(0), y = (kint)get_global_id(1);
  if (x >= params.width || y >= params.height) return;
  KReprojectFresh fresh = {rgba, ycocgw, depth, prev_depth, motion, normal, id, albedo};
  KReprojectHistory history = {h_rgba, h_length, h_depth, h_normal, h_id, h_moments};
  KReprojectState next = {n_rgba, n_length, n_depth, n_normal, n_id, n_moments};
  k_reproject_pixel(&params, &fresh, &history, &next, x, y);
}
#include "cohort/kernel/svgf.h"
__kernel void svgf_variance(__global const float* illumination, __global const float* moments,
                            __global const float* length, __global const float* geometry,
                            __global float* variance, KSvgfVarianceParams params) {
  kint x = (kint)get_global_id(0), y = (kint)get_global_id(1);
  if (x < params.width && y < params.height)
    k_svgf_variance_pixel(illumination, moments, length, geometry, variance, &params, x, y);
}
__kernel void svgf_atrous(__global const float* in_rgba, __global float* out_rgba, __global const float* geometry,
                          KAtrousParams params) {
  kint x = (kint)get_global_id(0), y = (kint)get_global_id(1);
  if (x < params.width && y < params.height) k_svgf_atrous_pixel(in_rgba, out_rgba, geometry, &params, x, y);
}
)CL";

}  // namespace

TEST(AtrousOpenCL, APassMatchesTheCppBuildOfTheSameHeader) {
#ifndef COHORT_HAVE_OPENCL
  GTEST_SKIP() << "built without OpenCL (COHORT_WITH_OPENCL=OFF)";
#else
  OpenCLKernelProgram cl(kProgram);
  if (!cl.skip.empty()) GTEST_SKIP() << cl.skip;
  ASSERT_TRUE(cl.problem.empty()) << "atrous.h or reproject.h: " << cl.problem;
  cl_context context = cl.context;
  cl_command_queue queue = cl.queue;
  cl_program program = cl.program;
  cl_int err = CL_SUCCESS;
  cl_kernel kernel = clCreateKernel(program, "atrous", &err);
  ASSERT_EQ(err, CL_SUCCESS);

  // A noisy frame over three surfaces (two walls and a miss) with a depth ramp.
  const int w = 40, h = 30;
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.0f, 2.0f);
  std::vector<float> rgba(4 * w * h), depth(w * h), normal(3 * w * h, 0.0f), out(4 * w * h, -1.0f), expected(4 * w * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const int p = y * w + x;
      for (int k = 0; k < 3; ++k) rgba[4 * p + k] = u(rng);
      rgba[4 * p + 3] = 1.0f;
      depth[p] = x < 4 ? 0.0f : 5.0f + 0.1f * float(x);
      normal[3 * p + (y < h / 2 ? 0 : 2)] = 1.0f;
    }
  KAtrousParams params{};
  params.width = w, params.height = h, params.step = 2;
  params.normal_squarings = 6, params.depth_sigma = 0.1f, params.color_sigma = 2.0f;
  std::vector<float> geometry(4 * w * h);
  for (int p = 0; p < w * h; ++p) k_atrous_pack_geometry(depth.data(), normal.data(), geometry.data(), p);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) k_atrous_pixel(rgba.data(), expected.data(), geometry.data(), &params, x, y);

  auto buffer = [&](std::vector<float>& v, cl_mem_flags flags) {
    cl_mem m = clCreateBuffer(context, flags | CL_MEM_COPY_HOST_PTR, v.size() * sizeof(float), v.data(), &err);
    EXPECT_EQ(err, CL_SUCCESS);
    return m;
  };
  cl_mem mems[3] = {buffer(rgba, CL_MEM_READ_ONLY), buffer(out, CL_MEM_WRITE_ONLY), buffer(geometry, CL_MEM_READ_ONLY)};
  for (cl_uint i = 0; i < 3; ++i) ASSERT_EQ(clSetKernelArg(kernel, i, sizeof(cl_mem), &mems[i]), CL_SUCCESS);
  ASSERT_EQ(clSetKernelArg(kernel, 3, sizeof(KAtrousParams), &params), CL_SUCCESS);
  const size_t global[2] = {size_t(w), size_t(h)};
  ASSERT_EQ(clEnqueueNDRangeKernel(queue, kernel, 2, nullptr, global, nullptr, 0, nullptr, nullptr), CL_SUCCESS);
  ASSERT_EQ(clEnqueueReadBuffer(queue, mems[1], CL_TRUE, 0, out.size() * sizeof(float), out.data(), 0, nullptr, nullptr),
            CL_SUCCESS);
  for (size_t i = 0; i < out.size(); ++i) ASSERT_NEAR(out[i], expected[i], 1e-4f * (1.0f + std::fabs(expected[i]))) << i;
  for (cl_mem m : mems) clReleaseMemObject(m);
  clReleaseKernel(kernel);
#endif
}

TEST(AtrousOpenCL, TheVarianceGuideMatchesTheCppBuildOfTheSameHeader) {
#ifndef COHORT_HAVE_OPENCL
  GTEST_SKIP() << "built without OpenCL (COHORT_WITH_OPENCL=OFF)";
#else
  OpenCLKernelProgram cl(kProgram);
  if (!cl.skip.empty()) GTEST_SKIP() << cl.skip;
  ASSERT_TRUE(cl.problem.empty()) << "svgf.h: " << cl.problem;
  cl_int err = CL_SUCCESS;
  cl_kernel variance_kernel = clCreateKernel(cl.program, "svgf_variance", &err);
  ASSERT_EQ(err, CL_SUCCESS);
  cl_kernel pass_kernel = clCreateKernel(cl.program, "svgf_atrous", &err);
  ASSERT_EQ(err, CL_SUCCESS);

  // Noisy illumination over two walls and a miss; history lengths 0..7, so both estimates run.
  const int w = 40, h = 30;
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> u(0.0f, 2.0f);
  std::vector<float> rgba(4 * w * h), depth(w * h), normal(3 * w * h, 0.0f), moments(2 * w * h), length(w * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const int p = y * w + x;
      for (int k = 0; k < 3; ++k) rgba[4 * p + k] = u(rng);
      rgba[4 * p + 3] = 1.0f;
      depth[p] = x < 4 ? 0.0f : 5.0f + 0.1f * float(x);
      normal[3 * p + (y < h / 2 ? 0 : 2)] = 1.0f;
      const float m1 = u(rng);
      moments[2 * p] = m1, moments[2 * p + 1] = m1 * m1 + u(rng);
      length[p] = float((x + y) % 8);
    }
  for (int of_mean : {0, 1}) {
  SCOPED_TRACE(of_mean ? "variance of the mean" : "variance of a sample");
  KSvgfVarianceParams vp{};
  vp.width = w, vp.height = h, vp.normal_squarings = 6, vp.have_history = 1;
  vp.depth_sigma = 0.1f, vp.short_history = 4.0f, vp.of_mean = of_mean;
  KAtrousParams params{};
  params.width = w, params.height = h, params.step = 2;
  params.normal_squarings = 6, params.depth_sigma = 0.1f, params.color_sigma = 4.0f;
  std::vector<float> variance(w * h), out(4 * w * h);
  std::vector<float> expected_variance(w * h), expected(4 * w * h), geometry(4 * w * h);
  for (int p = 0; p < w * h; ++p) k_atrous_pack_geometry(depth.data(), normal.data(), geometry.data(), p);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      k_svgf_variance_pixel(rgba.data(), moments.data(), length.data(), geometry.data(), expected_variance.data(), &vp,
                            x, y);
  // The pass reads the variance from the illumination's alpha and writes the filtered one there.
  std::vector<float> rgba_variance = rgba;
  for (int p = 0; p < w * h; ++p) rgba_variance[4 * p + 3] = expected_variance[p];
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) k_svgf_atrous_pixel(rgba_variance.data(), expected.data(), geometry.data(), &params, x, y);

  auto buffer = [&](std::vector<float>& v) {
    cl_mem m = clCreateBuffer(cl.context, CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR, v.size() * sizeof(float), v.data(),
                              &err);
    EXPECT_EQ(err, CL_SUCCESS);
    return m;
  };
  cl_mem m_rgba = buffer(rgba), m_moments = buffer(moments), m_length = buffer(length), m_variance = buffer(variance),
         m_out = buffer(out), m_rgba_variance = buffer(rgba_variance), m_geometry = buffer(geometry);
  cl_mem variance_args[5] = {m_rgba, m_moments, m_length, m_geometry, m_variance};
  for (cl_uint i = 0; i < 5; ++i) ASSERT_EQ(clSetKernelArg(variance_kernel, i, sizeof(cl_mem), &variance_args[i]), CL_SUCCESS);
  ASSERT_EQ(clSetKernelArg(variance_kernel, 5, sizeof(KSvgfVarianceParams), &vp), CL_SUCCESS);
  cl_mem pass_args[3] = {m_rgba_variance, m_out, m_geometry};
  for (cl_uint i = 0; i < 3; ++i) ASSERT_EQ(clSetKernelArg(pass_kernel, i, sizeof(cl_mem), &pass_args[i]), CL_SUCCESS);
  ASSERT_EQ(clSetKernelArg(pass_kernel, 3, sizeof(KAtrousParams), &params), CL_SUCCESS);
  const size_t global[2] = {size_t(w), size_t(h)};
  ASSERT_EQ(clEnqueueNDRangeKernel(cl.queue, variance_kernel, 2, nullptr, global, nullptr, 0, nullptr, nullptr), CL_SUCCESS);
  ASSERT_EQ(clEnqueueNDRangeKernel(cl.queue, pass_kernel, 2, nullptr, global, nullptr, 0, nullptr, nullptr), CL_SUCCESS);
  ASSERT_EQ(clEnqueueReadBuffer(cl.queue, m_variance, CL_TRUE, 0, variance.size() * sizeof(float), variance.data(), 0,
                                nullptr, nullptr), CL_SUCCESS);
  ASSERT_EQ(clEnqueueReadBuffer(cl.queue, m_out, CL_TRUE, 0, out.size() * sizeof(float), out.data(), 0, nullptr, nullptr),
            CL_SUCCESS);
  for (size_t i = 0; i < variance.size(); ++i)
    ASSERT_NEAR(variance[i], expected_variance[i], 1e-4f * (1.0f + std::fabs(expected_variance[i]))) << "variance " << i;
  for (size_t i = 0; i < out.size(); ++i)  // alpha: the filtered variance
    ASSERT_NEAR(out[i], expected[i], 1e-4f * (1.0f + std::fabs(expected[i]))) << i;
  for (cl_mem m : {m_rgba, m_moments, m_length, m_variance, m_out, m_rgba_variance, m_geometry})
    clReleaseMemObject(m);
  }
  clReleaseKernel(variance_kernel);
  clReleaseKernel(pass_kernel);
#endif
}
