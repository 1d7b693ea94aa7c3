#!/usr/bin/env bash
# Usage: viewer_xvfb.sh COHORT VIEWER_BUILT MAP SCREENSHOT CHECKER  (see viewer_xvfb.cmake)
set -u
cohort=$1 viewer_built=$2 map=$3 shot=$4 checker=$5
if [ "$viewer_built" != 1 ]; then
  echo "SKIP: cohort was built without the viewer (COHORT_WITH_VIEWER=OFF); nothing to test"
  exit 77
fi
if ! command -v xvfb-run >/dev/null; then
  echo "SKIP: xvfb-run is not installed (Debian/Ubuntu: apt-get install xvfb)"
  exit 77
fi
if ! command -v python3 >/dev/null; then
  echo "SKIP: python3 is needed to check the screenshot"
  exit 77
fi
mkdir -p "$(dirname "$shot")"
window_shot="${shot%.*}_window.${shot##*.}"
rm -f "$shot" "$window_shot"
# The embree tracer is always on the CPU, so the test does not depend on a GPU; opencl (PoCL) joins
# when built, to exercise the balancer with two tracers.
set -x
xvfb-run -a -s "-screen 0 1024x768x24" "$cohort" play "$map" --frames 5 --width 160 --height 120 --scale 1 \
  --screenshot "$shot" --window-screenshot "$window_shot"
rc=$?
set +x
if [ $rc -ne 0 ]; then
  echo "FAIL: cohort play exited with $rc"
  exit 1
fi
# The rendered frame, and the window as drawn through the GL texture upload with the HUD over it.
python3 "$checker" "$shot" 160 120 && python3 "$checker" "$window_shot" 160 120 || exit 1
# The HUD layer is only as large as the HUD and sits at the top-left corner: below its rows the window
# shows the frame untouched. The trace names the viewer's own stages (the HUD and the present).
hud_window="${shot%.*}_hud_window.${shot##*.}" hud_frame="${shot%.*}_hud_frame.${shot##*.}"
trace="$(dirname "$shot")/play_trace.json"
rm -f "$hud_window" "$hud_frame" "$trace"
xvfb-run -a -s "-screen 0 1024x768x24" "$cohort" play "$map" --tracers embree --frames 4 --width 320 --height 240 \
  --scale 1 --spp 1 --no-scenario --screenshot "$hud_frame" --window-screenshot "$hud_window" --trace "$trace" ||
  { echo "FAIL: cohort play (HUD corner) exited with $?"; exit 1; }
python3 "$(dirname "$checker")/hud_in_corner.py" "$hud_window" "$hud_frame" 150 || exit 1
for stage in '"hud"' '"present"'; do
  grep -q "$stage" "$trace" || { echo "FAIL: no $stage stage in the play trace $trace"; exit 1; }
done
# With neither --spp nor --scale on CPU tracers the session holds 30 fps (spp and scale follow the frame
# time): it still shows a whole window.
auto_shot="${shot%.*}_auto_window.${shot##*.}"
rm -f "$auto_shot"
xvfb-run -a -s "-screen 0 1024x768x24" "$cohort" play "$map" --tracers embree --frames 12 --width 160 --height 120 \
  --window-screenshot "$auto_shot" || { echo "FAIL: cohort play (frame-rate target) exited with $?"; exit 1; }
python3 "$checker" "$auto_shot" 160 120
# The a-trous filter after the reprojection (host threads here): it still shows a whole window, and it is
# smoother than the same frames reprojected alone (the scenario off, so both see the same scene).
atrous_shot="${shot%.*}_atrous.${shot##*.}" plain_shot="${shot%.*}_reproject.${shot##*.}"
rm -f "$atrous_shot" "$plain_shot"
for denoise in atrous none; do
  out=$atrous_shot; [ $denoise = none ] && out=$plain_shot
  xvfb-run -a -s "-screen 0 1024x768x24" "$cohort" play "$map" --tracers embree --frames 6 --width 160 --height 120 \
    --scale 1 --spp 1 --no-scenario --convergence reproject --denoise $denoise --screenshot "$out" ||
    { echo "FAIL: cohort play --denoise $denoise exited with $?"; exit 1; }
done
python3 "$checker" "$atrous_shot" 160 120 && python3 "$(dirname "$checker")/smoother_than.py" "$atrous_shot" "$plain_shot" ||
  exit 1
# Open Image Denoise on each frame as rendered (--convergence none --denoise oidn): smoother than the same
# frames shown raw. Skipped where the library does not load (tools/fetch_oidn.sh).
oidn_shot="${shot%.*}_oidn.${shot##*.}" raw_shot="${shot%.*}_raw.${shot##*.}"
rm -f "$oidn_shot" "$raw_shot"
if xvfb-run -a -s "-screen 0 1024x768x24" "$cohort" play "$map" --tracers embree --frames 4 --width 160 --height 120 \
     --scale 1 --spp 1 --no-scenario --convergence none --denoise oidn --denoise-quality fast --screenshot "$oidn_shot" \
     2> "${shot%.*}_oidn_stderr.txt"; then
  xvfb-run -a -s "-screen 0 1024x768x24" "$cohort" play "$map" --tracers embree --frames 4 --width 160 --height 120 \
    --scale 1 --spp 1 --no-scenario --convergence none --denoise none --screenshot "$raw_shot" ||
    { echo "FAIL: cohort play --convergence none exited with $?"; exit 1; }
  python3 "$checker" "$oidn_shot" 160 120 && python3 "$(dirname "$checker")/smoother_than.py" "$oidn_shot" "$raw_shot" ||
    exit 1
elif grep -q "Open Image Denoise" "${shot%.*}_oidn_stderr.txt"; then
  echo "note: Open Image Denoise does not load here; the play --denoise oidn case is not run"
else
  cat "${shot%.*}_oidn_stderr.txt"; echo "FAIL: cohort play --denoise oidn"; exit 1
fi
# Dynamic resolution: at scale 0.5 the joint-bilateral reconstruction renders at the window's size (paths
# at a quarter of the pixels), so the frame itself is 160x120, not the 80x60 the bilinear stretch renders.
upsample_shot="${shot%.*}_upsample.${shot##*.}"
rm -f "$upsample_shot"
xvfb-run -a -s "-screen 0 1024x768x24" "$cohort" play "$map" --tracers embree --frames 6 --width 160 --height 120 \
  --scale 0.5 --spp 1 --upsample joint-bilateral --screenshot "$upsample_shot" ||
  { echo "FAIL: cohort play --upsample joint-bilateral exited with $?"; exit 1; }
python3 "$checker" "$upsample_shot" 160 120
