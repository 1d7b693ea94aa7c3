# kernel/upsample.h on devices: the OpenCL run is upsample_opencl_test.cpp; here a compile-only nvcc
# check where a CUDA compiler exists (as bvh_traverse_devices.cmake does for the traversal).
set(_upsample_nvcc "${CMAKE_CUDA_COMPILER}")
if(NOT _upsample_nvcc)
  find_program(_upsample_nvcc nvcc PATHS /usr/local/cuda/bin)
endif()
if(_upsample_nvcc)
  add_test(NAME kernel.upsample_nvcc_compiles
           COMMAND ${_upsample_nvcc} -x cu -c ${CMAKE_CURRENT_LIST_DIR}/upsample_cuda_check.cu
                   -I ${CMAKE_SOURCE_DIR}/kernel/include -o ${CMAKE_BINARY_DIR}/upsample_cuda_check.o)
  set_tests_properties(kernel.upsample_nvcc_compiles PROPERTIES LABELS kernel TIMEOUT 300)
endif()
