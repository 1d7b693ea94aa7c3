# tools/frame_times.py, the summary every GPU run's figures come from (tests/apps/frame_times_test.py).
find_package(Python3 COMPONENTS Interpreter REQUIRED)
add_test(NAME apps.frame_times
         COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_LIST_DIR}/frame_times_test.py ${CMAKE_SOURCE_DIR}/tools/frame_times.py)
set_tests_properties(apps.frame_times PROPERTIES LABELS apps TIMEOUT 60)
