# Cluster runs under mpiexec on localhost (tests/mpi/run_cluster.py): rank 0 renders with Embree plus
# mpi:1 and mpi:2, ranks 1 and 2 run `cohort node` with Embree, and every frame must match the
# single-process render (with OpenCL on the nodes, PoCL where there is no GPU: within the tracers'
# agreement). Only where MPI was found. Open MPI refuses to start as root (CI runs as root)
# unless told twice that it is meant.
if(TARGET cohort AND TARGET cohort_tracer_mpi AND TARGET cohort_tracer_embree AND MPIEXEC_EXECUTABLE)
  # The remote tracer against a node over MPI with malformed messages (protocol_check.cpp).
  add_executable(mpi_protocol_check ${CMAKE_CURRENT_LIST_DIR}/protocol_check.cpp)
  target_link_libraries(mpi_protocol_check PRIVATE cohort_tracer_registry cohort_core cohort_test_support cohort_warnings)
  find_package(Python3 COMPONENTS Interpreter QUIET)
  if(Python3_Interpreter_FOUND)
    set(_cases match stall killed version load_error bench protocol replay play bad_piece ahead ahead_recovery jobs_ahead jobs_ahead_two_in_flight early_announce link
                match_rgb9e5 play_early_announce join rejoin rejoin_unready play_join)
    if(TARGET cohort_tracer_opencl)
      list(APPEND _cases mixed)
    endif()
    foreach(case ${_cases})
      add_test(NAME mpi.cluster_${case}
               COMMAND Python3::Interpreter ${CMAKE_CURRENT_LIST_DIR}/run_cluster.py ${case}
                       --mpiexec ${MPIEXEC_EXECUTABLE} --cohort $<TARGET_FILE:cohort>
                       --protocol-check $<TARGET_FILE:mpi_protocol_check>
                       --testmap-base ${CMAKE_SOURCE_DIR}/assets/testmap --viewer-built ${COHORT_WITH_VIEWER}
                       --map ${CMAKE_SOURCE_DIR}/tests/scene/data/base/maps/two_rooms.map
                       --broken-map ${CMAKE_SOURCE_DIR}/tests/scene/data/broken_base/maps/bad_proc.map
                       --out ${CMAKE_BINARY_DIR}/test_output/mpi_cluster_${case})
      set_tests_properties(mpi.cluster_${case} PROPERTIES LABELS mpi TIMEOUT 300 RUN_SERIAL TRUE SKIP_RETURN_CODE 77
                           ENVIRONMENT "OMPI_ALLOW_RUN_AS_ROOT=1;OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1")
    endforeach()
  endif()
endif()
