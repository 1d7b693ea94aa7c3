#!/usr/bin/env python3
"""Summarises a `cohort render` stats.json: median, mean and 95th percentile of the frame interval (time
between delivered frames: the pipeline overlaps frames, so this is the time per frame), the end-to-end
latency, the Renderer's wall time, and per stage (the frame timeline), over the frames after a warm-up.
The headline's mean leaves out the run's last frame, whose interval holds the final image's write
(`--write last`): where frames alternate between two speeds the median picks one, the mean is the rate.

    tools/frame_times.py out/run/stats.json [--skip 20] [--json summary.json]
"""
import argparse
import json
import os
import statistics
import sys


def percentile(values, p):
    ordered = sorted(values)
    if not ordered:
        return float("nan")
    k = min(len(ordered) - 1, max(0, round(p / 100.0 * (len(ordered) - 1))))
    return ordered[k]


def summarise(stats, skip):
    frames = stats["frames"][skip:]
    if not frames:
        raise SystemExit(f"frame_times: only {len(stats['frames'])} frames, none left after skipping {skip}")
    out = {"tracers": stats.get("tracers"), "width": stats.get("width"), "height": stats.get("height"),
           "frames": len(frames)}
    for key in ("interval_ms", "end_to_end_ms", "wall_ms", "frame_ms", "idle_percent"):
        values = [f[key] for f in frames if key in f]
        out[key] = {"median": statistics.median(values), "p95": percentile(values, 95),
                    "mean": statistics.fmean(values)} if values else None
    but_last = [f["interval_ms"] for f in frames[:-1] if "interval_ms" in f]
    if out["interval_ms"] and but_last:
        out["interval_ms"]["mean_but_last"] = statistics.fmean(but_last)
    per_stage = {}
    for f in frames:
        totals = {}
        for s in f.get("stages", []):
            name = f"{s['track']}/{s['stage']}"
            totals[name] = totals.get(name, 0.0) + s["ms"]
        for name, ms in totals.items():
            per_stage.setdefault(name, []).append(ms)
    out["stages_median_ms"] = {name: statistics.median(v) for name, v in sorted(per_stage.items())}
    # Per tracer: its bands whose job was handed out only after its band before had ended (it waited for
    # work: `job_wait_ms` > 0; stats.json from before the count has none).
    waits = {}
    for f in frames:
        for t in f.get("tracers", []):
            if t.get("outcome") != "rendered" or "job_wait_ms" not in t:
                continue
            w = waits.setdefault(f"tracer {t['id']} ({t['name']})", {"bands": 0, "waits": []})
            w["bands"] += 1
            if t["job_wait_ms"] > 0.0:
                w["waits"].append(t["job_wait_ms"])
    out["job_waits"] = {name: {"bands": w["bands"], "waited": len(w["waits"]),
                               "median_wait_ms": statistics.median(w["waits"]) if w["waits"] else 0.0,
                               "mean_wait_ms_per_band": sum(w["waits"]) / w["bands"]}
                        for name, w in sorted(waits.items())}
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("stats")
    parser.add_argument("--skip", type=int, default=20, help="warm-up frames left out (default 20)")
    parser.add_argument("--json", help="also write the summary here")
    args = parser.parse_args()
    with open(args.stats) as f:
        summary = summarise(json.load(f), args.skip)
    if args.json:  # first: a reader that stops after the headline (`| head -n 1`) must not lose it
        with open(args.json, "w") as f:
            json.dump(summary, f, indent=2)
    e2e, wall = summary["end_to_end_ms"], summary["wall_ms"]
    interval = summary["interval_ms"] or e2e  # stats.json from before the pipeline has no interval
    try:
        print(f"{summary['tracers']}: {summary['frames']} frames at {summary['width']}x{summary['height']}: "
              f"per frame median {interval['median']:.2f} ms "
              f"(mean {interval.get('mean_but_last', interval['mean']):.2f}, p95 {interval['p95']:.2f}), "
              f"latency median {e2e['median']:.2f} ms, renderer wall {wall['median']:.2f} ms, "
              f"idle {summary['idle_percent']['mean']:.1f}% mean")
        for name, ms in summary["stages_median_ms"].items():
            print(f"  {name:60s} {ms:8.3f} ms")
        for name, w in summary["job_waits"].items():
            print(f"  {name}: waited for its job in {w['waited']} of {w['bands']} bands "
                  f"(median wait {w['median_wait_ms']:.3f} ms, {w['mean_wait_ms_per_band']:.3f} ms a band)")
        sys.stdout.flush()
    except BrokenPipeError:
        # The reader took what it wanted (`| head -n 1`): no traceback, and none at exit either.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
    return 0


if __name__ == "__main__":
    sys.exit(main())
