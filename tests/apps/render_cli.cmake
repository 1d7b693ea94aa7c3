# `cohort render` end to end: a small map from the scene tests on each built tracer kind, then a check
# that the image and the stats JSON were written.
if(TARGET cohort AND (TARGET cohort_tracer_embree OR TARGET cohort_tracer_opencl))
  set(_tracers "")
  if(TARGET cohort_tracer_embree)
    list(APPEND _tracers embree)
  endif()
  if(TARGET cohort_tracer_opencl)
    list(APPEND _tracers opencl)
  endif()
  string(REPLACE ";" "," _tracer_list "${_tracers}")
  set(_out ${CMAKE_BINARY_DIR}/test_output/render_cli)
  add_test(NAME apps.render_cli
           COMMAND ${CMAKE_COMMAND} -DCOHORT=$<TARGET_FILE:cohort> -DOUT=${_out} -DTRACERS=${_tracer_list}
                   -DMAP=${CMAKE_SOURCE_DIR}/tests/scene/data/base/maps/two_rooms.map
                   -P ${CMAKE_CURRENT_LIST_DIR}/check_render_cli.cmake-script)
  set_tests_properties(apps.render_cli PROPERTIES LABELS apps TIMEOUT 600)
endif()

# A port for joining nodes with no remote tracer (mpi:N) for them to serve is refused, naming the option
# (or, in a build without MPI, refused as needing it).
if(TARGET cohort)
  add_test(NAME apps.render_node_port_without_remote_tracer
           COMMAND cohort render ${CMAKE_SOURCE_DIR}/tests/scene/data/base/maps/two_rooms.map --tracers embree
                   --node-port ${CMAKE_BINARY_DIR}/test_output/unused_node_port --frames 1)
  set_tests_properties(apps.render_node_port_without_remote_tracer PROPERTIES LABELS apps
                       PASS_REGULAR_EXPRESSION "--node-port: (no remote tracer \\(mpi:N\\)|this build has no MPI)")
endif()
