# bench/quality/bench_quality.py along the recorded scenario (--scenario), tiny and at 4 spp for the
# reference: the door_main mask comes from the reference's id planes, the door moves in frames 11-40 at 20
# scenario fps, so its "4 frames still" FLIP is frame 44's, and the reprojection reports it. Skips (exit 77)
# where .venv-quality (bench/quality/setup_env.sh) with flip-evaluator is missing.
if(TARGET cohort)
  set(_dir ${CMAKE_BINARY_DIR}/test_output/bench_quality_scenario)
  set(_py ${CMAKE_SOURCE_DIR}/.venv-quality/bin/python)
  add_test(NAME apps.bench_quality_scenario
           COMMAND bash -c "set -e
             if ! [ -x '${_py}' ] || ! '${_py}' -c 'import flip_evaluator, numpy, matplotlib' 2>/dev/null; then
               echo 'skipped: no .venv-quality with flip-evaluator (bench/quality/setup_env.sh)'; exit 77; fi
             rm -rf '${_dir}'
             '${_py}' '${CMAKE_SOURCE_DIR}/bench/quality/bench_quality.py' --cohort '$<TARGET_FILE:cohort>' --scenario \
               --frames 45 --width 64 --height 36 --ref-spp 4 --methods reproject --out '${_dir}'
             '${_py}' -c \"import json, math, sys
d = json.load(open('${_dir}/bench_quality.json'))
m = d['mask']
ok = m['entity'] == 'door_main' and m['moving_frames'][0] == 11 and m['last_moving_frame'] == 40 and m['still_frame'] == 44
ok = ok and all(p > 0 for p in m['pixels'])
for name, r in d['methods'].items():
    v = r['object_flip_still']
    print(name, 'mean FLIP', sum(r['flip']) / len(r['flip']), 'door after 4 still frames', v)
    ok = ok and v is not None and 0.0 < v < 1.0 and len(r['object_flip']) == 45
    ok = ok and len(r['light_percent']) == 45 and all(math.isfinite(x) and abs(x) < 100.0 for x in r['light_percent'])
sys.exit(0 if ok else 1)\"")
  set_tests_properties(apps.bench_quality_scenario PROPERTIES LABELS apps TIMEOUT 300 SKIP_RETURN_CODE 77)
endif()
