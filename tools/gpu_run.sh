#!/usr/bin/env bash
# Runs Cohort's CUDA tests and benchmarks on the GPU machine lent by the `device` tool.
#
#   tools/gpu_run.sh stage     here: build the gpu-travel preset (CUDA on, no OpenImageIO, no viewer),
#                              pack the test map, and put binaries + Embree/TBB/libzip beside them in .gpu/;
#                              with COHORT_GPU_LARGEMAP=1 also generate and pack the large map (~28 MB more)
#   tools/gpu_run.sh remote    there (device tool: run command "bash tools/gpu_run.sh remote", carry [".gpu"]):
#                              registers NVIDIA's OpenCL, runs the GPU tests and benchmarks, writes
#                              results (logs, JSON, PPM frames) to $OUT
#   tools/gpu_run.sh multigpu  there, on a several-GPU kind: issue 14's end-to-end mixes (two GPUs, each with
#                              Embree and OpenCL), bench devices on both maps, Table 1 with two real GPUs. The
#                              OpenCL tracer of the mixes is the OpenCL device on the second GPU (the one cuda:1
#                              drives), found by PCI bus id in `cohort devices --json`; COHORT_GPU_OPENCL=opencl:N
#                              names another (opencl:N counts every platform's devices: PoCL's CPU may be one);
#                              COHORT_GPU_IN_FLIGHT="1 2" renders each mix with --frames-in-flight 1 then 2, back to
#                              back, COHORT_GPU_ROUNDS times (default 1; docs/balancing.md, "Two frames in flight");
#                              OPENCL in COHORT_GPU_MIXES stands for that OpenCL tracer (e.g. "embree,cuda:0,OPENCL");
#                              COHORT_GPU_MAPS="test" leaves the large map out;
#                              COHORT_GPU_ENQUEUE_AHEAD="1 0" renders each of those with COHORT_OPENCL_ENQUEUE_AHEAD=1
#                              then 0, back to back (the OpenCL tracer's next band enqueued while the current one
#                              renders, with two in flight; docs/balancing.md, "OpenCL enqueues its next band ahead")
#                              COHORT_GPU_TEST_FILTER names the tracer tests run first (default 'CudaMultiGpu*:FramePost*')
#                              COHORT_GPU_TRANSFER_QUEUE="1 0" renders each of those with COHORT_OPENCL_TRANSFER_QUEUE=1
#                              then 0, back to back (the band's uploads and reads off the compute queue, so bands run
#                              back to back on the device; docs/balancing.md, "OpenCL's bands back to back on the device")
#                              COHORT_GPU_BAND_GAPS=1 renders with --log-level debug and prints the OpenCL bands' device gap
#                              after the band before, kernels and transfer (tools/opencl_band_gaps.py)
#                              COHORT_GPU_HAND_OUT_AHEAD="1 0" renders each of those with COHORT_HAND_OUT_AHEAD=1 then 0,
#                              back to back (with two in flight, frame N+1 handed out as soon as N-1 is merged, before
#                              N-1's post; docs/balancing.md, "The next frame handed out as soon as a slot frees");
#                              each run also prints per tracer the bands that waited for their job
#                              COHORT_GPU_KEEP_RUNS=1 brings every run's stats.json and log back as one file,
#                              $OUT/runs.tar.xz (frame by frame: rows, stages and band gaps of each tracer; $OUT
#                              returns at most 8 files)
#   tools/gpu_run.sh compare BASE.tar.xz [MORE.tar.xz ...]  there: A/B of payloads on one machine (the staged
#                              one against earlier stages' payload.tar.xz, renamed and carried in .gpu/): the CUDA
#                              tracer tests of the staged one, then end-to-end ms per frame, cuda:0, both maps,
#                              Brigade's blend, each payload in turn, three rounds (COHORT_GPU_COMPARE_ARGS adds
#                              render options)
#   tools/gpu_run.sh compare-env VARIABLE A B  there: the staged payload with an environment variable at each value
#                              (e.g. COHORT_BLAS_LAYOUT bvh2 cwbvh): its tracer tests, then ms per frame, three rounds
#   tools/gpu_run.sh stage-mpi here: the travelling cohort built against PyPI's MPICH, with its libraries (.gpu/mpi.tar.xz)
#   tools/gpu_run.sh cluster   there, on a two-GPU kind: two ranks with one GPU each against the in-process two GPUs
#   tools/gpu_run.sh rejoin    there, on a two-GPU kind: two nodes that joined rank 0 on their own mpiexec, one GPU
#                              each; mpi:2's node dies, a fresh one joins its slot: frame times around the death
#                              and the return, and the newcomer's join -> first band (docs/cluster.md)
#                              (COHORT_CLUSTER_JOBS_AHEAD="1 0": with and without jobs ahead, back to back)
#                              (COHORT_REJOIN_WARM_UP="1 0", the default: the newcomer's full resync on the side
#                              and its ready (protocol 10), then without, back to back)
#   tools/gpu_run.sh links     there, on a two-GPU kind: remote tracers behind emulated links (COHORT_LINKS, default
#                              "none 10gbit,0.5ms 1gbit,1ms"): alone, two ranks together, and beside rank 0's cuda:0
#                              (COHORT_LINKS_EARLY="1 0": with the next frame announced at hand-out and after, back to back;
#                              COHORT_LINKS_FORMATS="rgb16f rgb9e5": each band format in turn, rows of 6 and 4 bytes a pixel)
#   tools/gpu_run.sh kernels   there: GPU time kernel by kernel (ncu) on the large map at 1080p, cuda:0, Brigade's
#                              blend / reprojection / reprojection + a-trous, with the same runs' frame times
#   tools/gpu_run.sh quality   there: bench/quality/bench_quality.py on cuda:0 along the test map's scenario,
#                              references at COHORT_QUALITY_REF_SPP (default 1,024) spp, at each of
#                              COHORT_QUALITY_SIZES (default "1280x720 320x180"); FLIP is computed there (the
#                              flip-evaluator wheel travels in .gpu/wheels: stage with COHORT_GPU_QUALITY=1);
#                              table, JSON, plot and door crops back in $OUT; COHORT_QUALITY_PATH=spin-slow
#                              follows that camera path instead, COHORT_QUALITY_VARIANTS="opts;opts" reruns the
#                              methods with other render options against the same references
#   tools/gpu_run.sh stage-oidn  here: Open Image Denoise's API, core, CUDA and CPU device libraries (tools/fetch_oidn.sh)
#                              as .gpu-oidn/oidn.tar.xz (~46 MB: too big to travel with the payload, so in a call of
#                              its own: device tool, carry [".gpu-oidn"], command "bash tools/gpu_run.sh unpack-oidn")
#   tools/gpu_run.sh unpack-oidn  there: unpacks them to /tmp/oidn/lib, kept on the warm machine for the next call:
#                              `quality` then points COHORT_OIDN_DIR at them (methods oidn-cuda, reproject+oidn-cuda)
#   tools/gpu_run.sh frametimes  there: only the end-to-end frame times (large map 1080p generated there,
#                              test map 720p; cuda:0, 1 spp, NEE + 1 bounce; reprojection on the GPU with and
#                              without the a-trous filter, on the host, and Brigade's blend; per-stage medians;
#                              the last frames go to $OUT/frames)
#
# The binaries and libraries travel compressed (.gpu/payload.tar.xz, ~11 MB instead of ~60 MB): the device
# tool carries at most 64 MiB with the working tree.
#
# The GPU machine (Ubuntu 24.04, newer glibc) lacks Embree, TBB, OpenImageIO, GLFW and GLM; binaries built
# here run there with the three shared libraries below carried beside them. See README, "GPU machine".
set -euo pipefail
cd "$(dirname "$0")/.."
stage=.gpu

