#!/usr/bin/env python3
"""Registers, stack frame and spills of every CUDA kernel in the given sources, as ptxas reports them for
the build's SASS target. The shading kernels are capped by __launch_bounds__, so a change to the portable
integrator shows first as spill bytes here (docs/integrator.md, "CUDA kernel shape"); compare two trees'
tables before measuring on a GPU.

    tools/kernel_resources.py build/default                       # render_band*.cu and wavefront_walk.cu
    tools/kernel_resources.py build/default tracers/cuda/src/skinning.cu

Reads the compile commands CMake wrote (CMAKE_EXPORT_COMPILE_COMMANDS, on in the presets) and reruns each
source's nvcc command with -Xptxas -v into /dev/null: nothing in the build changes.
"""
import argparse
import json
import os
import re
import shlex
import subprocess
import sys

DEFAULT_SOURCES = ("render_band.cu", "render_band_dense.cu", "wavefront_walk.cu")


def ptxas_command(entry):
    args = shlex.split(entry["command"]) if "command" in entry else list(entry["arguments"])
    out, skip = [], False
    for a in args:
        if skip:
            skip = False
            continue
        if a == "-o":
            skip = True
            continue
        # PTX for later GPUs is not assembled here: only the SASS target's figures mean anything.
        if a.startswith("--generate-code") and "code=[compute_" in a:
            continue
        out.append(a)
    return out + ["-Xptxas", "-v", "-o", os.devnull]


def demangle(names):
    try:
        result = subprocess.run(["c++filt"], input="\n".join(names), capture_output=True, text=True, check=True)
        return result.stdout.splitlines()
    except (OSError, subprocess.CalledProcessError):
        return names


def kernel_rows(stderr):
    rows, name, frame = [], None, None
    for line in stderr.splitlines():
        m = re.search(r"Compiling entry function '([^']+)'", line)
        if m:
            name, frame = m.group(1), None
            continue
        m = re.search(r"(\d+) bytes stack frame, (\d+) bytes spill stores, (\d+) bytes spill loads", line)
        if m and name:
            frame = tuple(int(v) for v in m.groups())
            continue
        m = re.search(r"Used (\d+) registers", line)
        if m and name:
            rows.append((name, int(m.group(1))) + (frame or (0, 0, 0)))
            name = None
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("build", help="a build folder with compile_commands.json")
    parser.add_argument("sources", nargs="*", help="sources to report (default: the band kernels' sources)")
    args = parser.parse_args()
    path = os.path.join(args.build, "compile_commands.json")
    try:
        with open(path) as f:
            entries = json.load(f)
    except (OSError, ValueError) as e:
        sys.exit(f"kernel_resources: cannot read {path}: {e}")
    wanted = [os.path.basename(s) for s in args.sources] or list(DEFAULT_SOURCES)
    chosen = [e for e in entries if e["file"].endswith(".cu") and os.path.basename(e["file"]) in wanted]
    if not chosen:
        sys.exit(f"kernel_resources: none of {', '.join(wanted)} in {path} (a build with CUDA?)")
    print(f"{'kernel':58s} {'regs':>4s} {'stack':>6s} {'spill st':>8s} {'spill ld':>8s}")
    for entry in sorted(chosen, key=lambda e: e["file"]):
        result = subprocess.run(ptxas_command(entry), cwd=entry["directory"], capture_output=True, text=True)
        if result.returncode != 0:
            sys.exit(f"kernel_resources: {entry['file']} did not compile:\n{result.stderr}")
        rows = kernel_rows(result.stderr)
        names = demangle([r[0] for r in rows])
        print(f"# {os.path.relpath(entry['file'])}")
        for name, (_, regs, stack, stores, loads) in sorted(zip(names, rows)):
            short = re.sub(r"cohort::tracers::(\(anonymous namespace\)::)?", "", name)
            short = re.sub(r"\(.*", "", short).removeprefix("void ")
            print(f"{short:58s} {regs:4d} {stack:6d} {stores:8d} {loads:8d}")


if __name__ == "__main__":
    main()
