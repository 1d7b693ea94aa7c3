# `cohort devices`: the table (header, the CPU for Embree, the "all" line) and its JSON; and the warning
# when two requested tracers render on one device (here PoCL's named twice, since this machine may have
# no GPU: the same check names cuda:0 and opencl:1 on the GPU machine).
if(TARGET cohort_tracer_embree)
  add_test(NAME apps.devices_table COMMAND cohort devices)
  set_tests_properties(apps.devices_table PROPERTIES LABELS apps
                       PASS_REGULAR_EXPRESSION "tracer +kind +PCI bus id +device.*embree +CPU.*\nall +embree")
  add_test(NAME apps.devices_json COMMAND cohort devices --json)
  set_tests_properties(apps.devices_json PROPERTIES LABELS apps
                       PASS_REGULAR_EXPRESSION "\"all\": \"embree.*\"kind\": \"CPU\".*\"tracer\": \"embree\"")
endif()
if(TARGET cohort_tracer_opencl)
  add_test(NAME apps.devices_shared_gpu_warning
           COMMAND cohort render ${CMAKE_SOURCE_DIR}/tests/scene/data/base/maps/two_rooms.map --tracers opencl:0,opencl:0
                   --width 16 --height 8 --frames 1 --spp 1 --out ${CMAKE_BINARY_DIR}/test_output/devices_shared_gpu)
  set_tests_properties(apps.devices_shared_gpu_warning PROPERTIES LABELS apps TIMEOUT 300
                       PASS_REGULAR_EXPRESSION "tracer opencl:0 is named twice")
endif()
