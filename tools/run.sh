#!/usr/bin/env bash
# The main job on a fresh machine: install packages, build, and render the bundled test map on every
# available tracer, writing out/quickstart/frame.png (and .exr) and out/quickstart/stats.json.
set -euo pipefail
cd "$(dirname "$0")/.."
./tools/setup.sh
cmake --preset default
cmake --build --preset default
./build/default/bin/cohort render assets/testmap/maps/testmap.map --tracers all --frames 8 \
  --write last --out out/quickstart "$@"
