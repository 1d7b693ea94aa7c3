# A recorded scenario replays through `cohort render --replay`: every recorded frame is rendered, and
# with only a CPU tracer the default convergence (auto) is reprojection.
if(TARGET cohort)
  set(_dir ${CMAKE_BINARY_DIR}/test_output/render_replay)
  add_test(NAME apps.render_replay
           COMMAND bash -c "set -e; rm -rf '${_dir}'; mkdir -p '${_dir}'
             '$<TARGET_FILE:cohort>' record-scenario testmap --base '${CMAKE_SOURCE_DIR}/assets/testmap' --frames 5 --out '${_dir}/s.cdelta'
             '$<TARGET_FILE:cohort>' render --replay '${_dir}/s.cdelta' --base '${CMAKE_SOURCE_DIR}/assets/testmap' --tracers embree --width 64 --height 36 --spp 1 --write last --out '${_dir}/out'
             python3 -c \"import json,sys; d=json.load(open('${_dir}/out/stats.json')); n=len(d['frames']); print(n, 'frames', d['convergence']); sys.exit(0 if n == 5 and d['convergence'] == 'reproject' else 1)\"")
  set_tests_properties(apps.render_replay PROPERTIES LABELS apps TIMEOUT 300)
endif()

# The same replay with reprojection (--convergence reproject): every tracer writes the auxiliary planes,
# the door's motion reaches the history, and the history grows past one frame (convergence_f < 1).
if(TARGET cohort)
  set(_dir ${CMAKE_BINARY_DIR}/test_output/render_replay_reproject)
  add_test(NAME apps.render_replay_reproject
           COMMAND bash -c "set -e; rm -rf '${_dir}'; mkdir -p '${_dir}'
             '$<TARGET_FILE:cohort>' record-scenario testmap --base '${CMAKE_SOURCE_DIR}/assets/testmap' --frames 5 --out '${_dir}/s.cdelta'
             '$<TARGET_FILE:cohort>' render --replay '${_dir}/s.cdelta' --base '${CMAKE_SOURCE_DIR}/assets/testmap' --tracers embree --width 64 --height 36 --spp 1 --convergence reproject --write last --out '${_dir}/out'
             python3 -c \"import json,sys; d=json.load(open('${_dir}/out/stats.json')); f=[x['convergence_f'] for x in d['frames']]; print(d['convergence'], f); sys.exit(0 if d['convergence'] == 'reproject' and len(f) == 5 and f[-1] < 0.9 else 1)\"")
  set_tests_properties(apps.render_replay_reproject PROPERTIES LABELS apps TIMEOUT 300)
endif()
