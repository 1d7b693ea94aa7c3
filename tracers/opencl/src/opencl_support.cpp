#include "opencl_support.h"

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <spdlog/spdlog.h>

namespace cohort::tracers {

void check(cl_int err, const char* what) {
  if (err != CL_SUCCESS) throw std::runtime_error(std::string("OpenCLTracer: ") + what + " failed (error " + std::to_string(err) + ")");
}

namespace {

// The built-in source, or with COHORT_OPENCL_SOURCE_DIR set, that folder's <program_name>.cl.
std::string program_source(const char* built_in, const char* program_name) {
  const char* dir = std::getenv("COHORT_OPENCL_SOURCE_DIR");
  if (!dir || !*dir) return built_in;
  const std::string path = std::string(dir) + "/" + program_name + ".cl";
  std::ifstream file(path, std::ios::binary);
  if (!file)
    throw std::runtime_error("OpenCLTracer: COHORT_OPENCL_SOURCE_DIR is set, but " + path + " cannot be read");
  std::ostringstream text;
  text << file.rdbuf();
  spdlog::warn("OpenCLTracer: building {} from {} instead of the built-in source (COHORT_OPENCL_SOURCE_DIR)",
               program_name, path);
  return text.str();
}

}  // namespace

cl_program build_program(cl_context context, cl_device_id device, const char* built_in_source,
                         const char* program_name, const std::string& options, const std::string& label) {
  cl_int err = CL_SUCCESS;
  const std::string text = program_source(built_in_source, program_name);
  const char* source = text.c_str();
  cl_program program = clCreateProgramWithSource(context, 1, &source, nullptr, &err);
  check(err, "clCreateProgramWithSource");
  err = clBuildProgram(program, 1, &device, options.c_str(), nullptr, nullptr);
  if (err != CL_SUCCESS) {
    size_t n = 0;
    clGetProgramBuildInfo(program, device, CL_PROGRAM_BUILD_LOG, 0, nullptr, &n);
    std::string log(n, '\0');
    clGetProgramBuildInfo(program, device, CL_PROGRAM_BUILD_LOG, n, log.data(), nullptr);
    clReleaseProgram(program);
    spdlog::error("OpenCLTracer: kernel build log for {} (options '{}'):\n{}", label, options, log);
    throw std::runtime_error("OpenCLTracer: kernel build failed on " + label + " (error " + std::to_string(err) +
                             "):\n" + log);
  }
  return program;
}

cl_kernel create_kernel(cl_program program, const char* name) {
  cl_int err = CL_SUCCESS;
  cl_kernel kernel = clCreateKernel(program, name, &err);
  check(err, (std::string("clCreateKernel(") + name + ")").c_str());
  return kernel;
}

cl_mem& grow_buffer(cl_context context, cl_mem& mem, size_t& capacity, size_t bytes, const char* what) {
  if (bytes > capacity) {
    if (mem) clReleaseMemObject(mem);
    mem = nullptr;
    capacity = 0;
    cl_int err = CL_SUCCESS;
    mem = clCreateBuffer(context, CL_MEM_READ_WRITE, bytes, nullptr, &err);
    check(err, what);
    capacity = bytes;
  }
  return mem;
}

}  // namespace cohort::tracers
