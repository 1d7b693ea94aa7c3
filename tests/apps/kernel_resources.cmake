# tools/kernel_resources.py, the ptxas table a kernel change is checked with before a GPU run
# (tests/apps/kernel_resources_test.py); only where nvcc is (no GPU needed).
if(_cohort_nvcc)
  find_package(Python3 COMPONENTS Interpreter REQUIRED)
  add_test(NAME apps.kernel_resources
           COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_LIST_DIR}/kernel_resources_test.py
                   ${CMAKE_SOURCE_DIR}/tools/kernel_resources.py ${_cohort_nvcc})
  set_tests_properties(apps.kernel_resources PROPERTIES LABELS apps TIMEOUT 120)
endif()
