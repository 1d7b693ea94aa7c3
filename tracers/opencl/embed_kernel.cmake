# Build step: inlines the quoted #includes of the OpenCL entry file (resolved against the including
# file's folder, then INCLUDE_ROOT), each file once, and writes the result as a C++ string so the
# tracer has no run-time dependence on the source tree.
# NAME: the string's name in cohort::tracers::opencl_source (default kRenderBand).
# PLAIN=1: write the inlined OpenCL C itself instead, for COHORT_OPENCL_SOURCE_DIR (opencl_support.h).
#   cmake -DENTRY=... -DINCLUDE_ROOT=... -DOUTPUT=... [-DNAME=...] [-DPLAIN=1] -P embed_kernel.cmake
cmake_minimum_required(VERSION 3.25)
set(_seen "")
function(_inline file out_var)
  get_filename_component(dir ${file} DIRECTORY)
  if("${file}" IN_LIST _seen)
    set(${out_var} "" PARENT_SCOPE)
    return()
  endif()
  list(APPEND _seen ${file})
  file(READ ${file} text)
  string(REGEX MATCHALL "#[ \t]*include[ \t]+\"[^\"]+\"" directives "${text}")
  foreach(directive IN LISTS directives)
    string(REGEX REPLACE "#[ \t]*include[ \t]+\"([^\"]+)\"" "\\1" name "${directive}")
    if(EXISTS ${dir}/${name})
      set(target ${dir}/${name})
    elseif(EXISTS ${INCLUDE_ROOT}/${name})
      set(target ${INCLUDE_ROOT}/${name})
    else()
      message(FATAL_ERROR "embed_kernel: ${file}: cannot find \"${name}\"")
    endif()
    get_filename_component(target ${target} REALPATH)
    _inline(${target} inner)
    string(REPLACE "${directive}" "/* ${name} */\n${inner}" text "${text}")
  endforeach()
  set(_seen ${_seen} PARENT_SCOPE)
  set(${out_var} "${text}" PARENT_SCOPE)
endfunction()

if(NOT NAME)
  set(NAME kRenderBand)
endif()
get_filename_component(entry ${ENTRY} REALPATH)
_inline(${entry} source)
if(PLAIN)
  file(WRITE ${OUTPUT} "${source}")
  return()
endif()
file(WRITE ${OUTPUT}.tmp "// Generated from ${ENTRY} by embed_kernel.cmake; do not edit.\n"
     "namespace cohort::tracers::opencl_source {\nextern const char* const ${NAME};\n"
     "const char* const ${NAME} = R\"COHORTCL(\n${source})COHORTCL\";\n}\n")
execute_process(COMMAND ${CMAKE_COMMAND} -E copy_if_different ${OUTPUT}.tmp ${OUTPUT})
