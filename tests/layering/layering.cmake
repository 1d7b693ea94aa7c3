# The module dependency direction (README, docs/architecture.md): the real tree obeys it, and the
# checker rejects a tree that breaks it.
find_package(Python3 COMPONENTS Interpreter REQUIRED)
add_test(NAME layering.direction COMMAND ${Python3_EXECUTABLE} ${CMAKE_SOURCE_DIR}/tools/check_layering.py ${CMAKE_SOURCE_DIR})
add_test(NAME layering.checker_rejects_violations
         COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_LIST_DIR}/check_layering_test.py ${CMAKE_SOURCE_DIR}/tools/check_layering.py)
set_tests_properties(layering.direction layering.checker_rejects_violations PROPERTIES LABELS layering TIMEOUT 60)
