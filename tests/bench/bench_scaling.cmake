# The scaling benchmark at tiny sizes (two light counts, two triangle counts, 64x36) on Embree: it keeps
# running, and its JSON and chart get written. Speed is measured by running it in full, never here.
if(COHORT_WITH_EMBREE)
  add_test(NAME bench.scaling_smoke
           COMMAND bench_scaling --smoke --tracer embree --json ${CMAKE_BINARY_DIR}/test_out/bench_scaling.json
                   --plot ${CMAKE_BINARY_DIR}/test_out/bench_scaling.png)
  set_tests_properties(bench.scaling_smoke PROPERTIES LABELS bench TIMEOUT 300
                       PASS_REGULAR_EXPRESSION "wrote .*bench_scaling.json and .*bench_scaling.png")
endif()
