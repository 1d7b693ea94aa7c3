#!/usr/bin/env python3
"""Image quality in motion: per-frame FLIP and PSNR against a converged reference along a camera path or
along a recorded scenario (a delta stream: moving objects, lights and camera).

Renders the same camera path (or replay) with `cohort render` once at high spp (the reference, every frame rendered
afresh) and once per method at the interactive sample count, then compares each written frame with the
reference frame: NVIDIA's FLIP (flip-evaluator, LDR, on the tone-mapped PNGs a viewer sees) and PSNR.
Methods: none (each frame as rendered), brigade (adaptive convergence, Brigade's blend), oidn (each frame
denoised by Open Image Denoise), brigade+oidn (the blended frame denoised), reproject (per-pixel history
through motion vectors, core/reprojection.h), reproject+oidn (the reprojected frame denoised, with the
albedo and normal planes as the denoiser's guides), atrous and reproject+atrous (the real-time edge-aware
a-trous filter of the portable kernel, core/atrous_filter.h, on each frame or on the reprojected one, with
its default luminance stop; the -fixed and -variance methods name the stop: --atrous-guide). Reports a table, JSON, a
per-frame FLIP plot and the milliseconds each method's extra stages took (from stats.json).

With --scenario (the test map's scenario, recorded first by `cohort record-scenario`) or --replay FILE,
the frames follow the stream, and the reference run also writes its id plane (`cohort render --write-ids`):
FLIP is then also measured on one object's pixels (--mask-entity, default door_main): the pixels it covers
in the reference frame, and those it covered in any of the --mask-history frames before if it moved since
(the pixels it just left, where a ghost would trail), grown by one pixel. Once it has stood still that
many frames, the mask is its own pixels (grown by one: the edges, where history bleeds). The object's last moving
frame L is the last frame whose placement differs from the one before (stats.json's moved_entities); "after N still frames" (--still-frames)
is frame L + N, the N-th frame in which it stood where frame L left it. The "swept" figures use every pixel it
covered since it started moving instead (its whole path, as seen from each frame's camera).

Setup once: bench/quality/setup_env.sh, then
    .venv-quality/bin/python bench/quality/bench_quality.py [--map testmap] [--frames 12] [--ref-spp 256]
    .venv-quality/bin/python bench/quality/bench_quality.py --scenario --frames 48 --methods brigade,reproject
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
    # The same filter on an NVIDIA GPU (OIDN's CUDA device), as a player with a GPU would get it.
    "oidn-cuda": ["--no-convergence", "--denoise", "oidn-cuda"],
    "reproject+oidn-cuda": ["--convergence", "reproject", "--denoise", "oidn-cuda"],
    "atrous": ["--no-convergence", "--denoise", "atrous"],
    "atrous-fixed": ["--no-convergence", "--denoise", "atrous", "--atrous-guide", "fixed"],
    "reproject+atrous": ["--convergence", "reproject", "--denoise", "atrous"],
    "reproject+atrous-fixed": ["--convergence", "reproject", "--denoise", "atrous", "--atrous-guide", "fixed"],
    # The G-buffer from the first sample's own first hit instead of a centre ray of its own (--aux-rays; its
    # default, auto, takes first hits on CUDA-only runs and centre rays elsewhere: these two name it).
    "reproject+atrous-centre": ["--convergence", "reproject", "--denoise", "atrous", "--aux-rays", "centre"],
    "reproject-first-hit": ["--convergence", "reproject", "--aux-rays", "first-hit"],
    "reproject+atrous-first-hit": ["--convergence", "reproject", "--denoise", "atrous", "--aux-rays", "first-hit"],
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
    source = ["--replay", args.replay] if args.replay else [args.map, "--camera-path", args.camera_path]
    cmd = [args.cohort, "render"] + source + ["--tracers", args.tracers, "--width", str(args.width), "--height",
           str(args.height), "--spp", str(spp), "--frames", str(args.frames),
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


def record_scenario(args):
    """Records the test map's scenario (door, fan, flicker, flashlight) at --scenario-fps into --out."""
    os.makedirs(args.out, exist_ok=True)
    path = os.path.join(args.out, f"scenario_{args.scenario_fps:g}fps_{args.frames}.cds")
    cmd = [args.cohort, "record-scenario", args.map, "--frames", str(args.frames), "--fps", str(args.scenario_fps),
           "--out", path]
    result = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if result.returncode != 0:
        sys.exit(f"bench_quality: `{' '.join(cmd)}` failed:\n{result.stderr[-2000:]}")
    return path


