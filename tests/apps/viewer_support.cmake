# The viewer's window-free parts are tested in the apps test executable.
if(TARGET cohort_apps_tests AND TARGET cohort_viewer_support)
  target_link_libraries(cohort_apps_tests PRIVATE cohort_viewer_support)
endif()
