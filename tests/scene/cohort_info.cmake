# `cohort info` end to end: the test map loads with no warnings, and a broken .proc fails with exit
# status 1 and the parser's file:line message.
if(TARGET cohort)
  add_test(NAME scene.cohort_info.testmap
           COMMAND cohort info testmap --base ${CMAKE_SOURCE_DIR}/assets/testmap)
  set_tests_properties(scene.cohort_info.testmap PROPERTIES LABELS scene
                       PASS_REGULAR_EXPRESSION "  sky +1 \\(cube maps[^\n]*environment maps 1 [^\n]*noSelfShadow 1\n.*lights +13: 10 point, 2 projected, 1 parallel\n  kinds +10 normal, 1 fog, 1 blend, 1 ambient.*unresolved 0 classes, 0 models.*warnings +0")
  add_test(NAME scene.cohort_info.broken_proc
           COMMAND sh -c "out=$(\"$0\" info \"$1\" 2>&1); rc=$?; echo \"$out\"; [ $rc -eq 1 ] && echo \"$out\" | grep -q \"$2\""
                   $<TARGET_FILE:cohort> ${CMAKE_CURRENT_LIST_DIR}/data/broken_base/maps/bad_proc.map
                   "bad_proc.proc:5:[0-9]*: expected a number for an index")
  set_tests_properties(scene.cohort_info.broken_proc PROPERTIES LABELS scene)
endif()
