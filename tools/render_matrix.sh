#!/usr/bin/env bash
# Renders the bundled test map once per debug mode on the Embree and OpenCL tracers, at a fixed seed,
# into OUT/<tracer>_<mode>.{png,exr} (PPM/PFM without OpenImageIO), so that two binaries can be held
# against each other:
#   tools/render_matrix.sh /tmp/cohort-before /tmp/before
#   tools/render_matrix.sh build/default/bin/cohort /tmp/after
#   tools/render_matrix.sh compare /tmp/before /tmp/after
# `compare` checks the 8-bit images byte for byte and the float images pixel for pixel with idiff (an
# EXR header carries a time stamp, so its bytes differ between any two runs). Optional third argument
# when rendering: extra `cohort render` options for every image.
set -euo pipefail
if [ "${1:-}" = compare ]; then
  before=${2:?usage: render_matrix.sh compare BEFORE AFTER}; after=${3:?usage: render_matrix.sh compare BEFORE AFTER}
  differ=0; count=0
  for f in "$before"/*.*; do
    g="$after/${f##*/}"; count=$((count + 1))
    case "$f" in
      *.exr) idiff -fail 0 -failpercent 0 "$f" "$g" >/dev/null 2>&1 || { echo "differs: ${f##*/}"; differ=$((differ + 1)); } ;;
      *) cmp -s "$f" "$g" || { echo "differs: ${f##*/}"; differ=$((differ + 1)); } ;;
    esac
  done
  echo "$((count - differ)) of $count images identical"
  [ "$differ" -eq 0 ]; exit
fi
cohort=${1:?usage: render_matrix.sh COHORT OUT [EXTRA_OPTIONS]}
out=${2:?usage: render_matrix.sh COHORT OUT [EXTRA_OPTIONS]}
extra=${3:-}
here=$(cd "$(dirname "$0")/.." && pwd)
mkdir -p "$out"
for tracer in embree opencl; do
  for mode in path direct albedo normals specular bvh triangles; do
    # shellcheck disable=SC2086
    "$cohort" render "$here/assets/testmap/maps/testmap.map" --tracers "$tracer" --mode "$mode" \
      --width 160 --height 90 --spp 2 --frames 2 --write last --out "$out/tmp" $extra >/dev/null 2>&1
    for f in "$out"/tmp/frame_0001.*; do mv "$f" "$out/${tracer}_${mode}.${f##*.}"; done
    rm -rf "$out/tmp"
  done
done
ls "$out" | wc -l
