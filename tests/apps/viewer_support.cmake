# The viewer's window-free parts are tested in the apps test executable.
if(TARGET cohort_apps_tests AND TARGET cohort_viewer_support)
  target_link_libraries(cohort_apps_tests PRIVATE cohort_viewer_support)
endif()
# The render command's helpers that need no tracer.
if(TARGET cohort_apps_tests)
  target_sources(cohort_apps_tests PRIVATE ${CMAKE_SOURCE_DIR}/apps/camera_path.cpp ${CMAKE_SOURCE_DIR}/apps/progress_bar.cpp)
endif()
