# kernel/bvh_traverse.h on devices: an OpenCL run on whatever platform exists (PoCL on the CPU) and a
# compile-only nvcc check where a CUDA compiler exists.
if(TARGET cohort_kernel_tests)
  target_link_libraries(cohort_kernel_tests PRIVATE cohort_core)
  if(COHORT_WITH_OPENCL)
    target_link_libraries(cohort_kernel_tests PRIVATE OpenCL::OpenCL)
    target_compile_definitions(cohort_kernel_tests PRIVATE COHORT_HAVE_OPENCL=1 CL_TARGET_OPENCL_VERSION=120)
  endif()
endif()

cohort_nvcc_compile_check(kernel.bvh_traverse_nvcc_compiles ${CMAKE_CURRENT_LIST_DIR}/bvh_traverse_cuda_check.cu)
