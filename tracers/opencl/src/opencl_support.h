// What the OpenCL tracer's files share to talk to the driver: errors as exceptions, programs built from
// embedded source (the build log on failure), device buffers that grow.
#pragma once

#include <CL/cl.h>

#include <string>

namespace cohort::tracers {

// Throws std::runtime_error naming `what` and the error code unless err is CL_SUCCESS.
void check(cl_int err, const char* what);

// The program built for `device` from `built_in_source` with `options`; throws with the build log (logged too)
// when it does not compile. label: the device, for the messages. With COHORT_OPENCL_SOURCE_DIR set, the source
// is that folder's `<program_name>.cl` instead (one file with its includes inlined, as
// `cmake -DPLAIN=1 ... -P tracers/opencl/embed_kernel.cmake` writes it), so kernels from another commit or an
// edit can run without rebuilding the host; their data layouts must be the host's.
cl_program build_program(cl_context context, cl_device_id device, const char* built_in_source,
                         const char* program_name, const std::string& options, const std::string& label);

// The kernel `name` of the program; throws naming it when there is none.
cl_kernel create_kernel(cl_program program, const char* name);

// A device buffer of at least `bytes` (`capacity`: its size), reallocated (contents lost) when smaller.
cl_mem& grow_buffer(cl_context context, cl_mem& mem, size_t& capacity, size_t bytes, const char* what);

}  // namespace cohort::tracers
