# `cohort bench devices` end to end on a tiny image: every default mix (Embree, and OpenCL on PoCL
# where present) runs, and the table, JSON and bar chart are written; a missing tracer exits with 3.
add_test(NAME apps.bench_devices_smoke
         COMMAND cohort bench devices --scene ${CMAKE_SOURCE_DIR}/assets/testmap/maps/testmap.map --width 32 --height 16
                 --frames 4 --warmup 1
                 --json ${CMAKE_BINARY_DIR}/bench_devices_test.json --plot ${CMAKE_BINARY_DIR}/bench_devices_test.png)
set_tests_properties(apps.bench_devices_smoke PROPERTIES LABELS apps
                     PASS_REGULAR_EXPRESSION "median ms.*efficiency.*100.0%.*wrote .*bench_devices_test.json.*wrote .*bench_devices_test.png")
add_test(NAME apps.bench_devices_tracer_missing COMMAND cohort bench devices --frames 2 --warmup 0 --mix no-such-tracer)
set_tests_properties(apps.bench_devices_tracer_missing PROPERTIES LABELS apps
                     PASS_REGULAR_EXPRESSION "cohort bench devices: .*no-such-tracer")
add_test(NAME apps.bench_devices_warmup_too_long COMMAND cohort bench devices --frames 2 --warmup 2)
set_tests_properties(apps.bench_devices_warmup_too_long PROPERTIES LABELS apps WILL_FAIL TRUE)
# Through the frame pipeline with two frames in flight: the same table, from the intervals between frames.
add_test(NAME apps.bench_devices_pipeline
         COMMAND cohort bench devices --scene ${CMAKE_SOURCE_DIR}/assets/testmap/maps/testmap.map --width 32 --height 16
                 --frames 6 --warmup 2 --frames-in-flight 2 --mix embree --mix embree,embree
                 --json ${CMAKE_BINARY_DIR}/bench_devices_pipeline_test.json)
set_tests_properties(apps.bench_devices_pipeline PROPERTIES LABELS apps
                     PASS_REGULAR_EXPRESSION "median ms.*embree\\+embree.*wrote .*bench_devices_pipeline_test.json")
