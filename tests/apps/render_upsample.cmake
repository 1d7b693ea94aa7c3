# `cohort render --render-scale 0.5`: paths at a quarter of the pixels, the rest reconstructed from the
# full-resolution G-buffer (core/upsample.h). On the test map with Embree, the joint-bilateral
# reconstruction must come close to a full-resolution render and closer than the nearest traced pixel and
# than a half-size frame stretched bilinearly, for the same paths per frame; each frame has an "upsample"
# stage. closer_to.py measures the mean difference of the written 8-bit images.
if(TARGET cohort)
  set(_dir ${CMAKE_BINARY_DIR}/test_output/render_upsample)
  set(_render "'$<TARGET_FILE:cohort>' render testmap --base '${CMAKE_SOURCE_DIR}/assets/testmap' --tracers embree --width 128 --height 72 --no-convergence --write last")
  add_test(NAME apps.render_upsample
           COMMAND bash -c "set -e; rm -rf '${_dir}'; mkdir -p '${_dir}'
             ${_render} --spp 256 --out '${_dir}/full'
             for m in joint-bilateral nearest bilinear; do ${_render} --spp 16 --frames 2 --render-scale 0.5 --upsample $m --out '${_dir}/'$m; done
             python3 -c \"import json,sys; d=json.load(open('${_dir}/joint-bilateral/stats.json')); n=[sum(1 for s in f['stages'] if s['stage'] == 'upsample') for f in d['frames']]; print('upsample stages per frame', n); sys.exit(0 if n == [1, 1] else 1)\"
             img() { ls \"${_dir}/$1\"/frame_000$2.p?g \"${_dir}/$1\"/frame_000$2.ppm 2>/dev/null | head -n 1; }
             python3 '${CMAKE_CURRENT_LIST_DIR}/closer_to.py' \"$(img full 0)\" \"$(img joint-bilateral 1)\" 7.5 \"$(img nearest 1)\" \"$(img bilinear 1)\"")
  set_tests_properties(apps.render_upsample PROPERTIES LABELS apps TIMEOUT 600)
endif()
