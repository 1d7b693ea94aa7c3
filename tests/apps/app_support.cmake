# The apps test executable links the code the app itself runs (cohort_app_support: camera paths, the
# progress bar, the viewer's window-free parts, the raster) instead of compiling app sources again.
if(TARGET cohort_apps_tests)
  target_link_libraries(cohort_apps_tests PRIVATE cohort_app_support)
endif()
