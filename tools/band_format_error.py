#!/usr/bin/env python3
"""What a band format costs in precision: `cohort render` runs of the same frames in other band formats
against a reference run in rgba32f (the integrator is deterministic per pixel, so the only difference is
the format's rounding). Per run, over every written frame: the largest and the mean error of a channel
relative to its pixel's brightest channel (what a shared exponent bounds), the mean error of a channel
relative to itself (channels above 1 % of their pixel's brightest), and the image mean's drift (the mean
of the run's frame over the reference's, minus 1: a biased rounding shows here, most after many frames
of blending).

    cohort render MAP --tracers embree --band-format rgba32f --no-convergence --frames 8 --write all --out f32
    cohort render MAP --tracers embree --band-format rgb9e5  --no-convergence --frames 8 --write all --out e5
    tools/band_format_error.py f32 e5 [more runs] [--json FILE]

Reads .exr frames through oiiotool and .pfm frames directly (tools/noise_rmse.py's readers).
"""
import argparse
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from noise_rmse import frames_of, read_frame  # noqa: E402


def compare(reference, run):
    """Error figures of one run's frame against the reference's (flat RGB floats)."""
    worst = total = own_total = 0.0
    channels = own_channels = 0
    for p in range(0, len(reference), 3):
        ref, got = reference[p:p + 3], run[p:p + 3]
        top = max(ref)
        if top <= 0.0:
            continue
        for r, g in zip(ref, got):
            e = abs(g - r) / top
            worst = max(worst, e)
            total += e
            channels += 1
            if r > 0.01 * top:
                own_total += abs(g - r) / r
                own_channels += 1
    ref_mean, run_mean = sum(reference) / len(reference), sum(run) / len(run)
    return {"max_of_brightest": worst, "mean_of_brightest": total / max(channels, 1),
            "mean_of_own": own_total / max(own_channels, 1), "mean_drift": run_mean / ref_mean - 1.0}


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("reference")
    parser.add_argument("runs", nargs="+")
    parser.add_argument("--json", help="write the table as JSON here too")
    args = parser.parse_args()
    reference = {os.path.basename(p): p for p in frames_of(args.reference)}
    rows = []
    for run in args.runs:
        figures = []
        for path in frames_of(run):
            name = os.path.basename(path)
            if name not in reference:
                sys.exit(f"band_format_error: {args.reference} has no {name}")
            ref, got = read_frame(reference[name]), read_frame(path)
            if len(ref) != len(got):
                sys.exit(f"band_format_error: {path} is not the reference's size")
            figures.append(compare(ref, got))
        row = {"run": run, "frames": len(figures),
               "max_of_brightest": max(f["max_of_brightest"] for f in figures),
               "mean_of_brightest": sum(f["mean_of_brightest"] for f in figures) / len(figures),
               "mean_of_own": sum(f["mean_of_own"] for f in figures) / len(figures),
               "worst_mean_drift": max((f["mean_drift"] for f in figures), key=abs)}
        rows.append(row)
    print(f"against {args.reference}: errors relative to the pixel's brightest channel (max, mean), to the channel "
          f"itself (mean), and the image mean's worst drift over the frames")
    print(f"{'run':40s} {'frames':>6s} {'max/top':>10s} {'mean/top':>10s} {'mean/own':>10s} {'mean drift':>11s}")
    for r in rows:
        print(f"{r['run']:40s} {r['frames']:6d} {r['max_of_brightest']:10.2e} {r['mean_of_brightest']:10.2e} "
              f"{r['mean_of_own']:10.2e} {r['worst_mean_drift']:+11.2e}")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(rows, f, indent=2)


if __name__ == "__main__":
    main()