def read_pnm(path, magic, maxval):
    """A binary PNM as `cohort render` writes it (no comments): its width, height and pixel bytes, checked
    against the magic (b"P5", b"P6") and maxval it must have."""
    with open(path, "rb") as f:
        data = f.read()
    fields, pos = [], 0
    while len(fields) < 4:  # magic, width, height, maxval
        while data[pos:pos + 1].isspace():
            pos += 1
        end = pos
        while end < len(data) and not data[end:end + 1].isspace():
            end += 1
        fields.append(data[pos:end])
        pos = end
    if fields[0] != magic or not fields[3].isdigit() or int(fields[3]) != maxval:
        sys.exit(f"bench_quality: {path} is not a {magic.decode()} PNM with maxval {maxval}")
    width, height = int(fields[1]), int(fields[2])
    return width, height, data[pos + 1:]


def load_id_plane(path):
    """A 16-bit binary PGM as `cohort render --write-ids` writes it: 0 the world, entity + 1, 65535 a miss."""
    width, height, pixels = read_pnm(path, b"P5", 65535)
    if len(pixels) < 2 * width * height:
        sys.exit(f"bench_quality: {path} is truncated")
    return np.frombuffer(pixels[:2 * width * height], dtype=">u2").reshape(height, width)


def grow(mask, pixels):
    """The mask grown by `pixels` in the 8 directions."""
    out = mask.copy()
    for _ in range(pixels):
        m = out.copy()
        m[1:, :] |= out[:-1, :]
        m[:-1, :] |= out[1:, :]
        m[:, 1:] |= out[:, :-1]
        m[:, :-1] |= out[:, 1:]
        m[1:, 1:] |= out[:-1, :-1]
        m[:-1, :-1] |= out[1:, 1:]
        m[1:, :-1] |= out[:-1, 1:]
        m[:-1, 1:] |= out[1:, :-1]
        out = m
    return out


def object_masks(args, ref_dir):
    """Per frame, the --mask-entity's pixels (with its recent trail) and its swept path, from the reference's
    id planes; and the frame L after which it stands still (None if it never moves in the frames rendered)."""
    with open(os.path.join(ref_dir, "stats.json")) as f:
        stats = json.load(f)
    ids = stats.get("entity_ids", {})
    if args.mask_entity not in ids:
        sys.exit(f"bench_quality: the reference's stats.json names no entity '{args.mask_entity}' "
                 f"(has: {', '.join(sorted(ids)) or 'none; was it rendered with --write-ids?'})")
    entity_id = ids[args.mask_entity]
    moving = [i for i, fr in enumerate(stats["frames"]) if args.mask_entity in fr.get("moved_entities", [])]
    covered = [load_id_plane(os.path.join(ref_dir, f"ids_{f:04d}.pgm")) == entity_id for f in range(args.frames)]
    first_moving = moving[0] if moving else None
    moved_in = set(moving)
    recent, swept = [], []
    for f in range(args.frames):
        m = covered[f].copy()
        for k in range(1, args.mask_history + 1):
            # Where it was k frames ago counts only if it moved since: once still, its pixels are its own.
            if f - k >= 0 and any(j in moved_in for j in range(f - k + 1, f + 1)):
                m |= covered[f - k]
        recent.append(grow(m, 1))
        s = covered[f].copy()
        if first_moving is not None and f >= first_moving:
            for j in range(max(first_moving - 1, 0), f):
                s |= covered[j]
        swept.append(grow(s, 1))
    return {"entity": args.mask_entity, "id": entity_id, "moving_frames": moving,
            "last_moving_frame": moving[-1] if moving else None, "recent": recent, "swept": swept}


def masked_mean(flip_map, mask):
    return float(flip_map[mask].mean()) if mask.any() else None


def load_ldr(path):
    """The frame as FLIP's LDR input: float32 sRGB values in [0, 1], height x width x 3. A build without
    OpenImageIO (the GPU machine's) writes binary PPM, which FLIP's own loader does not read."""
    if path.endswith(".ppm"):
        return load_ppm(path)
    return flip_evaluator.load(path)


def load_ppm(path):
    """An 8-bit binary PPM (P6, maxval 255) as `cohort render` writes it, as flip_evaluator.load returns a PNG."""
    width, height, pixels = read_pnm(path, b"P6", 255)
    if len(pixels) < 3 * width * height:
        sys.exit(f"bench_quality: {path} is truncated ({len(pixels)} of {3 * width * height} bytes)")
    return (np.frombuffer(pixels[:3 * width * height], dtype=np.uint8).reshape(height, width, 3).astype(np.float32) /
            np.float32(255.0))


