// kernel/atrous.h compiled as OpenCL C 1.2 from its own text and run on the first OpenCL device: one
// filter pass must equal the same header compiled as C++ (the host's AtrousFilter runs that one).
// kernel/reproject.h is built into the same program, so a construct OpenCL C refuses fails here too.
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cohort/kernel/atrous.h"

#ifdef COHORT_HAVE_OPENCL
#include <CL/cl.h>
#endif

namespace {

[[maybe_unused]] const char* kProgram = R"CL(
#include "cohort/kernel/atrous.h"
__kernel void atrous(__global const float* in_rgba, __global float* out_rgba, __global const float* depth,
                     __global const float* normal, KAtrousParams params) {
  kint x = (kint)get_global_id(0), y = (kint)get_global_id(1);
  if (x < params.width && y < params.height) k_atrous_pixel(in_rgba, out_rgba, depth, normal, &params, x, y);
}
/* kernel/reproject.h goes through the same OpenCL C compiler here (its planes travel in private structs
   of __global pointers, which OpenCL C 1.2 allows inside a kernel but not as arguments). */
#include "cohort/kernel/reproject.h"
__kernel void reproject(KReprojectParams params, __global const float* rgba, __global float* ycocgw,
                        __global const float* depth, __global const float* prev_depth, __global const float* motion,
                        __global const float* normal, __global const uint* id, __global const float* h_rgba,
                        __global const float* h_length, __global const float* h_depth, __global const float* h_normal,
                        __global const uint* h_id, __global float* n_rgba, __global float* n_length,
                        __global float* n_depth, __global float* n_normal, __global uint* n_id) {
  kint x = (kint)get_global_id(0), y = (kint)get_global_id(1);
  if (x >= params.width || y >= params.height) return;
  KReprojectFresh fresh = {rgba, ycocgw, depth, prev_depth, motion, normal, id};
  KReprojectHistory history = {h_rgba, h_length, h_depth, h_normal, h_id};
  KReprojectState next = {n_rgba, n_length, n_depth, n_normal, n_id};
  k_reproject_pixel(&params, &fresh, &history, &next, x, y);
}
)CL";

}  // namespace

TEST(AtrousOpenCL, APassMatchesTheCppBuildOfTheSameHeader) {
#ifndef COHORT_HAVE_OPENCL
  GTEST_SKIP() << "built without OpenCL (COHORT_WITH_OPENCL=OFF)";
#else
  cl_uint platform_count = 0;
  if (clGetPlatformIDs(0, nullptr, &platform_count) != CL_SUCCESS || platform_count == 0)
    GTEST_SKIP() << "no OpenCL platform on this machine (install pocl-opencl-icd for a CPU one)";
  std::vector<cl_platform_id> platforms(platform_count);
  clGetPlatformIDs(platform_count, platforms.data(), nullptr);
  cl_device_id device = nullptr;
  for (cl_platform_id p : platforms) {
    if (clGetDeviceIDs(p, CL_DEVICE_TYPE_ALL, 1, &device, nullptr) == CL_SUCCESS) break;
    device = nullptr;
  }
  if (!device) GTEST_SKIP() << "OpenCL platforms exist but none has a device";
  cl_int err = CL_SUCCESS;
  cl_context context = clCreateContext(nullptr, 1, &device, nullptr, nullptr, &err);
  ASSERT_EQ(err, CL_SUCCESS);
  cl_command_queue queue = clCreateCommandQueue(context, device, 0, &err);
  ASSERT_EQ(err, CL_SUCCESS);
  cl_program program = clCreateProgramWithSource(context, 1, &kProgram, nullptr, &err);
  ASSERT_EQ(err, CL_SUCCESS);
  const std::string options = std::string("-cl-std=CL1.2 -I ") + COHORT_SOURCE_DIR + "/kernel/include";
  if (clBuildProgram(program, 1, &device, options.c_str(), nullptr, nullptr) != CL_SUCCESS) {
    size_t size = 0;
    clGetProgramBuildInfo(program, device, CL_PROGRAM_BUILD_LOG, 0, nullptr, &size);
    std::string log(size, '\0');
    clGetProgramBuildInfo(program, device, CL_PROGRAM_BUILD_LOG, size, log.data(), nullptr);
    FAIL() << "atrous.h or reproject.h does not build as OpenCL C:\n" << log;
  }
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
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) k_atrous_pixel(rgba.data(), expected.data(), depth.data(), normal.data(), &params, x, y);

  auto buffer = [&](std::vector<float>& v, cl_mem_flags flags) {
    cl_mem m = clCreateBuffer(context, flags | CL_MEM_COPY_HOST_PTR, v.size() * sizeof(float), v.data(), &err);
    EXPECT_EQ(err, CL_SUCCESS);
    return m;
  };
  cl_mem mems[4] = {buffer(rgba, CL_MEM_READ_ONLY), buffer(out, CL_MEM_WRITE_ONLY), buffer(depth, CL_MEM_READ_ONLY),
                    buffer(normal, CL_MEM_READ_ONLY)};
  for (cl_uint i = 0; i < 4; ++i) ASSERT_EQ(clSetKernelArg(kernel, i, sizeof(cl_mem), &mems[i]), CL_SUCCESS);
  ASSERT_EQ(clSetKernelArg(kernel, 4, sizeof(KAtrousParams), &params), CL_SUCCESS);
  const size_t global[2] = {size_t(w), size_t(h)};
  ASSERT_EQ(clEnqueueNDRangeKernel(queue, kernel, 2, nullptr, global, nullptr, 0, nullptr, nullptr), CL_SUCCESS);
  ASSERT_EQ(clEnqueueReadBuffer(queue, mems[1], CL_TRUE, 0, out.size() * sizeof(float), out.data(), 0, nullptr, nullptr),
            CL_SUCCESS);
  for (size_t i = 0; i < out.size(); ++i) ASSERT_NEAR(out[i], expected[i], 1e-4f * (1.0f + std::fabs(expected[i]))) << i;
  for (cl_mem m : mems) clReleaseMemObject(m);
  clReleaseKernel(kernel);
  clReleaseProgram(program);
  clReleaseCommandQueue(queue);
  clReleaseContext(context);
#endif
}
