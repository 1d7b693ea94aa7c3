# `cohort render` of a map evaluates its materials' registers at each frame's game time (--time,
# --time-step): with the time frozen two renders of frame 1 are identical, with time running frame 1
# differs where the test map's materials animate (scrolling, pulsing, flickering), while frame 0 (same
# time in both) stays identical. One spp, no accumulation: a frame's noise depends only on its index.
if(TARGET cohort)
  set(_dir ${CMAKE_BINARY_DIR}/test_output/render_material_time)
  set(_render "'$<TARGET_FILE:cohort>' render testmap --base '${CMAKE_SOURCE_DIR}/assets/testmap' --tracers embree --width 96 --height 54 --spp 1 --frames 2 --no-convergence --balancer none")
  add_test(NAME apps.render_material_time
           COMMAND bash -c "set -e; rm -rf '${_dir}'; mkdir -p '${_dir}'
             ${_render} --time-step 0 --out '${_dir}/frozen'
             ${_render} --time-step 0 --out '${_dir}/frozen_again'
             ${_render} --time-step 700 --out '${_dir}/running'
             img() { ls \"$1\"/frame_000$2.p?g \"$1\"/frame_000$2.ppm 2>/dev/null | head -n 1; }
             python3 '${CMAKE_CURRENT_LIST_DIR}/compare_images.py' \"$(img '${_dir}/frozen' 1)\" \"$(img '${_dir}/frozen_again' 1)\" same
             python3 '${CMAKE_CURRENT_LIST_DIR}/compare_images.py' \"$(img '${_dir}/frozen' 0)\" \"$(img '${_dir}/running' 0)\" same
             python3 '${CMAKE_CURRENT_LIST_DIR}/compare_images.py' \"$(img '${_dir}/frozen' 1)\" \"$(img '${_dir}/running' 1)\" differ")
  set_tests_properties(apps.render_material_time PROPERTIES LABELS apps TIMEOUT 300)
endif()