# There: the MPI build's cohort from .gpu/mpi.tar.xz (as $cohort, mpiexec.hydra on PATH), and the large map
# generated and packed with it at /tmp/largemap.cpk (kept between calls on a warm machine).
mpi_cohort_and_large_map() {
  mkdir -p "$stage/mpi" && tar -C "$stage/mpi" -xJf "$stage/mpi.tar.xz"
  export PATH="$PWD/$stage/mpi/bin:$PATH"
  cohort="$PWD/$stage/mpi/bin/cohort"
  [ -f /tmp/largemap.cpk ] || { python3 tools/gen_testmap.py --large --out /tmp/largemap >/dev/null &&
    "$cohort" pack /tmp/largemap/maps/largemap.map --out /tmp/largemap.cpk | tail -n 1; }
}

case "${1:-}" in
  stage)
    cmake --preset gpu-travel
    # COHORT_GPU_TARGETS narrows the build while iterating on one part (e.g. "cohort cohort_tracers_tests").
    cmake --build --preset gpu-travel -j2 --target ${COHORT_GPU_TARGETS:-cohort cohort_tracers_tests bench_cuda bench_bvh \
      bench_scaling bench_host_frame bench_skinning bench_tracers}
    rm -rf "$stage" && mkdir -p "$stage/bin" "$stage/lib"
    for exe in build/gpu/bin/cohort build/gpu/bin/cohort_tracers_tests build/gpu/bin/bench_cuda \
               build/gpu/bin/bench_bvh build/gpu/bin/bench_scaling build/gpu/bin/bench_host_frame \
               build/gpu/bin/bench_skinning build/gpu/bin/bench_tracers; do
      [ -x "$exe" ] && [ -f "$exe" ] && strip -o "$stage/bin/$(basename "$exe")" "$exe"
    done
    for lib in libembree3.so.3 libtbb.so.12 libzip.so.4; do
      cp -L "/usr/lib/x86_64-linux-gnu/$lib" "$stage/lib/"
    done
    # The travelling binary has no OpenImageIO: the pack carries decoded textures.
    build/gpu/bin/cohort pack assets/testmap/maps/testmap.map --out "$stage/testmap.cpk"
    if [ "${COHORT_GPU_LARGEMAP:-0}" = 1 ]; then
      python3 tools/gen_testmap.py --large --out build/gpu/assets/largemap
      build/gpu/bin/cohort pack build/gpu/assets/largemap/maps/largemap.map --out "$stage/largemap.cpk"
    fi
    tar -C "$stage" -cJf "$stage/payload.tar.xz" bin lib && rm -rf "$stage/bin" "$stage/lib"
    if [ "${COHORT_GPU_QUALITY:-0}" = 1 ]; then
      # NVIDIA's FLIP for `quality`, as a wheel for the GPU machine's Python 3.12 (nothing is fetched there).
      python3 -m pip download -q --no-deps --only-binary=:all: --python-version 3.12 --implementation cp \
        --platform manylinux_2_17_x86_64 --platform manylinux2014_x86_64 -d "$stage/wheels" flip-evaluator==1.7
    fi
    du -sh "$stage"
    ;;
  stage-oidn)
    lib=third_party/oidn/lib
    [ -f "$lib/libOpenImageDenoise_core.so.2.5.1" ] || bash tools/fetch_oidn.sh
    mkdir -p .gpu-oidn
    tar -C "$lib" -cJf .gpu-oidn/oidn.tar.xz libOpenImageDenoise.so.2 libOpenImageDenoise_core.so.2.5.1 \
      libOpenImageDenoise_device_cuda.so.2.5.1 libOpenImageDenoise_device_cpu.so.2.5.1
    du -sh .gpu-oidn/oidn.tar.xz
    ;;
  unpack-oidn)
    # In a folder named lib: the libraries find each other through their RUNPATH, $ORIGIN/../lib.
    rm -rf /tmp/oidn && mkdir -p /tmp/oidn/lib && tar -C /tmp/oidn/lib -xJf .gpu-oidn/oidn.tar.xz
    ls -la /tmp/oidn/lib
    ;;
  stage-mpi)
    # Here: the travelling cohort built against MPICH from PyPI (docs/cluster.md), with MPICH's libraries and
    # launcher beside it, as .gpu/mpi.tar.xz (~16 MB; carried with the payload). `cluster` runs it there.
    venv=${COHORT_MPICH_VENV:-/tmp/cohort-mpich}
    [ -x "$venv/bin/mpicxx" ] || { python3 -m venv "$venv" && "$venv/bin/pip" install -q mpich; }
    cmake --preset gpu-travel -B build/gpu-mpi -DCOHORT_WITH_MPI=ON -DMPI_HOME="$venv" \
      -DMPI_CXX_COMPILER="$venv/bin/mpicxx" -DMPIEXEC_EXECUTABLE="$venv/bin/mpiexec" >/dev/null
    cmake --build build/gpu-mpi -j2 --target cohort
    mpi_stage=$(mktemp -d); mkdir -p "$mpi_stage/bin" "$mpi_stage/lib" "$stage"
    strip -o "$mpi_stage/bin/cohort" build/gpu-mpi/bin/cohort
    for lib in libembree3.so.3 libtbb.so.12 libzip.so.4; do cp -L "/usr/lib/x86_64-linux-gnu/$lib" "$mpi_stage/lib/"; done
    cp -a "$venv/lib/libmpi.so.12" "$venv/lib/mpich" "$mpi_stage/lib/"
    cp "$venv/bin/mpiexec.hydra" "$venv/bin/hydra_pmi_proxy" "$mpi_stage/bin/"
    tar -C "$mpi_stage" -cJf "$stage/mpi.tar.xz" bin lib && rm -rf "$mpi_stage"
    du -sh "$stage/mpi.tar.xz"
    ;;
  cluster)
    # There, on a two-GPU kind: issue 19's first target, two ranks with one GPU each (cohort node) against
    # the in-process two-GPU frame, both maps, Brigade's blend (rank 0 then has no GPU of its own), two rounds.
    mpi_cohort_and_large_map
    for round in 1 2; do
      for map in large test; do
        if [ $map = large ]; then pack=/tmp/largemap.cpk; size=(--width 1920 --height 1080 --camera 1690 300 80 5 -12)
        else pack="$PWD/$stage/testmap.cpk"; size=(--width 1280 --height 720); fi
        common=(--spp 1 --light-samples 1 --bounces 1 --convergence brigade --frames 200 --camera-path spin-slow --write last)
        timeout 120 "$cohort" render "$pack" "${size[@]}" "${common[@]}" --tracers cuda:0,cuda:1 --out /tmp/in_$map >/tmp/in_$map.log 2>&1 ||
          tail -n 3 /tmp/in_$map.log
        echo "round $round, $map map, in-process: $(python3 tools/frame_times.py /tmp/in_$map/stats.json --skip 50 | head -n 1)"
        # COHORT_CLUSTER_PIECES="1 2 4 8": the two-rank run once per piece count a band's rows travel in;
        # COHORT_CLUSTER_JOBS_AHEAD="1 0": with and without jobs ahead (docs/cluster.md), back to back.
        for ahead in ${COHORT_CLUSTER_JOBS_AHEAD:-1}; do
        for pieces in ${COHORT_CLUSTER_PIECES:-1}; do
          rm -rf /tmp/mpi_$map
          COHORT_MPI_JOBS_AHEAD=$ahead COHORT_MPI_BAND_PIECES=$pieces timeout 180 mpiexec.hydra -np 1 "$cohort" render \
            "$pack" "${size[@]}" "${common[@]}" --tracers mpi:1,mpi:2 --out /tmp/mpi_$map : \
            -np 1 "$cohort" node "$pack" --tracers cuda:0 : -np 1 "$cohort" node "$pack" --tracers cuda:1 >/tmp/mpi_$map.log 2>&1 ||
            { echo "two-rank run failed"; tail -n 8 /tmp/mpi_$map.log; }
          [ -f /tmp/mpi_$map/stats.json ] &&
            echo "round $round, $map map, two ranks, $pieces piece(s) a band, jobs ahead $ahead: $(python3 tools/frame_times.py /tmp/mpi_$map/stats.json --skip 50 | head -n 1)"
          # Rank 0's own stages (medians): with no GPU there, its merge, blend and tone map run on the host
          # while the nodes render the next frame; near the frame interval, they set it.
          [ -f /tmp/mpi_$map/stats.json ] && python3 tools/frame_times.py /tmp/mpi_$map/stats.json --skip 50 | grep " core/" || true
          grep -E "round trip" /tmp/mpi_$map.log | sed 's/^.*\] //' || true
        done
        done
      done
    done
    ;;
  rejoin)
    # There, on a two-GPU kind, with the staged MPICH build (stage-mpi): issue 19's rejoin. Rank 0 (no GPU of its
    # own, Brigade's blend on the host) opens a port; two nodes join it on their own mpiexec, one GPU each; mpi:2's
    # node kills itself before frame 600 and, once its band has timed out, a fresh node joins mpi:2.
    mpi_cohort_and_large_map
    size=(--width 1920 --height 1080 --camera 1690 300 80 5 -12)
    common=(--spp 1 --light-samples 1 --bounces 1 --convergence brigade --frames 3000 --camera-path spin-slow
            --write last --balancer perfect-smooth)
    # Protocol 10: the newcomer takes its full resync on the side and says ready; COHORT_REJOIN_WARM_UP="1 0"
    # (default) runs with it and without it (COHORT_MPI_WARM_UP=0: its first band waits for the resync), back to back.
    for warm in ${COHORT_REJOIN_WARM_UP:-1 0}; do
      echo "== COHORT_MPI_WARM_UP=$warm"
      port=/tmp/rejoin.port; rm -rf "$port" /tmp/rejoin
      COHORT_MPI_WARM_UP=$warm COHORT_MPI_BAND_TIMEOUT_MS=1000 timeout 300 mpiexec.hydra -np 1 "$cohort" render /tmp/largemap.cpk "${size[@]}" \
        "${common[@]}" --tracers mpi:1,mpi:2 --node-port "$port" --node-wait 120 --out /tmp/rejoin >/tmp/rejoin_r0.log 2>&1 &
      r0=$!
      timeout 300 mpiexec.hydra -np 1 "$cohort" node /tmp/largemap.cpk --tracers cuda:0 --join "$port" --as 1 \
        >/tmp/rejoin_n1.log 2>&1 &
      timeout 300 mpiexec.hydra -np 1 "$cohort" node /tmp/largemap.cpk --tracers cuda:1 --join "$port" --as 2 \
        --die-frame 600 >/tmp/rejoin_n2.log 2>&1 || true
      until grep -q "mpi:2: no answer for rows" /tmp/rejoin_r0.log || ! kill -0 $r0 2>/dev/null; do sleep 0.2; done
      timeout 300 mpiexec.hydra -np 1 "$cohort" node /tmp/largemap.cpk --tracers cuda:1 --join "$port" --as 2 \
        >/tmp/rejoin_n3.log 2>&1 &
      wait $r0 || { echo "rank 0 failed"; tail -n 20 /tmp/rejoin_r0.log; }
      wait
      grep -hE "joined mpi|first band|killing itself|no answer for rows|joined rank 0|is ready|: ready|not ready|let go" /tmp/rejoin_*.log | sed 's/^.*\] //'
      python3 - <<'PY'
