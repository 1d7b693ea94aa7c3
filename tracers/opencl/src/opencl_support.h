// What the OpenCL tracer's files share to talk to the driver: errors as exceptions, programs built from
// embedded source (the build log on failure), device buffers that grow.
#pragma once

#include <CL/cl.h>

#include <string>

namespace cohort::tracers {

// Throws std::runtime_error naming `what` and the error code unless err is CL_SUCCESS.
void check(cl_int err, const char* what);

// The program built for `device` from `source` with `options`; throws with the build log (logged too) when
// it does not compile. label: the device, for the messages.
cl_program build_program(cl_context context, cl_device_id device, const char* source, const std::string& options,
                         const std::string& label);

// The kernel `name` of the program; throws naming it when there is none.
cl_kernel create_kernel(cl_program program, const char* name);

// A device buffer of at least `bytes` (`capacity`: its size), reallocated (contents lost) when smaller.
cl_mem& grow_buffer(cl_context context, cl_mem& mem, size_t& capacity, size_t bytes, const char* what);

}  // namespace cohort::tracers
