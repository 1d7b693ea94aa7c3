# Reprojection followed by Open Image Denoise (`--convergence reproject --denoise oidn`): every frame goes
# through the denoiser after the reprojection (a `denoise` stage in stats.json); it used to be skipped
# once the reprojection moved into core::FramePost. Skips (exit 77) where the OIDN library does not load
# (tools/fetch_oidn.sh; COHORT_OIDN_DIR).
if(TARGET cohort)
  set(_dir ${CMAKE_BINARY_DIR}/test_output/render_reproject_oidn)
  add_test(NAME apps.render_reproject_oidn
           COMMAND bash -c "rm -rf '${_dir}'; mkdir -p '${_dir}'
             '$<TARGET_FILE:cohort>' record-scenario testmap --base '${CMAKE_SOURCE_DIR}/assets/testmap' --frames 3 --out '${_dir}/s.cdelta' || exit 1
             if ! '$<TARGET_FILE:cohort>' render --replay '${_dir}/s.cdelta' --base '${CMAKE_SOURCE_DIR}/assets/testmap' --tracers embree --width 48 --height 27 --spp 1 --convergence reproject --denoise oidn --denoise-quality fast --out '${_dir}/out' 2> '${_dir}/stderr.txt'; then
               if grep -q 'Open Image Denoise' '${_dir}/stderr.txt'; then echo 'skipped: OIDN does not load'; exit 77; fi
               cat '${_dir}/stderr.txt'; exit 1
             fi
             python3 -c \"import json,sys; d=json.load(open('${_dir}/out/stats.json')); n=[sum(1 for s in f['stages'] if s['stage'] == 'denoise') for f in d['frames']]; print(d['convergence'], n); sys.exit(0 if d['convergence'] == 'reproject' and n == [1, 1, 1] else 1)\"")
  set_tests_properties(apps.render_reproject_oidn PROPERTIES LABELS apps TIMEOUT 300 SKIP_RETURN_CODE 77)
endif()

# Without reprojection too, OIDN gets the frame's albedo and normal planes as its guides (the tracers are
# asked for them because the denoiser runs), from centre rays here, so marked clean (OIDN's cleanAux).
if(TARGET cohort)
  set(_dir ${CMAKE_BINARY_DIR}/test_output/render_oidn_guides)
  add_test(NAME apps.render_oidn_guides
           COMMAND bash -c "rm -rf '${_dir}'; mkdir -p '${_dir}'
             if ! '$<TARGET_FILE:cohort>' --log-level debug render '${CMAKE_SOURCE_DIR}/assets/testmap/maps/testmap.map' --tracers embree --width 48 --height 27 --spp 1 --frames 2 --no-convergence --denoise oidn --denoise-quality fast --aux-rays centre --out '${_dir}/out' > '${_dir}/log.txt' 2>&1; then
               if grep -q 'Open Image Denoise' '${_dir}/log.txt'; then echo 'skipped: OIDN does not load'; exit 77; fi
               cat '${_dir}/log.txt'; exit 1
             fi
             grep 'oidn (' '${_dir}/log.txt'
             test \"$(grep -c 'oidn (48x27, clean albedo and normal guides)' '${_dir}/log.txt')\" = 2")
  set_tests_properties(apps.render_oidn_guides PROPERTIES LABELS apps TIMEOUT 300 SKIP_RETURN_CODE 77)
endif()