import json
frames = json.load(open("/tmp/rejoin/stats.json"))["frames"]
slot = [{t["name"]: t["outcome"] for t in f["tracers"]}["mpi:2"] for f in frames]
ms = [f["wall_ms"] for f in frames]
gone = [i for i, s in enumerate(slot) if s != "rendered" and i >= 1]
back = next((i for i in range(gone[0], len(slot)) if slot[i] == "rendered"), None) if gone else None
median = sorted(ms[50:])[len(ms[50:]) // 2]
print(f"{len(frames)} frames, median {median:.2f} ms; late (> 3x median): {[i for i, t in enumerate(ms) if i > 0 and t > 3 * median]}")
if gone:
    print(f"mpi:2 away from frame {gone[0]}, back at {back}; frames around the death: "
          + ", ".join(f"{t:.2f}" for t in ms[gone[0] - 3:gone[0] + 4]))
    # Since issue 19's away slot: "away" (left out, no re-render) after the death's one timed_out/threw frame.
    outcomes = {}
    for s in slot[gone[0]:back]: outcomes[s] = outcomes.get(s, 0) + 1
    between = ms[gone[0] + 1:back] if back else ms[gone[0] + 1:]
    print(f"mpi:2 outcomes from the death to its return: {outcomes}; median frame between: "
          f"{sorted(between)[len(between) // 2]:.2f} ms" if between else "")
if back:
    print("frames around the return: " + ", ".join(f"{t:.2f}" for t in ms[back - 4:back + 4])
          + f"; median of the 100 frames after: {sorted(ms[back:back + 100])[50]:.2f} ms")
PY
    done
    ;;
  links)
    # There, on a two-GPU kind: issue 19's emulated links (COHORT_MPI_LINK on every rank, docs/cluster.md),
    # large map 1080p, Brigade's blend, 200 frames (medians of 50-199): each remote tracer alone and together
    # (two ranks with one GPU each), and rank 0's own cuda:0 beside mpi:1, on loopback and under each link of
    # COHORT_LINKS; scaling efficiency = (1 / T_mix) / sum(1 / T_alone), the alone runs over the same link.
    mpi_cohort_and_large_map
    common=(/tmp/largemap.cpk --width 1920 --height 1080 --camera 1690 300 80 5 -12 --spp 1 --light-samples 1 --bounces 1
            --convergence brigade --frames 200 --camera-path spin-slow --write last)
    median() { python3 tools/frame_times.py "$1/stats.json" --skip 50 | sed -nE '1s/.*per frame median ([0-9.]+) ms.*/\1/p'; }
    "$cohort" render "${common[@]}" --tracers cuda:0 --out /tmp/l_cuda0 >/dev/null 2>&1
    "$cohort" render "${common[@]}" --tracers cuda:0,cuda:1 --out /tmp/l_cuda01 >/dev/null 2>&1
    echo "in process: cuda:0 $(median /tmp/l_cuda0) ms, cuda:0,cuda:1 $(median /tmp/l_cuda01) ms"
    # COHORT_LINKS_EARLY="1 0": each link with the next frame announced at hand-out (the default) and after
    # rank 0's post of the frame before (COHORT_EARLY_ANNOUNCE=0, the order before), back to back.
    # COHORT_LINKS_FORMATS="rgb16f rgb9e5": each with the bands in that format (the in-process runs above stay
    # in the default, rgb16f).
    for link in ${COHORT_LINKS:-none 10gbit,0.5ms 1gbit,1ms}; do
    for early in ${COHORT_LINKS_EARLY:-1}; do
    for format in ${COHORT_LINKS_FORMATS:-rgb16f}; do
      export COHORT_EARLY_ANNOUNCE=$early
      [ "$link" = none ] && export COHORT_MPI_LINK= || export COHORT_MPI_LINK=$link
      runs() {  # NAME TRACERS NODE-TRACERS... : rank 0 renders TRACERS, one node per NODE-TRACERS
        local name=$1 tracers=$2; shift 2
        local nodes=() ; for t in "$@"; do nodes+=(: -np 1 "$cohort" node /tmp/largemap.cpk --tracers "$t"); done
        rm -rf /tmp/l_$name
        timeout 180 mpiexec.hydra -np 1 "$cohort" render "${common[@]}" --tracers "$tracers" --out /tmp/l_$name \
          --band-format "$format" "${nodes[@]}" >/tmp/l_$name.log 2>&1 || { echo "$name failed"; tail -n 5 /tmp/l_$name.log; }
      }
      runs m1 mpi:1 cuda:0; runs m2 mpi:2 cuda:0 cuda:1; runs m12 mpi:1,mpi:2 cuda:0 cuda:1
      runs c0m1 cuda:0,mpi:1 cuda:1
      python3 - "$link (next frame announced at hand-out: $early, bands $format)" "$(median /tmp/l_m1)" "$(median /tmp/l_m2)" "$(median /tmp/l_m12)" "$(median /tmp/l_cuda0)" \
        "$(median /tmp/l_c0m1)" <<'PY'
