#!/usr/bin/env bash
# Writes the OpenCL tracer's two programs as they were at a commit, as plain OpenCL C, into a folder for
# COHORT_OPENCL_SOURCE_DIR: one binary then runs the kernels of several commits (a bisect on a GPU without a
# build per commit). The host's data layouts must be the commit's; the kernels' own code may differ.
#   tools/opencl_source_at.sh COMMIT OUTDIR
set -euo pipefail
if [[ $# -ne 2 ]]; then
  echo "usage: $0 COMMIT OUTDIR" >&2
  exit 2
fi
commit=$1
out=$2
repo=$(git -C "$(dirname "$0")" rev-parse --show-toplevel)
tree=$(mktemp -d)
trap 'rm -rf "$tree"' EXIT
git -C "$repo" archive "$commit" kernel/include tracers/opencl/kernel | tar -C "$tree" -x
mkdir -p "$out"
for entry in render_band wavefront_walk; do
  cmake -DENTRY="$tree/tracers/opencl/kernel/$entry.cl" -DINCLUDE_ROOT="$tree/kernel/include" \
        -DOUTPUT="$out/$entry.cl" -DPLAIN=1 -P "$repo/tracers/opencl/embed_kernel.cmake"
done
echo "$out: render_band.cl, wavefront_walk.cl of $(git -C "$repo" rev-parse --short "$commit")"
