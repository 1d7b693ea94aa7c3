#!/usr/bin/env python3
"""Cluster runs of `cohort render` on rank 0 with `cohort node` on ranks 1 and 2, all on localhost,
checked against a single-process render of the same frames (the integrator is deterministic per
pixel, so the images must match byte for byte).

    run_cluster.py CASE --mpiexec PATH --cohort PATH --map MAP --out DIR [--broken-map MAP]

CASE: match (Embree on every rank), stall (rank 2 sleeps through frame 1: its rows are re-rendered by
the others and every frame is still delivered), version (rank 1 announces another version: rank 0
names both and renders without it), load_error (rank 1 cannot load its map: rank 0 logs its file:line
reason and renders without it).
"""
import argparse
import json
import os
import re
import shutil
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "apps"))
from compare_images import read_image  # noqa: E402

FRAMES = 4
RENDER_ARGS = ["--width", "96", "--height", "64", "--spp", "2", "--frames", str(FRAMES), "--balancer", "perfect-smooth"]


def mpiexec_flags(mpiexec):
    """Open MPI needs --oversubscribe to start 3 ranks on fewer cores; MPICH's mpiexec has no such flag."""
    version = subprocess.run([mpiexec, "--version"], capture_output=True, text=True).stdout
    return ["--oversubscribe"] if "Open MPI" in version or "OpenRTE" in version else []


def run(command, env=None, expect_ok=True):
    print("$ " + " ".join(command), flush=True)
    result = subprocess.run(command, capture_output=True, text=True, timeout=180, env=env)
    output = result.stdout + result.stderr
    print(output[-6000:])
    if expect_ok and result.returncode != 0:
        sys.exit(f"exit status {result.returncode}")
    return result.returncode, output


def compare_frames(a_dir, b_dir):
    for f in range(FRAMES):
        name = f"frame_{f:04d}.png"
        a, b = os.path.join(a_dir, name), os.path.join(b_dir, name)
        if not os.path.exists(b):
            sys.exit(f"{b} was not written: the cluster lost frame {f}")
        (wa, ha, ca, pa), (wb, hb, cb, pb) = read_image(a), read_image(b)
        if (wa, ha) != (wb, hb):
            sys.exit(f"{name}: sizes differ")
        differing = sum(1 for p in range(wa * ha) if pa[p * ca:p * ca + 3] != pb[p * cb:p * cb + 3])
        print(f"{name}: {differing} of {wa * ha} pixels differ")
        if differing:
            sys.exit(f"{name}: the cluster's image differs from the single-process render")


def tracer_outcomes(out_dir):
    with open(os.path.join(out_dir, "stats.json")) as f:
        stats = json.load(f)
    return [{t["name"]: t["outcome"] for t in frame["tracers"]} for frame in stats["frames"]]


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("case", choices=["match", "stall", "version", "load_error"])
    parser.add_argument("--mpiexec", required=True)
    parser.add_argument("--cohort", required=True)
    parser.add_argument("--map", required=True)
    parser.add_argument("--broken-map")
    parser.add_argument("--out", required=True)
    a = parser.parse_args()

    shutil.rmtree(a.out, ignore_errors=True)
    single, cluster = os.path.join(a.out, "single"), os.path.join(a.out, "cluster")
    run([a.cohort, "render", a.map, "--tracers", "embree", "--out", single] + RENDER_ARGS)

    env = dict(os.environ)
    node1 = [a.cohort, "node", a.map, "--tracers", "embree"]
    node2 = [a.cohort, "node", a.map, "--tracers", "embree"]
    if a.case == "stall":
        env["COHORT_MPI_BAND_TIMEOUT_MS"] = "1000"
        node2 += ["--stall-frame", "1", "--stall-ms", "3000"]
    if a.case == "version":
        node1 += ["--announce-version", "0.0.0-test"]
    if a.case == "load_error":
        node1 = [a.cohort, "node", a.broken_map, "--tracers", "embree"]
    flags = mpiexec_flags(a.mpiexec)
    command = ([a.mpiexec] + flags + ["-np", "1", a.cohort, "render", a.map, "--tracers", "embree,mpi:1,mpi:2",
                                      "--out", cluster] + RENDER_ARGS +
               [":"] + flags + ["-np", "1"] + node1 + [":"] + flags + ["-np", "1"] + node2)
    code, output = run(command, env=env, expect_ok=a.case in ("match", "stall"))
    compare_frames(single, cluster)
    outcomes = tracer_outcomes(cluster)
    print("outcomes per frame:", outcomes)

    if a.case == "match":
        for f, o in enumerate(outcomes):
            if o.get("mpi:1") != "rendered" or o.get("mpi:2") != "rendered":
                sys.exit(f"frame {f}: a remote tracer did not render its band: {o}")
    elif a.case == "stall":
        if outcomes[1].get("mpi:2") not in ("threw", "timed_out"):
            sys.exit(f"frame 1: the stalled node's band should have failed over: {outcomes[1]}")
        if "no answer for rows" not in output:
            sys.exit("rank 0 did not log the stalled band")
        if not any(o.get("mpi:2") == "rendered" for o in outcomes[2:]) and "shutdown from rank 0" not in output:
            sys.exit("the stalled node neither rendered again nor shut down cleanly")
    elif a.case == "version":
        if not re.search(r"rank 0 runs Cohort \S+ .*rank 1 .* runs Cohort 0\.0\.0-test", output):
            sys.exit("rank 0 did not name both versions")
        if "refused this node" not in output:
            sys.exit("rank 1 did not report the refusal")
        if any("mpi:1" in o for o in outcomes):
            sys.exit("the refused node still took part")
    elif a.case == "load_error":
        if not re.search(r"mpi:1: the node could not load its scene and leaves: .*:\d+", output):
            sys.exit("rank 0 did not log the node's file:line reason")
        if any("mpi:1" in o for o in outcomes):
            sys.exit("the node that could not load its map still took part")
    print(f"{a.case}: ok")


if __name__ == "__main__":
    main()
