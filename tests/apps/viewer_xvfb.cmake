# `cohort play` under a virtual X display (Xvfb, Mesa software GL) for a few frames; the screenshot it
# writes must show a rendered image, not a blank or uniform one. Skips (exit 77) without xvfb-run or
# without the viewer built in.
if(TARGET cohort)
  find_package(Python3 COMPONENTS Interpreter QUIET)
  if(COHORT_WITH_VIEWER)
    set(_viewer_built 1)
  else()
    set(_viewer_built 0)
  endif()
  if(COHORT_WITH_OIIO)
    set(_shot_ext png)
  else()
    set(_shot_ext ppm)
  endif()
  add_test(NAME apps.viewer_xvfb
           COMMAND bash ${CMAKE_CURRENT_LIST_DIR}/viewer_xvfb.sh $<TARGET_FILE:cohort> ${_viewer_built}
                   ${CMAKE_SOURCE_DIR}/assets/testmap/maps/testmap.map
                   ${CMAKE_BINARY_DIR}/test_output/viewer_xvfb/screenshot.${_shot_ext}
                   ${CMAKE_CURRENT_LIST_DIR}/image_not_uniform.py)
  set_tests_properties(apps.viewer_xvfb PROPERTIES LABELS apps TIMEOUT 600 SKIP_RETURN_CODE 77)
  if(COHORT_SANITIZE)
    # Mesa's llvmpipe driver (dlopen'ed, no symbols) leaks a few hundred bytes at exit; the leak checker
    # cannot attribute them, so it is off for this test only. ASan's other checks stay on.
    set_tests_properties(apps.viewer_xvfb PROPERTIES ENVIRONMENT "ASAN_OPTIONS=detect_leaks=0")
  endif()
endif()
