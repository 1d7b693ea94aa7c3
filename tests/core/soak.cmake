# The full reliability soak (20,000 frames, a minute or more): label `soak`, which the test presets
# leave out; run it with `ctest --test-dir build/default -L soak`. The default run has the short one.
if(TARGET cohort_core_tests)
  add_test(NAME core.soak.full COMMAND cohort_core_tests --gtest_filter=Soak.*)
  set_tests_properties(core.soak.full PROPERTIES LABELS "soak" ENVIRONMENT "COHORT_SOAK_FRAMES=20000" TIMEOUT 3600)
endif()
