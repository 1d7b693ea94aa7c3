# kernel/upsample.h on devices: the OpenCL run is upsample_opencl_test.cpp; here a compile-only nvcc
# check (tests/CMakeLists.txt's cohort_nvcc_compile_check).
cohort_nvcc_compile_check(kernel.upsample_nvcc_compiles ${CMAKE_CURRENT_LIST_DIR}/upsample_cuda_check.cu)
