// The kernel tests' OpenCL side: the first device of any platform, and a program of kernel/ headers built
// as OpenCL C 1.2 from source. Skips (platform or device missing) and build failures (with the compiler's
// log) are reported to GoogleTest by the caller through `problem` / `skip`.
#pragma once

#ifdef COHORT_HAVE_OPENCL
#include <CL/cl.h>

#include <string>
#include <vector>

struct OpenCLKernelProgram {
  cl_device_id device = nullptr;
  cl_context context = nullptr;
  cl_command_queue queue = nullptr;
  cl_program program = nullptr;
  std::string skip;     // non-empty: no OpenCL here; the test should skip with this reason
  std::string problem;  // non-empty: the program did not build; the compiler's log

  explicit OpenCLKernelProgram(const char* source) {
    cl_uint platform_count = 0;
    if (clGetPlatformIDs(0, nullptr, &platform_count) != CL_SUCCESS || platform_count == 0) {
      skip = "no OpenCL platform on this machine (install pocl-opencl-icd for a CPU one)";
      return;
    }
    std::vector<cl_platform_id> platforms(platform_count);
    clGetPlatformIDs(platform_count, platforms.data(), nullptr);
    for (cl_platform_id p : platforms) {
      if (clGetDeviceIDs(p, CL_DEVICE_TYPE_ALL, 1, &device, nullptr) == CL_SUCCESS) break;
      device = nullptr;
    }
    if (!device) {
      skip = "OpenCL platforms exist but none has a device";
      return;
    }
    cl_int err = CL_SUCCESS;
    context = clCreateContext(nullptr, 1, &device, nullptr, nullptr, &err);
    if (err == CL_SUCCESS) queue = clCreateCommandQueue(context, device, 0, &err);
    if (err == CL_SUCCESS) program = clCreateProgramWithSource(context, 1, &source, nullptr, &err);
    if (err != CL_SUCCESS) {
      problem = "OpenCL context, queue or program creation failed: error " + std::to_string(err);
      return;
    }
    const std::string options = std::string("-cl-std=CL1.2 -I ") + COHORT_SOURCE_DIR + "/kernel/include";
    if (clBuildProgram(program, 1, &device, options.c_str(), nullptr, nullptr) != CL_SUCCESS) {
      size_t size = 0;
      clGetProgramBuildInfo(program, device, CL_PROGRAM_BUILD_LOG, 0, nullptr, &size);
      std::string log(size, '\0');
      clGetProgramBuildInfo(program, device, CL_PROGRAM_BUILD_LOG, size, log.data(), nullptr);
      problem = "the program does not build as OpenCL C:\n" + log;
    }
  }
  ~OpenCLKernelProgram() {
    if (program) clReleaseProgram(program);
    if (queue) clReleaseCommandQueue(queue);
    if (context) clReleaseContext(context);
  }
  OpenCLKernelProgram(const OpenCLKernelProgram&) = delete;
  OpenCLKernelProgram& operator=(const OpenCLKernelProgram&) = delete;
};
#endif
