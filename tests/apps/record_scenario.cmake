# `cohort record-scenario`: a map without the scenario's entities is refused with their names; the test
# map records a stream.
if(TARGET cohort)
  add_test(NAME apps.record_scenario_names_missing
           COMMAND cohort record-scenario ${CMAKE_SOURCE_DIR}/tests/scene/data/base/maps/two_rooms.map
                   --frames 5 --out ${CMAKE_BINARY_DIR}/test_output/record_scenario/missing.cds)
  set_tests_properties(apps.record_scenario_names_missing PROPERTIES LABELS apps TIMEOUT 120
                       PASS_REGULAR_EXPRESSION "lacks entity 'door_main', entity 'fan_spin', light 'light_flicker'")
  if(EXISTS ${CMAKE_SOURCE_DIR}/assets/testmap)
    add_test(NAME apps.record_scenario_testmap
             COMMAND cohort record-scenario testmap --base ${CMAKE_SOURCE_DIR}/assets/testmap --frames 30
                     --out ${CMAKE_BINARY_DIR}/test_output/record_scenario/testmap.cds)
    set_tests_properties(apps.record_scenario_testmap PROPERTIES LABELS apps TIMEOUT 300
                         PASS_REGULAR_EXPRESSION "recorded 30 frames")
  endif()
endif()
