# The committed test map (assets/testmap) must be exactly what tools/gen_testmap.py writes, and the
# generator's watertightness/winding/node checks must catch broken geometry.
find_program(COHORT_PYTHON3 python3)
if(COHORT_PYTHON3)
  add_test(NAME testmap_generator
           COMMAND ${COHORT_PYTHON3} ${CMAKE_SOURCE_DIR}/tests/scene/testmap_generator_test.py
                   --repo ${CMAKE_SOURCE_DIR} --work ${CMAKE_BINARY_DIR}/testmap_regenerated)
  set_tests_properties(testmap_generator PROPERTIES LABELS scene TIMEOUT 300)
endif()
