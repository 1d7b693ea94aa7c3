#!/usr/bin/env bash
# Builds the scene parsers' libFuzzer targets with clang (ASan+UBSan) in build/fuzz and runs each for a
# bounded time. Usage: tools/fuzz.sh [seconds per target, default 30] [targets: proc map mtr image ase lwo md5 def].
# New interesting inputs go to build/fuzz/corpus/<target>; crashes to build/fuzz/artifacts/<target>/ —
# copy a crash input into scene/fuzz/corpus/<target>/ once fixed, so the corpus replay test keeps it.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-30}
shift || true
targets=${*:-proc map mtr image ase lwo md5 def}
jobs=${JOBS:-2}

command -v clang++ >/dev/null || { echo "fuzz.sh: clang++ is needed for libFuzzer" >&2; exit 3; }
cmake -S . -B build/fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ -DCOHORT_FUZZERS=ON -DCOHORT_BUILD_TESTS=OFF \
  -DCMAKE_CXX_FLAGS="-fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=undefined" \
  -DCOHORT_WITH_OIIO=OFF -DCOHORT_WITH_CUDA=OFF -DCOHORT_WITH_OPENCL=OFF -DCOHORT_WITH_EMBREE=OFF \
  -DCOHORT_WITH_VIEWER=OFF >/dev/null
cmake --build build/fuzz -j"$jobs" --target $(for t in $targets; do printf 'cohort_fuzz_%s ' "$t"; done)

# The generated test map's files are seeds too, when present.
seeds_from_testmap() {
  case "$1" in
    proc|map) [ -d assets/testmap/maps ] && echo assets/testmap/maps ;;
    mtr) [ -d assets/testmap/materials ] && echo assets/testmap/materials ;;
    image) [ -d assets/testmap/lights ] && echo assets/testmap/lights ;;
    ase|lwo|md5) [ -d assets/testmap/models ] && echo assets/testmap/models ;;
    def) [ -d assets/testmap/def ] && echo assets/testmap/def assets/testmap/skins ;;
  esac
  return 0
}

status=0
for t in $targets; do
  mkdir -p "build/fuzz/corpus/$t" "build/fuzz/artifacts/$t"
  echo "== fuzzing $t for ${seconds}s"
  if ! "build/fuzz/bin/cohort_fuzz_$t" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
       -max_len=65536 -print_final_stats=1 -artifact_prefix="build/fuzz/artifacts/$t/" \
       "build/fuzz/corpus/$t" "scene/fuzz/corpus/$t" $(seeds_from_testmap "$t") 2>"build/fuzz/$t.log"; then
    echo "!! $t: fuzzer found a failure; see build/fuzz/$t.log and build/fuzz/artifacts/$t/" >&2
    tail -40 "build/fuzz/$t.log" >&2
    status=1
  else
    grep -E "stat::number_of_executed_units|stat::peak_rss_mb" "build/fuzz/$t.log" | sed "s/^/   $t /"
  fi
done
exit $status
