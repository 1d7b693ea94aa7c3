#!/usr/bin/env python3
"""tools/frame_times.py on a small stats.json: the headline's medians are the frames' after the warm-up, its
mean leaves out the last frame (the final image's write), the stages are summed per frame, and a reader that stops early (`| head -n 1`, here: closes the pipe at once)
costs neither the --json summary nor a traceback.

    frame_times_test.py TOOLS/frame_times.py
"""
import json
import os
import subprocess
import sys
import tempfile


def main():
    tool = sys.argv[1]
    with tempfile.TemporaryDirectory() as folder:
        frames = []
        for i in range(10):
            interval = 100.0 if i < 2 else 2.0 + 0.1 * i  # two slow warm-up frames
            if i == 9:
                interval = 60.0  # the last frame writes the image
            frames.append({"interval_ms": interval, "end_to_end_ms": 2 * interval, "wall_ms": interval,
                           "frame_ms": interval, "idle_percent": 1.0,
                           "stages": [{"track": "core", "stage": "merge", "ms": 0.25},
                                      {"track": "core", "stage": "merge", "ms": 0.25}]})
        stats = os.path.join(folder, "stats.json")
        with open(stats, "w") as f:
            json.dump({"tracers": "sim", "width": 8, "height": 4, "frames": frames}, f)
        summary = os.path.join(folder, "summary.json")
        out = subprocess.run([sys.executable, tool, stats, "--skip", "2", "--json", summary], capture_output=True,
                             text=True, check=True).stdout
        if "per frame median 2.55 ms (mean 2.50," not in out or "core/merge" not in out:
            sys.exit(f"unexpected headline or stages:\n{out}")
        with open(summary) as f:
            written = json.load(f)
        if written["frames"] != 8 or abs(written["stages_median_ms"]["core/merge"] - 0.5) > 1e-9:
            sys.exit(f"unexpected summary: {written}")
        os.remove(summary)
        reader = subprocess.Popen([sys.executable, tool, stats, "--skip", "2", "--json", summary],
                                  stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        reader.stdout.close()  # a reader that has what it wanted
        errors = reader.stderr.read().decode()
        status = reader.wait()
        if status != 0 or "Traceback" in errors:
            sys.exit(f"a closed pipe ended it with status {status}:\n{errors}")
        if not os.path.exists(summary):
            sys.exit("a closed pipe lost the --json summary")
    print("frame_times: ok")


if __name__ == "__main__":
    main()
