# The large generated map (tools/gen_testmap.py --large, not committed): generated once into the build
# tree by a fixture, then checked with `cohort info` (counts match the generator, targets met, no
# warnings) and for determinism (a second generation in a fresh process gives the same bytes).
find_program(COHORT_PYTHON3 python3)
if(COHORT_PYTHON3)
  set(COHORT_LARGEMAP_DIR ${CMAKE_BINARY_DIR}/assets/largemap)
  set(COHORT_LARGEMAP_TEST ${CMAKE_CURRENT_LIST_DIR}/largemap_test.py)
  # `cmake --build --preset <p> --target largemap` generates it without running the tests.
  add_custom_target(largemap
                    COMMAND ${COHORT_PYTHON3} ${CMAKE_SOURCE_DIR}/tools/gen_testmap.py --large
                            --out ${COHORT_LARGEMAP_DIR}
                    COMMENT "Generating the large map into ${COHORT_LARGEMAP_DIR}" VERBATIM)
  add_test(NAME scene.largemap.generate
           COMMAND ${COHORT_PYTHON3} ${COHORT_LARGEMAP_TEST} generate --repo ${CMAKE_SOURCE_DIR}
                   --out ${COHORT_LARGEMAP_DIR})
  set_tests_properties(scene.largemap.generate PROPERTIES FIXTURES_SETUP largemap LABELS scene TIMEOUT 300
                       RESOURCE_LOCK largemap_dir)
  add_test(NAME scene.largemap.deterministic
           COMMAND ${COHORT_PYTHON3} ${COHORT_LARGEMAP_TEST} deterministic --repo ${CMAKE_SOURCE_DIR}
                   --out ${COHORT_LARGEMAP_DIR})
  set_tests_properties(scene.largemap.deterministic PROPERTIES FIXTURES_REQUIRED largemap LABELS scene
                       TIMEOUT 300)
  if(TARGET cohort)
    add_test(NAME scene.largemap.cohort_info
             COMMAND ${COHORT_PYTHON3} ${COHORT_LARGEMAP_TEST} info --cohort $<TARGET_FILE:cohort>
                     --out ${COHORT_LARGEMAP_DIR})
    set_tests_properties(scene.largemap.cohort_info PROPERTIES FIXTURES_REQUIRED largemap LABELS scene
                         TIMEOUT 120)
    # Issue 16's bad-input rule: no NaN or Inf pixel in any frame of the large map.
    add_test(NAME scene.largemap.frames_finite
             COMMAND ${COHORT_PYTHON3} ${COHORT_LARGEMAP_TEST} frames --cohort $<TARGET_FILE:cohort>
                     --out ${COHORT_LARGEMAP_DIR})
    set_tests_properties(scene.largemap.frames_finite PROPERTIES FIXTURES_REQUIRED largemap LABELS scene
                         TIMEOUT 300)
  endif()
endif()
