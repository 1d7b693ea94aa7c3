# `cohort render --denoise atrous`: the tracers write the auxiliary planes, every frame goes through the
# a-trous filter (a "denoise" stage in each frame's timeline, "convergence+denoise" where it runs with the
# reprojection, the CPU-only default), and the written frame is a picture.
if(TARGET cohort)
  set(_dir ${CMAKE_BINARY_DIR}/test_output/render_atrous)
  add_test(NAME apps.render_atrous
           COMMAND bash -c "set -e; rm -rf '${_dir}'; mkdir -p '${_dir}'
             '$<TARGET_FILE:cohort>' render testmap --base '${CMAKE_SOURCE_DIR}/assets/testmap' --tracers embree --width 96 --height 54 --spp 1 --frames 3 --denoise atrous --write last --out '${_dir}/out'
             python3 -c \"import json,sys; d=json.load(open('${_dir}/out/stats.json')); n=[sum(1 for s in f['stages'] if s['stage'] in ('denoise', 'convergence+denoise')) for f in d['frames']]; print('denoise stages per frame', n); sys.exit(0 if n == [1, 1, 1] else 1)\"
             python3 '${CMAKE_CURRENT_LIST_DIR}/image_not_uniform.py' \"$(ls '${_dir}'/out/frame_0002.p?g '${_dir}'/out/frame_0002.ppm 2>/dev/null | head -n 1)\" 96 54")
  set_tests_properties(apps.render_atrous PROPERTIES LABELS apps TIMEOUT 300)
endif()
