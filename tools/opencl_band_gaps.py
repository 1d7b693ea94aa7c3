#!/usr/bin/env python3
"""Summarises the OpenCL tracer's per-band debug lines of a `cohort --log-level debug render` log: for the bands
enqueued ahead (two frames in flight), the device's gap between the band before's last kernel and the band's
first (docs/balancing.md, "OpenCL's bands back to back on the device"), and the band's own clock (kernels,
transfer), medians and quartiles over the frames after a warm-up; one line per OpenCL tracer.

    tools/opencl_band_gaps.py run.log [--skip 50]
"""
import argparse
import re
import statistics
import sys

LINE = re.compile(
    r"opencl \((?P<tracer>.*?)\): band \[(?P<begin>\d+), (?P<end>\d+)\) of frame (?P<frame>\d+): (?P<how>enqueued ahead|enqueued) in "
    r"[\d.]+ ms;.*device gap after the band before (?P<gap>-?[\d.]+) ms, kernels (?P<kernels>[\d.]+) ms, "
    r"transfer (?P<transfer>[\d.]+) ms")


def quartiles(values):
    if not values:
        return "none"
    if len(values) < 2:
        return f"{values[0]:.3f}"
    q = statistics.quantiles(values, n=4)
    return f"{statistics.median(values):.3f} ({q[0]:.3f}-{q[2]:.3f})"


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("log")
    parser.add_argument("--skip", type=int, default=50, help="frames left out at the start (warm-up)")
    args = parser.parse_args()
    bands = {}
    with open(args.log, errors="replace") as f:
        for line in f:
            m = LINE.search(line)
            if m and int(m["frame"]) >= args.skip:
                bands.setdefault(m["tracer"], []).append(m)
    if not bands:
        print("no OpenCL band lines (run with `cohort --log-level debug render ...`, two frames in flight)")
        return 1
    for tracer, lines in bands.items():
        ahead = [m for m in lines if m["how"] == "enqueued ahead"]
        gaps = [float(m["gap"]) for m in ahead if float(m["gap"]) >= 0.0]
        print(f"opencl ({tracer}): {len(lines)} bands, {len(ahead)} enqueued ahead; of those, ms median (quartiles): "
              f"device gap after the band before {quartiles(gaps)}, "
              f"kernels {quartiles([float(m['kernels']) for m in ahead])}, "
              f"transfer {quartiles([float(m['transfer']) for m in ahead])}, "
              f"rows {statistics.median([int(m['end']) - int(m['begin']) for m in ahead]) if ahead else 0}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
