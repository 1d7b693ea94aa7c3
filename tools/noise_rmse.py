#!/usr/bin/env python3
"""Noise of `cohort render` runs against a reference run of the same still view: per-frame RMSE of linear
RGB (every frame written with --no-convergence is an independent estimate), the mean over frames, the
image means (equal to the reference's when a method is unbiased), and the median frame time from
stats.json. The reference is the mean of the reference run's frames.

    cohort render MAP --tracers embree --no-convergence --spp 64 --frames 8 --out ref ...
    cohort render MAP --tracers embree --no-convergence --spp 1 --frames 8 --out tree ...
    tools/noise_rmse.py ref tree every [--skip 1]

Needs oiiotool (OpenImageIO's tools) to read the .exr frames; .pfm frames (builds without OpenImageIO) are
read directly.
"""
import argparse
import array
import glob
import json
import math
import os
import statistics
import subprocess
import sys


def read_pfm(path):
    with open(path, "rb") as f:
        kind = f.readline().strip()
        width, height = (int(v) for v in f.readline().split())
        scale = float(f.readline())
        data = array.array("f")
        data.frombytes(f.read())
    if scale > 0:
        data.byteswap()
    channels = 3 if kind == b"PF" else 1
    if len(data) != width * height * channels:
        sys.exit(f"noise_rmse: {path}: {len(data)} floats for {width}x{height}x{channels}")
    return data


def read_frame(path):
    if path.endswith(".pfm"):
        return read_pfm(path)
    # oiiotool writes no PFM here; its text dump of the pixels is exact and fast enough at these sizes.
    text = subprocess.run(["oiiotool", "--dumpdata", path], check=True, capture_output=True, text=True).stdout
    data = array.array("f")
    for line in text.splitlines():
        if line.lstrip().startswith("Pixel ("):
            data.extend(float(v) for v in line.split(":", 1)[1].split()[:3])
    if not data:
        sys.exit(f"noise_rmse: oiiotool printed no pixels for {path}")
    return data


def frames_of(folder):
    files = sorted(glob.glob(os.path.join(folder, "frame_*.exr")) + glob.glob(os.path.join(folder, "frame_*.pfm")))
    if not files:
        sys.exit(f"noise_rmse: no frame_*.exr or frame_*.pfm in {folder}")
    return files


def frame_ms(folder, skip):
    try:
        with open(os.path.join(folder, "stats.json")) as f:
            frames = json.load(f)["frames"][skip:]
        values = [fr["frame_ms"] for fr in frames if "frame_ms" in fr]
        return statistics.median(values) if values else float("nan")
    except (OSError, KeyError, ValueError):
        return float("nan")


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("reference")
    parser.add_argument("runs", nargs="+")
    parser.add_argument("--skip", type=int, default=1, help="frames left out of the timing median (warm-up)")
    parser.add_argument("--json", help="write the table as JSON here too")
    args = parser.parse_args()
    if True:
        ref_frames = [read_frame(p) for p in frames_of(args.reference)]
        n = len(ref_frames[0])
        reference = array.array("d", [0.0]) * n
        for fr in ref_frames:
            for i in range(n):
                reference[i] += fr[i]
        for i in range(n):
            reference[i] /= len(ref_frames)
        ref_mean = sum(reference) / n
        rows = []
        for run in args.runs:
            errors, means = [], []
            for path in frames_of(run):
                fr = read_frame(path)
                if len(fr) != n:
                    sys.exit(f"noise_rmse: {path} is not the reference's size")
                errors.append(math.sqrt(sum((fr[i] - reference[i]) ** 2 for i in range(n)) / n))
                means.append(sum(fr) / n)
            rows.append({"run": run, "frames": len(errors), "rmse": statistics.mean(errors),
                         "mean": statistics.mean(means), "reference_mean": ref_mean,
                         "frame_ms": frame_ms(run, args.skip)})
    print(f"reference {args.reference}: {len(ref_frames)} frames, mean {ref_mean:.5f}")
    print(f"{'run':40s} {'frames':>6s} {'RMSE':>8s} {'mean':>8s} {'ms/frame':>9s} {'RMSE x sqrt(ms)':>15s}")
    for r in rows:
        print(f"{r['run']:40s} {r['frames']:6d} {r['rmse']:8.4f} {r['mean']:8.5f} {r['frame_ms']:9.1f} "
              f"{r['rmse'] * math.sqrt(r['frame_ms']):15.3f}")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(rows, f, indent=2)


if __name__ == "__main__":
    main()