def linear_light(image):
    """The frame's mean light: its sRGB values linearised (the EOTF) and averaged. Against the reference's it shows
    a method that loses or adds light (a clamp or an edge stop biased by skewed noise), which FLIP and PSNR mix
    with noise. A mean of tone-mapped values, so a guide to bias, not a radiometric measure."""
    v = image.astype(np.float64)
    return float(np.mean(np.where(v <= 0.04045, v / 12.92, ((v + 0.055) / 1.055) ** 2.4)))


def psnr(reference, test):
    mse = float(np.mean((reference.astype(np.float64) - test.astype(np.float64)) ** 2))
    return float("inf") if mse == 0.0 else 10.0 * np.log10(1.0 / mse)


def temporal_rmse(reference_before, reference, test_before, test):
    """How far the frame-to-frame change of a method's frames is from the reference's (RMSE over pixels and
    channels, display values in [0, 1]): flicker, and lag, that each frame's own FLIP does not see. A method
    that renders each frame afresh shows its noise twice here; one that holds history too long shows its lag."""
    change = (test.astype(np.float64) - test_before) - (reference.astype(np.float64) - reference_before)
    return float(np.sqrt(np.mean(change ** 2)))


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
    p.add_argument("--scenario", action="store_true",
                   help="record the map's scenario (`cohort record-scenario`: the door opens and stops, the fan spins, "
                        "a light flickers, a flashlight follows the camera) and measure along it instead of a path")
    p.add_argument("--scenario-fps", type=float, default=20.0,
                   help="scenario time per frame of --scenario: at 20 the door moves in frames 11-40")
    p.add_argument("--replay", default="", help="a recorded delta stream to measure along instead of a camera path")
    p.add_argument("--mask-entity", default="door_main",
                   help="with --scenario/--replay: the entity whose pixels get their own FLIP")
    p.add_argument("--mask-history", type=int, default=4,
                   help="the entity's mask also holds the pixels it covered in this many frames before, if it moved since")
    p.add_argument("--still-frames", type=int, default=4,
                   help="report the entity's FLIP this many frames after its last moving frame")
    args = p.parse_args()
    methods = args.methods.split(",")
    for m in methods:
        if m not in METHODS:
            sys.exit(f"bench_quality: unknown method '{m}' (expected one of {', '.join(METHODS)})")
    if not os.path.exists(args.cohort):
        sys.exit(f"bench_quality: {args.cohort} not found (build first, or pass --cohort)")
    if args.scenario and args.replay:
        sys.exit("bench_quality: --scenario records its own stream; drop --replay")
    if args.scenario:
        args.replay = record_scenario(args)
    elif args.replay and not os.path.exists(args.replay):
        sys.exit(f"bench_quality: {args.replay} not found")

    ref_dir = os.path.join(args.out, f"reference_{args.ref_spp}spp")
    print(f"reference: {args.frames} frames at {args.ref_spp} spp ...", flush=True)
    have_reference = all(any(os.path.exists(os.path.join(ref_dir, f"frame_{f:04d}{ext}")) for ext in (".png", ".ppm"))
                         for f in range(args.frames))
    if args.replay:
        have_reference = have_reference and os.path.exists(os.path.join(ref_dir, "stats.json")) and all(
            os.path.exists(os.path.join(ref_dir, f"ids_{f:04d}.pgm")) for f in range(args.frames))
    if args.reuse_reference and have_reference:
        ref_seconds = 0.0
        print("  (reused)", flush=True)
    else:
        ref_seconds = render(args, ref_dir, args.ref_spp, ["--no-convergence"] + (["--write-ids"] if args.replay else []))
    references = [load_ldr(frame_path(ref_dir, f)) for f in range(args.frames)]
    reference_light = [linear_light(r) for r in references]
    masks = object_masks(args, ref_dir) if args.replay else None
    still_frame = None
    if masks:
        last = masks["last_moving_frame"]
        if last is None:
            print(f"warning: '{args.mask_entity}' does not move in these {args.frames} frames", flush=True)
        elif last + args.still_frames >= args.frames:
            print(f"warning: '{args.mask_entity}' moves until frame {last}: render at least "
                  f"{last + args.still_frames + 1} frames to see it {args.still_frames} frames still", flush=True)
        else:
            still_frame = last + args.still_frames

    report = {"map": args.map, "tracers": args.tracers, "width": args.width, "height": args.height,
              "camera_path": None if args.replay else args.camera_path, "replay": args.replay or None,
              "scenario_fps": args.scenario_fps if args.scenario else None, "frames": args.frames,
              "spp": args.spp, "ref_spp": args.ref_spp, "reference_seconds": ref_seconds, "methods": {}}
    if masks:
        report["mask"] = {"entity": masks["entity"], "id": masks["id"], "moving_frames": masks["moving_frames"],
                          "last_moving_frame": masks["last_moving_frame"], "history": args.mask_history,
                          "still_frames": args.still_frames, "still_frame": still_frame,
                          "pixels": [int(m.sum()) for m in masks["recent"]],
                          "swept_pixels": [int(m.sum()) for m in masks["swept"]]}
    for m in methods:
        out_dir = os.path.join(args.out, m.replace("+", "_"))
        print(f"{m} ...", flush=True)
        render(args, out_dir, args.spp, METHODS[m] + args.extra_args.split())
        flips, psnrs, lights, object_flips, swept_flips, temporal = [], [], [], [], [], []
        before = None
        for f in range(args.frames):
            test = load_ldr(frame_path(out_dir, f))
            if before is not None:
                temporal.append(temporal_rmse(references[f - 1], references[f], before, test))
            before = test
            flip_map, mean_flip, _ = flip_evaluator.evaluate(references[f], test, "LDR", applyMagma=False)
            flips.append(float(mean_flip))
            psnrs.append(psnr(references[f], test))
            lights.append(100.0 * (linear_light(test) / reference_light[f] - 1.0) if reference_light[f] > 0 else 0.0)
            if masks:
                flip_map = np.asarray(flip_map).reshape(test.shape[0], test.shape[1])
                object_flips.append(masked_mean(flip_map, masks["recent"][f]))
                swept_flips.append(masked_mean(flip_map, masks["swept"][f]))
        r = {"flip": flips, "psnr": psnrs, "light_percent": lights, "temporal_rmse": temporal,
             "ms": stage_ms(os.path.join(out_dir, "stats.json"))}
        if masks:
            r["object_flip"] = object_flips
            r["object_swept_flip"] = swept_flips
            r["object_flip_still"] = object_flips[still_frame] if still_frame is not None else None
            r["object_swept_flip_still"] = swept_flips[still_frame] if still_frame is not None else None
        report["methods"][m] = r

    source = os.path.basename(args.replay) if args.replay else args.camera_path
    print(f"\n{args.map}, {args.tracers}, {args.width}x{args.height}, {source}, {args.frames} frames, "
          f"{args.spp} spp against {args.ref_spp} spp")
    if masks:
        print(f"{args.mask_entity}: moves in frames {masks['moving_frames'][0] if masks['moving_frames'] else '-'}-"
              f"{masks['last_moving_frame'] if masks['moving_frames'] else '-'}; 'still' columns: frame "
              f"{still_frame if still_frame is not None else '-'} ({args.still_frames} frames still); 'obj' = its "
              f"pixels and last {args.mask_history} frames' trail, 'swept' = its whole path")
    print("'light %': the frames' mean linearised light against the reference's, averaged over the frames after "
          "the first 8 (a bias: light lost or added)")
    print("'temporal': RMSE of each frame's change from the frame before against the reference's change, display "
          "values, mean over the frames (flicker and lag; lower is better)")
    object_header = f"{'obj FLIP':>9}{'obj still':>10}{'swept still':>12}" if masks else ""
    print(f"{'method':<26}{'mean FLIP':>10}{'last FLIP':>10}{'mean PSNR':>10}{'light %':>9}{'temporal':>9}{object_header}{'frame ms':>10}"
          f"{'blend ms':>10}{'denoise ms':>11}{'both ms':>9}")

    def cell(v, width):
        return f"{v:>{width}.4f}" if v is not None else f"{'-':>{width}}"
    for m, r in report["methods"].items():
        ms = r["ms"]
        object_cells = ""
        if masks:
            seen = [v for v in r["object_flip"] if v is not None]
            object_cells = (cell(statistics.mean(seen) if seen else None, 9) + cell(r["object_flip_still"], 10) +
                            cell(r["object_swept_flip_still"], 12))
        settled = r["light_percent"][8:] or r["light_percent"]
        print(f"{m:<26}{statistics.mean(r['flip']):>10.4f}{r['flip'][-1]:>10.4f}{statistics.mean(r['psnr']):>10.2f}"
              f"{statistics.mean(settled):>+9.1f}{cell(statistics.mean(r['temporal_rmse']) if r['temporal_rmse'] else None, 9)}{object_cells}{ms['frame']:>10.1f}{ms.get('convergence', 0.0):>10.2f}{ms.get('denoise', 0.0):>11.1f}"
              f"{ms.get('convergence+denoise', 0.0):>9.1f}")
    os.makedirs(args.out, exist_ok=True)
    json_path = os.path.join(args.out, "bench_quality.json")
    with open(json_path, "w") as f:
        json.dump(report, f, indent=2)
    print(f"wrote {json_path}")

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2 if masks else 1, figsize=(13 if masks else 7, 4), squeeze=False)
    ax = axes[0][0]
    for m, r in report["methods"].items():
        ax.plot(range(args.frames), r["flip"], marker="o", markersize=3, label=m)
    ax.set_xlabel("frame")
    ax.set_ylabel("mean FLIP (lower is better)")
    ax.set_title(f"{args.map}, {source}, {args.spp} spp vs {args.ref_spp} spp ({args.tracers})", fontsize=9)
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    if masks:
        ax = axes[0][1]
        for m, r in report["methods"].items():
            ax.plot(range(args.frames), [v if v is not None else float("nan") for v in r["object_flip"]], marker="o",
                    markersize=3, label=m)
        if masks["moving_frames"]:
            ax.axvspan(masks["moving_frames"][0], masks["last_moving_frame"], color="grey", alpha=0.15,
                       label=f"{args.mask_entity} moving")
        if still_frame is not None:
            ax.axvline(still_frame, color="black", linestyle="--", linewidth=1,
                       label=f"{args.still_frames} frames still")
        ax.set_xlabel("frame")
        ax.set_ylabel(f"FLIP on {args.mask_entity}'s pixels")
        ax.set_title(f"{args.mask_entity} and its last {args.mask_history} frames' pixels", fontsize=9)
        ax.legend(fontsize=8)
        ax.grid(alpha=0.3)
    plot_path = os.path.join(args.out, "bench_quality.png")
    fig.tight_layout()
    fig.savefig(plot_path, dpi=100)
    print(f"wrote {plot_path}")
    if masks:
        crops_path = write_object_crops(args, ref_dir, masks, methods, plt)
        if crops_path:
            print(f"wrote {crops_path}")


