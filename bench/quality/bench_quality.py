#!/usr/bin/env python3
"""Image quality in motion: per-frame FLIP and PSNR against a converged reference along a camera path.

Renders the same camera path with `cohort render` once at high spp (the reference, every frame rendered
afresh) and once per method at the interactive sample count, then compares each written frame with the
reference frame: NVIDIA's FLIP (flip-evaluator, LDR, on the tone-mapped PNGs a viewer sees) and PSNR.
Methods: none (each frame as rendered), brigade (adaptive convergence, Brigade's blend), oidn (each frame
denoised by Open Image Denoise), brigade+oidn (the blended frame denoised), reproject (per-pixel history
through motion vectors, core/reprojection.h), reproject+oidn (the reprojected frame denoised, with the
albedo and normal planes as the denoiser's guides), atrous and reproject+atrous (the real-time edge-aware
a-trous filter of the portable kernel, core/atrous_filter.h, on each frame or on the reprojected one, with
its default luminance stop; the -fixed and -variance methods name the stop: --atrous-guide). Reports a table, JSON, a
per-frame FLIP plot and the milliseconds each method's extra stages took (from stats.json).

Setup once: bench/quality/setup_env.sh, then
    .venv-quality/bin/python bench/quality/bench_quality.py [--map testmap] [--frames 12] [--ref-spp 256]
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import time

try:
    import flip_evaluator
    import numpy as np
except ImportError as e:  # pragma: no cover - environment check
    sys.exit(f"bench_quality: {e.name} is missing; run bench/quality/setup_env.sh and use .venv-quality/bin/python")

METHODS = {
    "none": ["--no-convergence"],
    "brigade": ["--convergence", "brigade"],
    "oidn": ["--no-convergence", "--denoise", "oidn"],
    "brigade+oidn": ["--convergence", "brigade", "--denoise", "oidn"],
    "reproject": ["--convergence", "reproject"],
    "reproject+oidn": ["--convergence", "reproject", "--denoise", "oidn"],
    "atrous": ["--no-convergence", "--denoise", "atrous"],
    "atrous-fixed": ["--no-convergence", "--denoise", "atrous", "--atrous-guide", "fixed"],
    "reproject+atrous": ["--convergence", "reproject", "--denoise", "atrous"],
    "reproject+atrous-fixed": ["--convergence", "reproject", "--denoise", "atrous", "--atrous-guide", "fixed"],
    "reproject+atrous-variance": ["--convergence", "reproject", "--denoise", "atrous", "--atrous-guide", "variance"],
    "reproject+atrous-variance-of-mean": ["--convergence", "reproject", "--denoise", "atrous", "--atrous-guide",
                                          "variance-of-mean"],
    # Dynamic resolution (docs/denoising.md): paths at a quarter of the pixels, reconstructed at full size.
    "half-bilinear": ["--no-convergence", "--render-scale", "0.5", "--upsample", "bilinear"],
    "half-nearest": ["--no-convergence", "--render-scale", "0.5", "--upsample", "nearest"],
    "half-joint-bilateral": ["--no-convergence", "--render-scale", "0.5", "--upsample", "joint-bilateral"],
    "half-bilinear+reproject": ["--convergence", "reproject", "--render-scale", "0.5", "--upsample", "bilinear"],
    "half-joint-bilateral+reproject": ["--convergence", "reproject", "--render-scale", "0.5", "--upsample",
                                       "joint-bilateral"],
}
EXTRA_STAGES = ("convergence", "denoise", "convergence+denoise")


def render(args, out_dir, spp, extra):
    cmd = [args.cohort, "render", args.map, "--tracers", args.tracers, "--width", str(args.width), "--height",
           str(args.height), "--spp", str(spp), "--frames", str(args.frames), "--camera-path", args.camera_path,
           "--bounces", str(args.bounces), "--out", out_dir] + extra
    start = time.monotonic()
    result = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if result.returncode != 0:
        sys.exit(f"bench_quality: `{' '.join(cmd)}` failed:\n{result.stderr[-2000:]}")
    return time.monotonic() - start


def frame_path(out_dir, f):
    for ext in (".png", ".ppm"):
        p = os.path.join(out_dir, f"frame_{f:04d}{ext}")
        if os.path.exists(p):
            return p
    sys.exit(f"bench_quality: {out_dir} has no frame {f} (png or ppm)")


def load_ldr(path):
    return flip_evaluator.load(path)


def psnr(reference, test):
    mse = float(np.mean((reference.astype(np.float64) - test.astype(np.float64)) ** 2))
    return float("inf") if mse == 0.0 else 10.0 * np.log10(1.0 / mse)


def stage_ms(stats_file):
    """Median ms per frame of the stages a method adds, and of the time per frame."""
    with open(stats_file) as f:
        frames = json.load(f)["frames"]
    out = {}
    for name in EXTRA_STAGES:
        values = [s["ms"] for fr in frames for s in fr["stages"] if s["track"] == "core" and s["stage"] == name]
        if values:
            out[name] = statistics.median(values)
    per_frame = [fr.get("interval_ms", fr.get("end_to_end_ms", 0.0)) for fr in frames[1:]] or [0.0]
    out["frame"] = statistics.median(per_frame)
    return out


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--cohort", default="build/default/bin/cohort", help="the cohort executable")
    p.add_argument("--map", default="testmap", help="map or scene pack")
    p.add_argument("--tracers", default="embree")
    p.add_argument("--width", type=int, default=320)
    p.add_argument("--height", type=int, default=180)
    p.add_argument("--frames", type=int, default=12)
    p.add_argument("--camera-path", default="spin-slow")
    p.add_argument("--bounces", type=int, default=1)
    p.add_argument("--spp", type=int, default=1, help="samples per pixel per frame of the methods")
    p.add_argument("--ref-spp", type=int, default=256, help="samples per pixel of each reference frame")
    p.add_argument("--methods", default=",".join(METHODS), help="comma-separated: " + ", ".join(METHODS))
    p.add_argument("--extra-args", default="", help="more `cohort render` arguments for every method (not the "
                   "reference), e.g. \"--atrous-passes 2 --atrous-sigma 4\"")
    p.add_argument("--out", default="out/bench_quality")
    p.add_argument("--reuse-reference", action="store_true",
                   help="keep the reference frames already in --out when all are there (same path, size and spp)")
    args = p.parse_args()
    methods = args.methods.split(",")
    for m in methods:
        if m not in METHODS:
            sys.exit(f"bench_quality: unknown method '{m}' (expected one of {', '.join(METHODS)})")
    if not os.path.exists(args.cohort):
        sys.exit(f"bench_quality: {args.cohort} not found (build first, or pass --cohort)")

    ref_dir = os.path.join(args.out, f"reference_{args.ref_spp}spp")
    print(f"reference: {args.frames} frames at {args.ref_spp} spp ...", flush=True)
    have_reference = all(any(os.path.exists(os.path.join(ref_dir, f"frame_{f:04d}{ext}")) for ext in (".png", ".ppm"))
                         for f in range(args.frames))
    if args.reuse_reference and have_reference:
        ref_seconds = 0.0
        print("  (reused)", flush=True)
    else:
        ref_seconds = render(args, ref_dir, args.ref_spp, ["--no-convergence"])
    references = [load_ldr(frame_path(ref_dir, f)) for f in range(args.frames)]

    report = {"map": args.map, "tracers": args.tracers, "width": args.width, "height": args.height,
              "camera_path": args.camera_path, "spp": args.spp, "ref_spp": args.ref_spp,
              "reference_seconds": ref_seconds, "methods": {}}
    for m in methods:
        out_dir = os.path.join(args.out, m.replace("+", "_"))
        print(f"{m} ...", flush=True)
        render(args, out_dir, args.spp, METHODS[m] + args.extra_args.split())
        flips, psnrs = [], []
        for f in range(args.frames):
            test = load_ldr(frame_path(out_dir, f))
            _, mean_flip, _ = flip_evaluator.evaluate(references[f], test, "LDR", applyMagma=False)
            flips.append(float(mean_flip))
            psnrs.append(psnr(references[f], test))
        report["methods"][m] = {"flip": flips, "psnr": psnrs, "ms": stage_ms(os.path.join(out_dir, "stats.json"))}

    print(f"\n{args.map}, {args.tracers}, {args.width}x{args.height}, {args.camera_path}, {args.frames} frames, "
          f"{args.spp} spp against {args.ref_spp} spp")
    print(f"{'method':<26}{'mean FLIP':>10}{'last FLIP':>10}{'mean PSNR':>10}{'frame ms':>10}"
          f"{'blend ms':>10}{'denoise ms':>11}{'both ms':>9}")
    for m, r in report["methods"].items():
        ms = r["ms"]
        print(f"{m:<26}{statistics.mean(r['flip']):>10.4f}{r['flip'][-1]:>10.4f}{statistics.mean(r['psnr']):>10.2f}"
              f"{ms['frame']:>10.1f}{ms.get('convergence', 0.0):>10.2f}{ms.get('denoise', 0.0):>11.1f}"
              f"{ms.get('convergence+denoise', 0.0):>9.1f}")
    os.makedirs(args.out, exist_ok=True)
    json_path = os.path.join(args.out, "bench_quality.json")
    with open(json_path, "w") as f:
        json.dump(report, f, indent=2)
    print(f"wrote {json_path}")

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 4))
    for m, r in report["methods"].items():
        ax.plot(range(args.frames), r["flip"], marker="o", label=m)
    ax.set_xlabel("frame")
    ax.set_ylabel("mean FLIP (lower is better)")
    ax.set_title(f"{args.map}, {args.camera_path}, {args.spp} spp vs {args.ref_spp} spp ({args.tracers})")
    ax.legend()
    ax.grid(alpha=0.3)
    plot_path = os.path.join(args.out, "bench_quality.png")
    fig.tight_layout()
    fig.savefig(plot_path, dpi=100)
    print(f"wrote {plot_path}")


if __name__ == "__main__":
    main()
