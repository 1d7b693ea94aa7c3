# Finds Cohort's dependencies and sets the COHORT_WITH_* options. Hardware-dependent parts default to
# ON when found and are skipped with a message when not.
find_package(Threads REQUIRED)
find_package(glm REQUIRED)
find_package(CLI11 REQUIRED)
find_package(nlohmann_json 3 REQUIRED)
find_package(fmt REQUIRED)
find_package(spdlog REQUIRED)
find_package(PkgConfig REQUIRED)
pkg_check_modules(LIBZIP REQUIRED IMPORTED_TARGET libzip)

option(COHORT_BUILD_TESTS "Build the GoogleTest suites" ON)
if(COHORT_BUILD_TESTS)
  find_package(GTest REQUIRED)
endif()

# OpenImageIO: texture loading and EXR/PNG output. Optional so that a binary can travel to machines
# that lack its very large shared-library closure (see README, "GPU machine").
# Debian's OpenImageIO CMake package insists on OpenCV's headers; its pkg-config file does not.
pkg_check_modules(OIIO QUIET IMPORTED_TARGET OpenImageIO)
set(_oiio_default OFF)
if(OIIO_FOUND)
  set(_oiio_default ON)
  add_library(OpenImageIO::OpenImageIO ALIAS PkgConfig::OIIO)
endif()
option(COHORT_WITH_OIIO "Load textures and write images through OpenImageIO" ${_oiio_default})
if(COHORT_WITH_OIIO AND NOT OIIO_FOUND)
  message(FATAL_ERROR "COHORT_WITH_OIIO=ON but OpenImageIO was not found (install libopenimageio-dev)")
endif()

# Embree and TBB: the core builds every BVH through Embree's rtcBuildBVH (multithreaded through TBB),
# so both are required; COHORT_WITH_EMBREE only chooses whether the Embree CPU tracer is built.
find_package(embree 3 REQUIRED)
find_package(TBB REQUIRED)
option(COHORT_WITH_EMBREE "Build the Embree CPU tracer" ON)

# An option that is ON by default where what it needs was found, and refused with `missing` (what is
# absent and how to install it) where it is asked for but was not found.
function(cohort_detected_option name description found missing)
  set(_default OFF)
  if(found)
    set(_default ON)
  endif()
  option(${name} "${description}" ${_default})
  if(${name} AND NOT found)
    message(FATAL_ERROR "${name}=ON but ${missing}")
  endif()
endfunction()

find_package(OpenCL QUIET)
cohort_detected_option(COHORT_WITH_OPENCL "Build the OpenCL tracer" "${OpenCL_FOUND}"
                       "OpenCL headers/loader were not found (install ocl-icd-opencl-dev opencl-headers)")

include(CheckLanguage)
check_language(CUDA)
cohort_detected_option(COHORT_WITH_CUDA "Build the CUDA tracer (needs nvcc; runs only where a GPU is present)"
                       "${CMAKE_CUDA_COMPILER}" "no CUDA compiler was found")
if(COHORT_WITH_CUDA)
  if(NOT DEFINED CMAKE_CUDA_ARCHITECTURES)
    set(CMAKE_CUDA_ARCHITECTURES "90-real;90-virtual")   # Hopper SASS plus PTX for newer GPUs
  endif()
  set(CMAKE_CUDA_STANDARD 17)
  set(CMAKE_CUDA_STANDARD_REQUIRED ON)
  enable_language(CUDA)
  find_package(CUDAToolkit REQUIRED)
endif()

# MPI: remote tracers on other processes or machines (tracers/mpi, `cohort node`, docs/cluster.md). Any
# MPI-3 library (Open MPI, MPICH) through the standard interface only.
find_package(MPI QUIET COMPONENTS CXX)
cohort_detected_option(COHORT_WITH_MPI "Build the remote tracers over MPI (cohort node, mpi:RANK)" "${MPI_CXX_FOUND}"
                       "no MPI for C++ was found (install libopenmpi-dev openmpi-bin)")

find_package(glfw3 3.3 QUIET)
find_package(OpenGL QUIET)
set(_viewer_found OFF)
if(glfw3_FOUND AND OpenGL_FOUND)
  set(_viewer_found ON)
endif()
cohort_detected_option(COHORT_WITH_VIEWER "Build the GLFW gameplay viewer (cohort play)" "${_viewer_found}"
                       "GLFW 3.3+/OpenGL were not found (install libglfw3-dev libgl-dev)")

set(_fuzz_default OFF)
if(CMAKE_CXX_COMPILER_ID MATCHES "Clang")
  set(_fuzz_default ON)
endif()
option(COHORT_FUZZERS "Build libFuzzer targets (needs clang)" ${_fuzz_default})

# Header-only logging and formatting keep the binary free of extra shared libraries.
add_library(cohort_logging INTERFACE)
target_link_libraries(cohort_logging INTERFACE spdlog::spdlog_header_only fmt::fmt-header-only)

# A module library from the sources in its src/ folder (an interface target while it has none yet).
function(cohort_module name)
  file(GLOB sources CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/src/*.cpp)
  if(sources)
    add_library(${name} STATIC ${sources})
    target_include_directories(${name} PUBLIC ${CMAKE_CURRENT_SOURCE_DIR}/include)
    target_link_libraries(${name} PRIVATE cohort_warnings)
  else()
    add_library(${name} INTERFACE)
    target_include_directories(${name} INTERFACE ${CMAKE_CURRENT_SOURCE_DIR}/include)
  endif()
endfunction()

# Link dependencies with the right keyword whether the module is compiled or still header-only.
function(cohort_module_link name)
  get_target_property(type ${name} TYPE)
  if(type STREQUAL "INTERFACE_LIBRARY")
    list(FILTER ARGN EXCLUDE REGEX "^(PUBLIC|PRIVATE|INTERFACE)$")
    target_link_libraries(${name} INTERFACE ${ARGN})
  else()
    target_link_libraries(${name} ${ARGN})
  endif()
endfunction()