def write_object_crops(args, ref_dir, masks, methods, plt):
    """Side by side, the reference and each method around the object's swept path, at the frame it started
    moving, halfway, its last moving frame and N still frames after (rows), 3x enlarged."""
    last = masks["last_moving_frame"]
    if last is None:
        return None
    first = masks["moving_frames"][0]
    frames = sorted({first, (first + last) // 2, last, min(last + args.still_frames, args.frames - 1)})
    union = np.zeros_like(masks["swept"][0])
    for f in frames:
        union |= masks["swept"][f]
    ys, xs = np.nonzero(union)
    if len(xs) == 0:
        return None
    margin = 6
    y0, y1 = max(ys.min() - margin, 0), min(ys.max() + margin + 1, union.shape[0])
    x0, x1 = max(xs.min() - margin, 0), min(xs.max() + margin + 1, union.shape[1])
    dirs = [ref_dir] + [os.path.join(args.out, m.replace("+", "_")) for m in methods]
    rows = []
    for f in frames:
        row = []
        for d in dirs:
            img = load_ldr(frame_path(d, f))[..., :3]
            row.append(img[y0:y1, x0:x1])
            row.append(np.ones((y1 - y0, 1, 3), np.float32))
        rows.append(np.concatenate(row[:-1], axis=1))
        rows.append(np.ones((1, rows[-1].shape[1], 3), np.float32))
    tile = np.concatenate(rows[:-1], axis=0)
    tile = np.repeat(np.repeat(tile, 3, axis=0), 3, axis=1)
    path = os.path.join(args.out, f"bench_quality_{args.mask_entity}.png")
    plt.imsave(path, np.clip(tile, 0.0, 1.0))
    with open(os.path.splitext(path)[0] + ".txt", "w") as f:
        f.write(f"columns: reference, {', '.join(methods)}; rows: frames {', '.join(map(str, frames))}\n")
    return path


if __name__ == "__main__":
    main()