import sys
link, m1, m2, m12, c0, c0m1 = sys.argv[1], *map(float, sys.argv[2:])
print(f"link {link}: mpi:1 alone {m1:.2f} ms, mpi:2 alone {m2:.2f}, mpi:1,mpi:2 {m12:.2f} "
      f"(efficiency {100 / m12 / (1 / m1 + 1 / m2):.1f} %); cuda:0 + mpi:1 {c0m1:.2f} "
      f"(efficiency {100 / c0m1 / (1 / c0 + 1 / m1):.1f} %)")
PY
      grep -hE "round trip|a job ahead left|colour rows a band" /tmp/l_m12.log | sed "s/^.*\] //" || true
      python3 tools/frame_times.py /tmp/l_m12/stats.json --skip 50 | grep " core/" || true
      # Every run's log, and the mix's stats (~0.5 MB), come back, so that a figure can be read again later.
      if [ -n "${OUT:-}" ]; then
        keep="$OUT/links/${link//[^a-z0-9.]/_}_early${early}_$format" && mkdir -p "$keep"
        for run in m1 m2 m12 c0m1; do cp /tmp/l_$run.log "$keep/" 2>/dev/null || true; done
        cp /tmp/l_m12/stats.json "$keep/m12.stats.json" 2>/dev/null || true
      fi
    done
    done
    done
    ;;
  compare)
    # Each payload unpacks into .gpu/cmp/NAME (NAME: its file name without .tar.xz; the staged one is "new").
    # COHORT_GPU_TRACERS: the tracers of the timed runs (default cuda:0).
    [ $# -ge 2 ] || { echo "usage: gpu_run.sh compare BASE_PAYLOAD.tar.xz [MORE.tar.xz ...]"; exit 2; }
    shift
    names=()
    for payload in "$@" "$stage/payload.tar.xz"; do
      name=$(basename "$payload" .tar.xz); [ "$payload" = "$stage/payload.tar.xz" ] && name=new
      mkdir -p "$stage/cmp/$name" && tar -C "$stage/cmp/$name" -xJf "$payload" && names+=("$name")
    done
    export LD_LIBRARY_PATH="$PWD/$stage/cmp/new/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
    nvidia-smi --query-gpu=index,name --format=csv,noheader
    # Each payload packs both maps itself: pack versions change between commits.
    [ -d /tmp/largemap/maps ] || python3 tools/gen_testmap.py --large --out /tmp/largemap >/dev/null
    for name in "${names[@]}"; do
      for map in large test; do
        src=/tmp/largemap/maps/largemap.map; [ $map = test ] && src=assets/testmap/maps/testmap.map
        "$stage/cmp/$name/bin/cohort" pack $src --out /tmp/cmp_${name}_$map.cpk >/dev/null
      done
    done
    [ -x "$stage/cmp/new/bin/cohort_tracers_tests" ] && COHORT_PACK=/tmp/cmp_new_test.cpk "$stage/cmp/new/bin/cohort_tracers_tests" --gtest_filter="${COHORT_GPU_TEST_FILTER:-*Cuda*}" 2>&1 |
      grep -E "^\[  (PASSED|FAILED) |^\[  FAILED|tests? ran" || true
    for round in 1 2 3; do
      for name in "${names[@]}"; do
        for map in large test; do
          if [ $map = large ]; then args=(/tmp/cmp_${name}_large.cpk --width 1920 --height 1080 --camera 1690 300 80 5 -12)
          else args=(/tmp/cmp_${name}_test.cpk --width 1280 --height 720); fi
          run=/tmp/cmp_${name}_${map}_$round
          "$stage/cmp/$name/bin/cohort" render "${args[@]}" --tracers "${COHORT_GPU_TRACERS:-cuda:0}" --spp 1 --bounces 1 \
            --convergence brigade --frames 60 --camera-path spin-slow ${COHORT_GPU_COMPARE_ARGS:-} --write last --out $run \
            >/dev/null 2>&1
          echo "== round $round, $name, $map map: $(python3 tools/frame_times.py $run/stats.json --skip 10 | head -n 1)"
        done
      done
    done
    ;;
  compare-env)
    # A/B of one environment variable's values with the staged payload (e.g. compare-env COHORT_BLAS_LAYOUT
    # bvh2 cwbvh): the GPU tracer tests with the last value, then end-to-end ms per frame on cuda:0, both
    # maps, Brigade's blend (COHORT_GPU_CONVERGENCE names another), the values alternated over three rounds
    # (COHORT_GPU_COMPARE_ARGS adds options).
    [ $# -ge 4 ] || { echo "usage: gpu_run.sh compare-env VARIABLE VALUE_A VALUE_B [...]"; exit 2; }
    variable=$2; shift 2
    [ -d "$stage/bin" ] || tar -C "$stage" -xJf "$stage/payload.tar.xz"
    export LD_LIBRARY_PATH="$PWD/$stage/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
    # NVIDIA's OpenCL registered. PoCL still lists itself first on the GPU machines (2026-11-28: opencl:0 was PoCL's
    # CPU device, opencl:1 the first GPU, with only nvidia.icd in OCL_ICD_VENDORS): name the GPU's OpenCL device as
    # `cohort devices` lists it there (COHORT_GPU_TRACERS=opencl:1, COHORT_TEST_OPENCL_DEVICE=1).
    mkdir -p /tmp/icd && echo libnvidia-opencl.so.1 > /tmp/icd/nvidia.icd
    export OCL_ICD_VENDORS=/tmp/icd
    nvidia-smi --query-gpu=index,name --format=csv,noheader
    [ -f /tmp/largemap.cpk ] || { [ -f "$stage/largemap.cpk" ] && cp "$stage/largemap.cpk" /tmp/largemap.cpk; } ||
      { python3 tools/gen_testmap.py --large --out /tmp/largemap >/dev/null &&
        "$stage/bin/cohort" pack /tmp/largemap/maps/largemap.map --out /tmp/largemap.cpk | tail -n 1; }
    last=${!#}
    [ -x "$stage/bin/cohort_tracers_tests" ] && env "$variable=$last" COHORT_PACK="$stage/testmap.cpk" \
      "$stage/bin/cohort_tracers_tests" --gtest_filter="${COHORT_GPU_TEST_FILTER:-*}" 2>&1 |
      grep -E "^\[  (PASSED|FAILED) |^\[  FAILED|tests? ran|SKIPPED \]" | head -n 40 || true
    for round in 1 2 3; do
      for value in "$@"; do
        for map in large test; do
          if [ $map = large ]; then args=(/tmp/largemap.cpk --width 1920 --height 1080 --camera 1690 300 80 5 -12)
          else args=("$stage/testmap.cpk" --width 1280 --height 720); fi
          run=/tmp/env_${value}_${map}_$round
          env "$variable=$value" "$stage/bin/cohort" render "${args[@]}" --tracers "${COHORT_GPU_TRACERS:-cuda:0}" --spp 1 \
            --bounces 1 --convergence ${COHORT_GPU_CONVERGENCE:-brigade} --frames 60 --camera-path spin-slow ${COHORT_GPU_COMPARE_ARGS:-} --write last \
            --out $run >/dev/null 2>&1
          echo "== round $round, $variable=$value, $map map: $(python3 tools/frame_times.py $run/stats.json --skip 10 | head -n 1)"
          [ -n "${OUT:-}" ] && [ $round = 1 ] && mkdir -p "$OUT/frames" &&
            cp $run/frame_0059.* "$OUT/frames/${map}_$value.$(ls $run/frame_0059.* | head -n1 | sed 's/.*\.//')" 2>/dev/null || true
        done
      done
    done
    ;;
  kernels)
    # There: where the GPU's time goes, kernel by kernel (Nsight Compute's duration of each launch, kernels
    # serialised), for cuda:0 on the large map at 1080p with Brigade's blend, reprojection, and reprojection +
    # the a-trous filter, over 8 frames after 20; then the end-to-end frame times of the same runs without it.
    [ -d "$stage/bin" ] || tar -C "$stage" -xJf "$stage/payload.tar.xz"
    export LD_LIBRARY_PATH="$PWD/$stage/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
    ncu=$(command -v ncu || ls /usr/local/cuda/bin/ncu 2>/dev/null || true)
    [ -n "$ncu" ] || { echo "no ncu on this machine"; exit 1; }
    nvidia-smi --query-gpu=index,name --format=csv,noheader
    [ -f /tmp/largemap.cpk ] || { [ -f "$stage/largemap.cpk" ] && cp "$stage/largemap.cpk" /tmp/largemap.cpk; } ||
      { python3 tools/gen_testmap.py --large --out /tmp/largemap >/dev/null &&
        "$stage/bin/cohort" pack /tmp/largemap/maps/largemap.map --out /tmp/largemap.cpk | tail -n 1; }
    for variant in ${COHORT_GPU_KERNEL_VARIANTS:-brigade:none reproject:none reproject:atrous}; do
      convergence=${variant%:*} denoise=${variant#*:}
      args=(/tmp/largemap.cpk --width 1920 --height 1080 --camera 1690 300 80 5 -12 --tracers cuda:0 --spp 1 --bounces 1
            --convergence $convergence --denoise $denoise --camera-path spin-slow ${COHORT_GPU_COMPARE_ARGS:-})
      echo "== large map 1080p, $convergence, denoise $denoise: device ms a frame by kernel (frames 20-27, serialised)"
      "$ncu" --metrics gpu__time_duration.sum --csv --print-units base "$stage/bin/cohort" render "${args[@]}" --frames 30 \
        --out /tmp/kernels_run 2>/dev/null | python3 -c '
import csv, collections, sys
rows = [r for r in csv.reader(l for l in sys.stdin if l.startswith("\""))]
head, rows = rows[0], rows[1:]
name, value, ident = head.index("Kernel Name"), head.index("Metric Value"), head.index("ID")
launches = sorted({int(r[ident]) for r in rows})
# The first kernel of a band marks frames (the megakernel, or the camera kernel of the wavefront): keep
# the launches from its 21st up to its 29th.
firsts = ("render_band_kernel", "wave_camera_kernel", "camera_walk_kernel")
render = [int(r[ident]) for r in rows if r[name].split("(")[0].replace("void ", "").split("::")[-1].startswith(firsts)]
lo, hi = (render[20], render[28]) if len(render) >= 29 else (launches[0], launches[-1] + 1)
total = collections.defaultdict(float); count = collections.Counter()
for r in rows:
    i = int(r[ident])
    if not lo <= i < hi: continue
    key = r[name].split("(")[0][:60]
    total[key] += float(r[value].replace(",", "")) / 1e6; count[key] += 1
frames = 8
for k, v in sorted(total.items(), key=lambda kv: -kv[1]):
    print(f"  {v / frames:7.3f} ms  {count[k] / frames:4.1f}x  {k}")
print(f"  {sum(total.values()) / frames:7.3f} ms  all kernels a frame")'
      "$stage/bin/cohort" render "${args[@]}" --frames 60 --write last --out /tmp/kernels_plain >/dev/null 2>&1
      echo "  without the profiler: $(python3 tools/frame_times.py /tmp/kernels_plain/stats.json --skip 10 | head -n 1)"
    done
    ;;
  quality)
    # There: issue 17's quality figures with references of >= 1,024 spp (a CPU affords 64-128), rendered and
    # measured on cuda:0. Each size is one bench_quality.py run over the scenario; the frames stay on the
    # machine, the report comes back.
    [ -d "$stage/bin" ] || tar -C "$stage" -xJf "$stage/payload.tar.xz"
    export LD_LIBRARY_PATH="$PWD/$stage/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
    ls "$stage"/wheels/flip_evaluator-*.whl >/dev/null 2>&1 || { echo "no FLIP wheel: stage with COHORT_GPU_QUALITY=1"; exit 2; }
    python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site \
      "$stage"/wheels/*.whl
    export PYTHONPATH=/tmp/site${PYTHONPATH:+:$PYTHONPATH} PYTHONUNBUFFERED=1
    # Open Image Denoise, where an earlier call on this warm machine unpacked it (stage-oidn, unpack-oidn).
    [ -d /tmp/oidn/lib ] && export COHORT_OIDN_DIR=/tmp/oidn/lib
    nvidia-smi --query-gpu=index,name --format=csv,noheader
    out=${OUT:-/tmp/out}; mkdir -p "$out"
    methods=${COHORT_QUALITY_METHODS:-none,brigade,reproject+atrous,reproject+atrous-first-hit}
    # COHORT_QUALITY_PATH=spin-slow: along that camera path instead of the scenario.
    if [ -n "${COHORT_QUALITY_PATH:-}" ]; then source=(--camera-path "$COHORT_QUALITY_PATH"); else source=(--scenario); fi
    status=0
    for size in ${COHORT_QUALITY_SIZES:-1280x720 320x180}; do
      work=/tmp/quality_$size
      python3 bench/quality/bench_quality.py --cohort "$stage/bin/cohort" --tracers cuda:0 "${source[@]}" \
        --frames "${COHORT_QUALITY_FRAMES:-48}" --width "${size%x*}" --height "${size#*x}" \
        --ref-spp "${COHORT_QUALITY_REF_SPP:-1024}" --methods "$methods" --out "$work" \
        ${COHORT_QUALITY_ARGS:-} 2>&1 | tee "$work.log" || status=1
      mkdir -p "$out/$size"
      for f in bench_quality.json bench_quality.png bench_quality_door_main.png; do
        [ -f "$work/$f" ] && cp "$work/$f" "$out/$size/"
      done
      cp "$work.log" "$out/$size/" 2>/dev/null || true
      # COHORT_QUALITY_VARIANTS="--anti-lag 0;--atrous-passes 3": the methods again with each set of render
      # options, against the same references (tables in the log; the other files are the first run's).
      IFS=';' read -r -a variants <<<"${COHORT_QUALITY_VARIANTS:-}"
      for variant in "${variants[@]}"; do
        [ -n "$variant" ] || continue
        echo "== with: $variant" | tee -a "$work.log"
        python3 bench/quality/bench_quality.py --cohort "$stage/bin/cohort" --tracers cuda:0 "${source[@]}" \
          --frames "${COHORT_QUALITY_FRAMES:-48}" --width "${size%x*}" --height "${size#*x}" \
          --ref-spp "${COHORT_QUALITY_REF_SPP:-1024}" --methods "$methods" --out "$work" --reuse-reference \
          --extra-args="$variant" ${COHORT_QUALITY_ARGS:-} 2>&1 | grep -A12 "^testmap" | tee -a "$work.log" || status=1
        cp "$work.log" "$out/$size/"
      done
    done
    exit $status
    ;;
  frametimes)
    [ -d "$stage/bin" ] || tar -C "$stage" -xJf "$stage/payload.tar.xz"
    export LD_LIBRARY_PATH="$PWD/$stage/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
    nvidia-smi --query-gpu=index,name --format=csv,noheader
    [ -f /tmp/largemap.cpk ] || { python3 tools/gen_testmap.py --large --out /tmp/largemap >/dev/null &&
      "$stage/bin/cohort" pack /tmp/largemap/maps/largemap.map --out /tmp/largemap.cpk | tail -n 1; }
    # Reprojection on the GPU (alone, then with the a-trous filter: variance guide, then the fixed stop) and
    # on the host, then the paper's blend.
    for variant in "reproject cuda:0 none" "reproject cuda:0 atrous" "reproject cuda:0 atrous-fixed" \
                   "reproject host none" "brigade host none"; do
      read -r convergence post denoise <<<"$variant"
      denoise_args=(--denoise "${denoise%-fixed}")
      [ "$denoise" = atrous-fixed ] && denoise_args+=(--atrous-guide fixed)
      for map in large test; do
        if [ $map = large ]; then args=(/tmp/largemap.cpk --width 1920 --height 1080 --camera 1690 300 80 5 -12)
        else args=("$stage/testmap.cpk" --width 1280 --height 720); fi
        run=/tmp/ft_${map}_${convergence}_${post}_$denoise
        "$stage/bin/cohort" render "${args[@]}" --tracers "${COHORT_GPU_TRACERS:-cuda:0}" --spp 1 --bounces 1 \
          --convergence $convergence --post-on $post "${denoise_args[@]}" --frames 60 --camera-path spin-slow \
          --write last --out $run >/dev/null
        echo "== $map map, convergence $convergence, post on $post, denoise $denoise"
        python3 tools/frame_times.py $run/stats.json --skip 10
        [ -n "${OUT:-}" ] && [ $map = test ] && mkdir -p "$OUT/frames" && cp $run/frame_0059.* "$OUT/frames/${map}_${convergence}_${post}_$denoise.$(ls $run/frame_0059.* | head -n1 | sed 's/.*\.//')" 2>/dev/null || true
      done
    done
    ;;
  multigpu)
    # Issue 14 on a machine with several GPUs: end-to-end frame times of each mix (the test map at
    # 1280x720 and the large map at 1920x1080, 1 spp, NEE + 1 bounce, spin-slow, 100 frames, medians of
    # frames 20-99; default convergence, then Brigade's blend), bench devices, and Table 1 with real GPUs.
    # COHORT_GPU_FRAMES / COHORT_GPU_SKIP change the 100 / 20 (Whole Cost's sit-out trials end after
    # frame 124: use 400 / 150 to see what they decided); the sit-out verdicts are printed.
    [ -d "$stage/bin" ] || tar -C "$stage" -xJf "$stage/payload.tar.xz"
    export LD_LIBRARY_PATH="$PWD/$stage/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
    mkdir -p /tmp/icd && echo libnvidia-opencl.so.1 > /tmp/icd/nvidia.icd
    export OCL_ICD_VENDORS=/tmp/icd
    out="${OUT:-/tmp/cohort-out}"; mkdir -p "$out"
    nvidia-smi --query-gpu=index,name --format=csv,noheader; nproc
    "$stage/bin/cohort" devices || true
    # OpenCL on the GPU that cuda:0 does not drive: never a second tracer on cuda:0's GPU, nor PoCL.
    opencl="${COHORT_GPU_OPENCL:-$("$stage/bin/cohort" devices --json 2>/dev/null | python3 -c '
import json, sys
devices = json.load(sys.stdin)["devices"]
gpus = [d for d in devices if d["tracer"].startswith("opencl:") and d["kind"] == "GPU"]
pick = [d for d in gpus if "cuda:1" in d["same_gpu_as"]] or [d for d in gpus if "cuda:0" not in d["same_gpu_as"]]
print(pick[0]["tracer"] if pick else "")' || true)}"
    echo "OpenCL tracer of the mixes: ${opencl:-none found (COHORT_GPU_OPENCL names one)}"
    opencl_mixes=""; [ -n "$opencl" ] && opencl_mixes="cuda:0,$opencl embree,cuda:0,$opencl"
    [ -f /tmp/largemap.cpk ] || { python3 tools/gen_testmap.py --large --out /tmp/largemap >/dev/null &&
      "$stage/bin/cohort" pack /tmp/largemap/maps/largemap.map --out /tmp/largemap.cpk | tail -n 1; }
    # COHORT_GPU_TEST_FILTER: other tests first (e.g. 'CudaMultiGpu*:FramePost*:FramesInFlightAgreement.*:OpenCL*';
    # opencl there is NVIDIA's OpenCL on the first GPU).
    COHORT_PACK="$stage/testmap.cpk" "$stage/bin/cohort_tracers_tests" --gtest_filter="${COHORT_GPU_TEST_FILTER:-CudaMultiGpu*:FramePost*}" 2>&1 |
      grep -E "^\[  (PASSED|FAILED|SKIPPED) |^\[       OK" || true
    for map in ${COHORT_GPU_MAPS:-test large}; do
      if [ $map = large ]; then args=(/tmp/largemap.cpk --width 1920 --height 1080 --camera 1690 300 80 5 -12)
      else args=("$stage/testmap.cpk" --width 1280 --height 720); fi
      for convergence in ${COHORT_GPU_CONVERGENCE:-auto brigade}; do
        for mix in ${COHORT_GPU_MIXES:-cuda:0 cuda:0,cuda:1 embree,cuda:0 embree,cuda:0,cuda:1 $opencl_mixes}; do
        mix=${mix//OPENCL/$opencl}
        for round in $(seq ${COHORT_GPU_ROUNDS:-1}); do
        # Unset: the option is not passed (payloads from before it still run).
        for in_flight in ${COHORT_GPU_IN_FLIGHT:-default}; do
        for ahead in ${COHORT_GPU_ENQUEUE_AHEAD:-default}; do
        for transfer in ${COHORT_GPU_TRANSFER_QUEUE:-default}; do
        for handout in ${COHORT_GPU_HAND_OUT_AHEAD:-default}; do
        # COHORT_GPU_ENVS: sets of environment variables to alternate, each VAR=VALUE[,VAR=VALUE...] (e.g.
        # "default COHORT_CUDA_FUSED_WALKS=0,COHORT_OPENCL_FUSED_WALKS=0" for an A/B in one round).
        for envset in ${COHORT_GPU_ENVS:-default}; do
          run=/tmp/mg_${map}_${convergence}_$(echo "$mix" | tr ',:' '__')
          in_flight_args=()
          if [ "$in_flight" != default ]; then
            run=${run}_if${in_flight}_r${round}
            in_flight_args=(--frames-in-flight "$in_flight")
          fi
          ahead_env=(); ahead_label=""
          if [ "$ahead" != default ]; then
            run=${run}_ea${ahead}
            ahead_env=(COHORT_OPENCL_ENQUEUE_AHEAD=$ahead); ahead_label=", COHORT_OPENCL_ENQUEUE_AHEAD=$ahead"
          fi
          if [ "$transfer" != default ]; then
            run=${run}_tq${transfer}
            ahead_env+=(COHORT_OPENCL_TRANSFER_QUEUE=$transfer); ahead_label="$ahead_label, COHORT_OPENCL_TRANSFER_QUEUE=$transfer"
          fi
          if [ "$handout" != default ]; then
            run=${run}_ho${handout}
            ahead_env+=(COHORT_HAND_OUT_AHEAD=$handout); ahead_label="$ahead_label, COHORT_HAND_OUT_AHEAD=$handout"
          fi
          if [ "$envset" != default ]; then
            run=${run}_$(echo "$envset" | tr ',=' '__' | tr -cd 'A-Za-z0-9_' | tail -c 40)_r${round}
            IFS=, read -r -a envs <<< "$envset"
            ahead_env+=("${envs[@]}"); ahead_label="$ahead_label, $envset"
          fi
          log_args=(); [ "${COHORT_GPU_BAND_GAPS:-0}" = 1 ] && log_args=(--log-level debug)
          env "${ahead_env[@]}" timeout 120 "$stage/bin/cohort" "${log_args[@]}" render "${args[@]}" --tracers "$mix" --spp 1 --light-samples 1 --bounces 1 \
            ${COHORT_GPU_RENDER_ARGS:-} "${in_flight_args[@]}" --convergence $convergence --frames ${COHORT_GPU_FRAMES:-100} \
            --camera-path spin-slow --write last --out $run >$run.log 2>&1 ||
            { echo "== $map $convergence $mix: failed"; tail -n 3 $run.log; continue; }
          echo "== $map map, $convergence, $mix${in_flight_args[*]:+, ${in_flight_args[*]}, round $round}$ahead_label"
          # With COHORT_GPU_KEEP_RUNS the summaries travel inside runs.tar.xz: $OUT returns at most 8 files.
          summary_dir=$out; [ "${COHORT_GPU_KEEP_RUNS:-0}" = 1 ] && summary_dir=$run
          python3 tools/frame_times.py $run/stats.json --skip ${COHORT_GPU_SKIP:-20} --json $summary_dir/$(basename $run).json > $run/summary.txt
          head -n 1 $run/summary.txt
          grep "waited for its job" $run/summary.txt || true  # per tracer: bands whose job came after the band before ended
          [ "${COHORT_GPU_BAND_GAPS:-0}" = 1 ] && { python3 tools/opencl_band_gaps.py $run.log --skip ${COHORT_GPU_SKIP:-20} || true; }
          grep -E "sits out|keeps its rows" $run.log | sed 's/^.*\] //' | head -n 3 || true
        done
        done
        done
        done
        done
        done
        done
      done
      [ "${COHORT_GPU_SKIP_DEVICES:-0}" = 1 ] || timeout 300 "$stage/bin/cohort" bench devices --scene "${args[0]}" --width "${args[2]}" --height "${args[4]}" \
        --frames 60 --json "$out/bench_devices_$map.json" 2>&1 | tail -n 14 || true
    done
    if [ "${COHORT_GPU_KEEP_RUNS:-0}" = 1 ]; then
      (cd /tmp && ls -d mg_*/stats.json mg_*/mg_*.json mg_*.log 2>/dev/null | tar -cJf "$out/runs.tar.xz" -T -) && ls -la "$out/runs.tar.xz"
    fi
    for real in ${COHORT_GPU_BALANCE_MIXES:-cuda:0,cuda:1}; do
    echo "== Table 1, real tracers $real"
    timeout 200 "$stage/bin/cohort" bench balance --real $real --scene "$stage/testmap.cpk" --rows 720 \
      --frames 200 --json "$out/bench_balance_$(echo $real | tr ',:' '__').json" 2>&1 | grep -v "loads" | tail -n 16 || true
    done
    ;;
  remote)
    [ -d "$stage/bin" ] || tar -C "$stage" -xJf "$stage/payload.tar.xz"
    export LD_LIBRARY_PATH="$PWD/$stage/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
    mkdir -p /tmp/icd && echo libnvidia-opencl.so.1 > /tmp/icd/nvidia.icd
    cp /etc/OpenCL/vendors/pocl.icd /tmp/icd/ 2>/dev/null || true
    export OCL_ICD_VENDORS=/tmp/icd
    out="${OUT:-/tmp/cohort-out}"; mkdir -p "$out"
    nvidia-smi --query-gpu=index,name,memory.total,driver_version --format=csv | tee "$out/gpus.csv"
    (clinfo -l 2>&1 || true) | tee "$out/opencl_devices.txt"
    status=0
    mkdir -p "$out/images"
    # Frames and plots are PPM/PFM here (no OpenImageIO travels); the archive at the end must stay small.
    COHORT_PACK="$stage/testmap.cpk" COHORT_TEST_IMAGES="$out/images" \
      "$stage/bin/cohort_tracers_tests" --gtest_output=json:"$out/tracers_tests.json" 2>&1 | tee "$out/tracers_tests.log" || status=1
    if [ -x "$stage/bin/bench_cuda" ]; then
      "$stage/bin/bench_cuda" --scene "$stage/testmap.cpk" --json "$out/bench_cuda.json" 2>&1 | tee "$out/bench_cuda.log" || status=1
    fi
    # A frame of the test map through the whole app, every GPU tracer: PFM/PPM since no OpenImageIO travels.
    "$stage/bin/cohort" render "$stage/testmap.cpk" --tracers "${COHORT_GPU_TRACERS:-cuda:all}" --width 640 --height 360 \
      --spp 16 --frames 2 --out "$out/render" 2>&1 | tail -n 8 | tee "$out/render.log" || status=1
    # End-to-end frame times and timelines (docs/frame-timeline.md): the test map at 1280x720, 1 spp,
    # NEE + 1 bounce, 100 frames turning slowly, for each tracer mix; medians over frames 20-99.
    for mix in ${COHORT_GPU_MIXES:-cuda:0 cuda:all embree,cuda:0 embree,cuda:all}; do
      name=$(echo "$mix" | tr ',:' '__')
      "$stage/bin/cohort" render "$stage/testmap.cpk" --tracers "$mix" --width 1280 --height 720 --spp 1 \
        --light-samples 1 --bounces 1 --frames 100 --camera-path spin-slow --write last --out "$out/e2e_$name" \
        --trace "$out/e2e_$name/trace.json" >/dev/null 2>&1 || status=1
      python3 tools/frame_times.py "$out/e2e_$name/stats.json" --json "$out/e2e_$name/summary.json" \
        | tee -a "$out/e2e.log" || status=1
    done
    # The large generated map: staged, or generated and packed here (COHORT_GPU_LARGEMAP=remote).
    if [ "${COHORT_GPU_LARGEMAP:-0}" = remote ] && [ ! -f "$stage/largemap.cpk" ]; then
      python3 tools/gen_testmap.py --large --out /tmp/largemap >/dev/null 2>&1 &&
        "$stage/bin/cohort" pack /tmp/largemap/maps/largemap.map --out "$stage/largemap.cpk" 2>&1 | tail -n 2 || status=1
    fi
    # BVH builds on this machine's cores: BLAS Mtris/s (test map, large map, 1M-triangle terrain), TLAS ms.
    if [ -x "$stage/bin/bench_bvh" ]; then
      maps=(--map assets/testmap/maps/testmap.map)
      [ -f /tmp/largemap/maps/largemap.map ] && maps+=(--map /tmp/largemap/maps/largemap.map)
      timeout 300 "$stage/bin/bench_bvh" "${maps[@]}" --json "$out/bench_bvh.json" 2>&1 | tee "$out/bench_bvh.log" || status=1
    fi
    # Host work per frame at 1080p (merge, convergence, tone map) on this machine's cores.
    [ -x "$stage/bin/bench_host_frame" ] && (cd "$out" && timeout 120 "$OLDPWD/$stage/bin/bench_host_frame" 2>&1 | tee "$out/bench_host_frame.log") || true
    # Skinned characters (docs/skinning.md): skin + refit per character per frame on the CPU tracer and CUDA.
    if [ -x "$stage/bin/bench_skinning" ]; then
      timeout 200 "$stage/bin/bench_skinning" --characters 16 --tracers embree,cuda:0 \
        --json "$out/bench_skinning.json" 2>&1 | tee "$out/bench_skinning.log" || status=1
    fi
    # Light and triangle scaling on the GPU (issue 16), 1920x1080, 1 spp, NEE + 1 bounce.
    if [ -x "$stage/bin/bench_scaling" ]; then
      timeout 400 "$stage/bin/bench_scaling" --tracer cuda:0 --width 1920 --height 1080 --spp 1 --bounces 1 --light-samples 1 \
        --frames 10 --json "$out/bench_scaling_cuda.json" --plot "$out/bench_scaling_cuda.ppm" 2>&1 | tee "$out/bench_scaling_cuda.log" || status=1
    fi
    # Does every device add speed (issue 14): each tracer alone and mixes, end to end.
    timeout 400 "$stage/bin/cohort" bench devices --scene "$stage/testmap.cpk" \
      ${COHORT_GPU_DEVICE_MIXES:---mix cuda:0 --mix embree --mix opencl:0 --mix embree,cuda:0 --mix cuda:0,opencl:0 --mix embree,cuda:0,opencl:0} \
      --frames 60 --json "$out/bench_devices.json" --plot "$out/bench_devices.ppm" 2>&1 | tee "$out/bench_devices.log" || status=1
    if [ -f "$stage/largemap.cpk" ]; then
      "$stage/bin/cohort" render "$stage/largemap.cpk" --tracers "${COHORT_GPU_TRACERS:-cuda:all}" --width 1920 \
        --height 1080 --spp 1 --frames 8 --out "$out/render_largemap" 2>&1 | tail -n 8 | tee "$out/render_largemap.log" || status=1
    fi
    # Balancer efficiency with real GPU tracers (the paper's Table 1 metric), both camera paths.
    "$stage/bin/cohort" bench balance --real "${COHORT_GPU_TRACERS:-cuda:all}" --scene "$stage/testmap.cpk" --rows 720 \
      --frames 200 --json "$out/bench_balance_gpu.json" 2>&1 | grep -v "loads" | tee "$out/bench_balance_gpu.log" || status=1
    # The device tool brings back at most 8 files: one archive holds them all (logs also print above).
    tar cf /tmp/cohort-results.tar -C "$out" . && rm -rf "${out:?}"/* && mv /tmp/cohort-results.tar "$out/results.tar"
    exit $status
    ;;
  *)
    sed -n '2,23p' "$0"; exit 2 ;;
esac
