#!/usr/bin/env python3
"""Cluster runs of `cohort render` on rank 0 with `cohort node` on ranks 1 and 2, all on localhost,
checked against a single-process render of the same frames (the integrator is deterministic per
pixel, so the images must match byte for byte).

    run_cluster.py CASE --mpiexec PATH --cohort PATH --map MAP --out DIR [--broken-map MAP]

CASE: match (Embree on every rank), mixed (rank 1 splits its band between Embree and OpenCL, rank 2
renders on OpenCL: PoCL on a machine without GPUs; images agree within the tracers' tolerance),
stall (rank 2 sleeps through frame 1: its rows are re-rendered by
the others, only that frame is late, and rank 2 renders again once it answers), killed (the same with
rank 2 killed: Open MPI only, with orte_enable_recovery), version (rank 1 announces another version: rank 0
names both and renders without it), load_error (rank 1 cannot load its map: rank 0 logs its file:line
reason and renders without it), bench (`cohort bench devices` with remote tracers reports their bytes
per frame and round trip), protocol (protocol_check.cpp on 2 ranks: malformed messages against a
real node), replay (the test map's recorded scenario: door, fan, flicker, a skinned walker; instance,
TLAS, light and joint records cross the wire every frame, and every frame matches), play (`cohort play`
under a virtual display with remote tracers: the scenario runs, the screenshot is written and not
uniform; skipped with status 77 without xvfb-run or the viewer), bad_piece (rank 2 sends a piece of its
band's rows a byte short once: rank 0 refuses that band with the sizes, its rows are re-rendered by the
others, and every frame matches), ahead (the scenario on mpi:1 and mpi:2 alone, the nodes taking 40 ms
longer a band: each frame's commit is submitted while the band before renders, travels behind that band's
job and is applied once it is rendered; every frame matches the single-process render), ahead_recovery
(the same with rank 2 stalled through frame 1: its rows are re-rendered on mpi:1, whose node has already
applied the next frame's commit; rank 0 says so, and the frame differs from the single-process render at
most in those rows, the others match), jobs_ahead (the scenario on mpi:1 and mpi:2 alone, the nodes 3
and 6 ms slower a row (bands far longer than rank 0's own frame work, so that each next job is announced
while they render), so that the balancer moves rows every frame: each later frame's job goes to the
node while its band before renders, the node renders it right after that band, and the frame's job
adopts those rows, rendering only the rows beyond them; every frame matches the single-process render;
with COHORT_MPI_JOBS_AHEAD=0 nothing is adopted), jobs_ahead_two_in_flight (the same with rank 0 rendering
--frames-in-flight 2, jobs ahead on: the job queued behind a band is the one sent ahead, its commit before
it; every later job adopted, every frame matches), early_announce (rank 0 writes every frame, which takes
longer than a node's band: announced after that work, COHORT_EARLY_ANNOUNCE=0, bands come back before the
next frame is announced (5-9 of 11 here); announced at hand-out, none does; every frame matches), link (`cohort bench devices` with mpi:1 behind an emulated
link, COHORT_MPI_LINK=0.1gbit,20ms on every rank: the band's round trip holds the link's latency both ways and
its bytes at the link's rate), match_rgb9e5 (match with the rows as RGB9E5, 4 bytes a pixel: the
dither is a hash of pixel and frame, so the nodes' rows equal the single-process render's, and the nodes log
4 bytes a pixel), play_early_announce (`cohort play` under a virtual display with mpi:1 and mpi:2 alone, the
window 320x180 in albedo mode: announced at hand-out (the default) at most 2 bands of both nodes come back
before the next frame is announced, and its jobs ahead leave sooner after their band's job than with
COHORT_EARLY_ANNOUNCE=0, where play announces a frame only when it pushes it), play_join (`cohort play` with
--node-port: a node started on its own joins mpi:1 and renders in play).
"""
import argparse
import json
import os
import re
import shutil
import socket
import subprocess
import sys
import time

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


def compare_frames(a_dir, b_dir, tolerant=False, frames=FRAMES):
    """Byte for byte; tolerant (other tracer kinds): at most 0.5% of pixels differ, by at most 3 levels."""
    for f in range(frames):
        name = f"frame_{f:04d}.png"
        a, b = os.path.join(a_dir, name), os.path.join(b_dir, name)
        if not os.path.exists(b):
            sys.exit(f"{b} was not written: the cluster lost frame {f}")
        (wa, ha, ca, pa), (wb, hb, cb, pb) = read_image(a), read_image(b)
        if (wa, ha) != (wb, hb):
            sys.exit(f"{name}: sizes differ")
        differing, worst = 0, 0
        for p in range(wa * ha):
            d = max(abs(pa[p * ca + c] - pb[p * cb + c]) for c in range(3))
            differing += d > 0
            worst = max(worst, d)
        print(f"{name}: {differing} of {wa * ha} pixels differ, by at most {worst} levels")
        if (differing > 0.005 * wa * ha or worst > 3) if tolerant else differing:
            sys.exit(f"{name}: the cluster's image differs from the single-process render")


# Below this a frame is not called late whatever the median: the tests' frames take 2-5 ms, and on the loaded
# 2-core VM (rank 0 and two nodes on two cores) a node waking from its stall, or the scheduler, stretches a frame
# to 7-9 ms now and then (seen in mpi.cluster_stall); a lost band costs the 1000 ms band timeout.
LATE_FLOOR_MS = 25.0


def late_after_fault(stats, fault, until=None):
    """The frames from `fault` up to `until` (the end of the run when None) that took more than 3x the run's
    median (and LATE_FLOOR_MS): a fault should cost at most one such frame (issue 19), not one per frame while
    the node is away."""
    times = sorted(f["wall_ms"] for f in stats)
    median = times[len(times) // 2]
    end = len(stats) if until is None else until
    over_3x = [f["frame"] for f in stats[fault:end] if f["wall_ms"] > 3 * median]
    late = [f["frame"] for f in stats[fault:end] if f["wall_ms"] > max(3 * median, LATE_FLOOR_MS)]
    window = [f["wall_ms"] for f in stats[max(fault - 3, 0):fault + 6]]
    rest = [f["wall_ms"] for f in stats[fault + 1:end]]
    print(f"frames {max(fault - 3, 0)}..{fault + 5} around the fault: {', '.join(f'{t:.1f}' for t in window)} ms; "
          f"median of the run {median:.1f} ms, of the frames after the fault up to "
          f"{'the end' if until is None else until} {sorted(rest)[len(rest) // 2]:.1f} ms; over 3x the median there: "
          f"{over_3x}; late (and over {LATE_FLOOR_MS:.0f} ms): {late}")
    return late


def away_check(stats, name, fault, until=None, check_late=True):
    """From the frame after the fault: the slot's tracer is left out ("away", or "busy" with its commits) until it renders again (or until
    `until`, the rejoin), nothing is dropped and re-rendered meanwhile, and (check_late) from the fault up to `until` (the
    end of the run when None) at most the fault's frame is late. Exits with the reason otherwise."""
    end = len(stats) if until is None else until
    for f in stats[fault + 1:end]:
        t = next(t for t in f["tracers"] if t["name"] == name)
        if t["outcome"] == "rendered" and until is None:
            break  # a stalled node that answered: back
        # "busy": still on its commits handed out on the side (while away) when the frame began: not asked either.
        if t["outcome"] not in ("away", "busy"):
            sys.exit(f"frame {f['frame']}: {name} should be away (its node has not answered), not {t['outcome']} "
                     f"{t.get('error', '')}")
        if f["dropped"] != 0:
            sys.exit(f"frame {f['frame']}: {f['dropped']} tracer(s) dropped while {name} was away")
    if not check_late:
        return
    late = late_after_fault(stats, fault, until)
    if len(late) > 1 or (late and late[0] != fault):
        sys.exit(f"the fault at frame {fault} should make at most that frame late: {late}")


def tracer_outcomes(out_dir):
    with open(os.path.join(out_dir, "stats.json")) as f:
        stats = json.load(f)
    return [{t["name"]: t["outcome"] for t in frame["tracers"]} for frame in stats["frames"]]


def stall(a, killed=False):
    """Rank 2 sleeps 1.2 s before its band of frame 1 (killed: kills itself there); bands time out after
    1 s. Frame 1 is the one late frame (its rows are re-rendered by the others); while rank 2 has not
    answered, its bands fail at once; a stalled rank 2 renders again once it answers. The last frame
    matches the single-process render. A killed rank needs a launcher that lets the job outlive it:
    Open MPI with orte_enable_recovery (others: skipped)."""
    flags = mpiexec_flags(a.mpiexec)
    if killed:
        if "--oversubscribe" not in flags:
            # MPICH's mpiexec ends the whole job when a rank is killed, -disable-auto-cleanup or not (its
            # per-host proxy fails writing to the dead rank's PMI socket); nodes that join on their own
            # launch are separate jobs: the killed one's launcher ends alone.
            killed_joined(a)
            return
        flags = flags + ["--mca", "orte_enable_recovery", "1"]
    frames = 400
    args = ["--width", "192", "--height", "128", "--spp", "2", "--frames", str(frames), "--write", "last",
            "--balancer", "perfect-smooth"]
    single, cluster = os.path.join(a.out, "single"), os.path.join(a.out, "cluster")
    run([a.cohort, "render", a.map, "--tracers", "embree", "--out", single] + args)
    env = dict(os.environ)
    env["COHORT_MPI_BAND_TIMEOUT_MS"] = "1000"
    fault = ["--die-frame", "1"] if killed else ["--stall-frame", "1", "--stall-ms", "1200"]
    _, output = run([a.mpiexec] + flags + ["-np", "1", a.cohort, "render", a.map, "--tracers", "embree,mpi:1,mpi:2",
                                           "--out", cluster] + args +
                    [":"] + flags + ["-np", "1", a.cohort, "node", a.map, "--tracers", "embree"] +
                    [":"] + flags + ["-np", "1", a.cohort, "node", a.map, "--tracers", "embree"] + fault,
                    env=env, expect_ok=not killed)
    name = f"frame_{frames - 1:04d}.png"
    if not os.path.exists(os.path.join(cluster, "stats.json")):
        sys.exit("rank 0 did not finish the run")
    (w, h, ca, pa), (_, _, cb, pb) = read_image(os.path.join(single, name)), read_image(os.path.join(cluster, name))
    differing = sum(1 for p in range(w * h) if pa[p * ca:p * ca + 3] != pb[p * cb:p * cb + 3])
    print(f"{name}: {differing} of {w * h} pixels differ")
    with open(os.path.join(cluster, "stats.json")) as f:
        stats = json.load(f)["frames"]
    late = [f["frame"] for f in stats if f["wall_ms"] > 500]
    outcome = [{t["name"]: (t["outcome"], t.get("error", "")) for t in f["tracers"]} for f in stats]
    print("late frames:", late)
    print("mpi:2 per frame:", [o["mpi:2"][0] for o in outcome])
    if len(stats) != frames:
        sys.exit(f"{len(stats)} of {frames} frames delivered")
    if differing:
        sys.exit("the last frame differs from the single-process render")
    if late != [1]:
        sys.exit(f"the fault should make frame 1, and only it, late: {late}")
    if "no answer for rows" not in outcome[1]["mpi:2"][1]:
        sys.exit(f"frame 1: the node's band should have timed out: {outcome[1]['mpi:2']}")
    if outcome[2]["mpi:2"][0] != "away":
        sys.exit(f"frame 2: the silent node should have been left out (away): {outcome[2]['mpi:2']}")
    # Away until it answers (stall: then rendered again), never asked for a band meanwhile.
    away_check(stats, "mpi:2", 1)
    if killed:
        if any(o["mpi:2"][0] == "rendered" for o in outcome[1:]):
            sys.exit("a killed node cannot have rendered")
        if any(o["mpi:1"][0] != "rendered" for o in outcome):
            sys.exit("the surviving node should have rendered every frame")
    elif outcome[-1]["mpi:2"][0] != "rendered":
        sys.exit("the node did not come back after answering")
    print(f"{a.case}: ok")


def bad_piece(a):
    """Rank 2 sends piece 0 of its band of frame 1 a byte short: rank 0 refuses the band with the reason
    (never taking the piece into its rows), re-renders those rows on the others, and every frame, that
    one too, matches the single-process render; rank 2 renders the next frames."""
    args = RENDER_ARGS + ["--tracers", "embree,mpi:1,mpi:2"]
    single, cluster = os.path.join(a.out, "single"), os.path.join(a.out, "cluster")
    run([a.cohort, "render", a.map, "--out", single] + RENDER_ARGS + ["--tracers", "embree"])
    flags = mpiexec_flags(a.mpiexec)
    run([a.mpiexec] + flags + ["-np", "1", a.cohort, "render", a.map, "--out", cluster] + args +
        [":"] + flags + ["-np", "1", a.cohort, "node", a.map, "--tracers", "embree"] +
        [":"] + flags + ["-np", "1", a.cohort, "node", a.map, "--tracers", "embree", "--short-piece-frame", "1"])
    compare_frames(single, cluster)
    with open(os.path.join(cluster, "stats.json")) as f:
        stats = json.load(f)["frames"]
    outcome = [{t["name"]: (t["outcome"], t.get("error", "")) for t in f["tracers"]} for f in stats]
    print("mpi:2 per frame:", [o["mpi:2"] for o in outcome])
    status, error = outcome[1]["mpi:2"]
    if status != "threw" or "refused the band's rows: piece 0 of" not in error or "bytes; they are" not in error:
        sys.exit(f"frame 1: the short piece should have been refused with its sizes: {outcome[1]['mpi:2']}")
    if any(o["mpi:2"][0] != "rendered" for i, o in enumerate(outcome) if i != 1):
        sys.exit("rank 2 should render every other frame")
    print("bad_piece: ok")


def replay(a):
    os.makedirs(a.out)
    stream = os.path.join(a.out, "scenario.cdelta")
    run([a.cohort, "record-scenario", "testmap", "--base", a.testmap_base, "--frames", str(FRAMES), "--out", stream])
    args = ["--replay", stream, "--base", a.testmap_base, "--width", "96", "--height", "54", "--spp", "1"]
    single, cluster = os.path.join(a.out, "single"), os.path.join(a.out, "cluster")
    run([a.cohort, "render", "--tracers", "embree", "--out", single] + args)
    flags = mpiexec_flags(a.mpiexec)
    _, output = run([a.mpiexec] + flags + ["-np", "1", a.cohort, "render", "--tracers", "embree,mpi:1,mpi:2",
                                           "--out", cluster] + args +
                    [":"] + flags + ["-np", "2", a.cohort, "node", "testmap", "--base", a.testmap_base,
                                     "--tracers", "embree"])
    compare_frames(single, cluster)
    outcomes = tracer_outcomes(cluster)
    print("outcomes per frame:", outcomes)
    # A frame may leave a node out ("no_rows": the balancer found the frame faster without it, which a loaded
    # machine can make so); a failed band may not, and each node must render frames after the first, so that
    # the scenario's commits reached it.
    if any(o.get(t) not in ("rendered", "no_rows") for o in outcomes for t in ("mpi:1", "mpi:2")):
        sys.exit("a remote tracer failed a band of the scenario")
    if any(sum(o.get(t) == "rendered" for o in outcomes[1:]) < 2 for t in ("mpi:1", "mpi:2")):
        sys.exit("a remote tracer rendered fewer than 2 of the scenario's frames after the first")
    if "sending the whole scene" in output:
        sys.exit("the nodes loaded the same map: the first resync should not have sent the whole scene")
    print("replay: ok")


def ahead(a, stalled=False):
    os.makedirs(a.out)
    stream = os.path.join(a.out, "scenario.cdelta")
    run([a.cohort, "record-scenario", "testmap", "--base", a.testmap_base, "--frames", str(FRAMES), "--out", stream])
    args = ["--replay", stream, "--base", a.testmap_base, "--width", "96", "--height", "54", "--spp", "1"]
    if stalled:
        args.append("--no-convergence")  # each frame as rendered: a re-rendered row's difference stays in it
    single, cluster = os.path.join(a.out, "single"), os.path.join(a.out, "cluster")
    run([a.cohort, "render", "--tracers", "embree", "--out", single] + args)
    flags = mpiexec_flags(a.mpiexec)
    node = [a.cohort, "node", "testmap", "--base", a.testmap_base, "--tracers", "embree", "--band-delay-ms",
            "100" if stalled else "40"]
    env = dict(os.environ)
    if stalled:
        env["COHORT_MPI_BAND_TIMEOUT_MS"] = "1000"
        nodes = ["-np", "1"] + node + [":"] + flags + ["-np", "1"] + node + ["--stall-frame", "1", "--stall-ms", "2500"]
    else:
        nodes = ["-np", "2"] + node
    _, output = run([a.mpiexec] + flags + ["-np", "1", a.cohort, "render", "--tracers", "mpi:1,mpi:2", "--out", cluster] +
                    args + [":"] + flags + nodes, env=env)
    if stalled:
        ahead_recovery_check(single, cluster, output)
        return
    compare_frames(single, cluster)
    if any(o.get("mpi:1") != "rendered" or o.get("mpi:2") != "rendered" for o in tracer_outcomes(cluster)):
        sys.exit("a remote tracer failed a band of the scenario")
    for rank in (1, 2):
        found = re.search(rf"mpi:{rank}: .*\((\d+) commit\(s\) sent ahead of their job\)", output)
        if not found:
            sys.exit(f"mpi:{rank}: no count of the commits sent ahead in the log")
        # Frame 0's commit comes with the first job; every later frame's goes ahead of its job.
        if int(found.group(1)) != FRAMES - 1:
            sys.exit(f"mpi:{rank}: {found.group(1)} commit(s) went ahead of their job; {FRAMES - 1} should have")
    print("ahead: ok")


def jobs_ahead(a, in_flight="1"):
    """in_flight "2": rank 0 renders with --frames-in-flight 2 (its next frame's job queued behind the band
    before: the remote tracer sends that one ahead), jobs ahead on only."""
    os.makedirs(a.out)
    stream = os.path.join(a.out, "scenario.cdelta")
    run([a.cohort, "record-scenario", "testmap", "--base", a.testmap_base, "--frames", str(FRAMES), "--out", stream])
    args = ["--replay", stream, "--base", a.testmap_base, "--width", "96", "--height", "54", "--spp", "1"]
    single = os.path.join(a.out, "single")
    run([a.cohort, "render", "--tracers", "embree", "--out", single] + args)
    flags = mpiexec_flags(a.mpiexec)
    node = [a.cohort, "node", "testmap", "--base", a.testmap_base, "--tracers", "embree", "--row-delay-ms"]
    pattern = (r"mpi:{}: the node idled ([\d.]+) ms a band waiting for a job; jobs ahead: (\d+) sent, (\d+) adopted "
               r"by their frame's band, (\d+) dropped; (\d+) row\(s\) rendered ahead for nothing, (\d+) rendered after")
    for enabled in ("1", "0") if in_flight == "1" else ("1",):
        cluster = os.path.join(a.out, "cluster_" + enabled)
        env = dict(os.environ)
        env["COHORT_MPI_JOBS_AHEAD"] = enabled
        _, output = run([a.mpiexec] + flags + ["-np", "1", a.cohort, "render", "--tracers", "mpi:1,mpi:2", "--out",
                                               cluster, "--frames-in-flight", in_flight] + args +
                        [":"] + flags + ["-np", "1"] + node + ["3"] + [":"] + flags + ["-np", "1"] + node + ["6"],
                        env=env)
        compare_frames(single, cluster)
        if any(o.get("mpi:1") != "rendered" or o.get("mpi:2") != "rendered" for o in tracer_outcomes(cluster)):
            sys.exit("a remote tracer failed a band of the scenario")
        moved = 0
        for rank in (1, 2):
            found = re.search(pattern.format(rank), output)
            if not found:
                sys.exit(f"mpi:{rank}: no jobs-ahead line in the log")
            idle, sent, adopted, dropped, unused, beyond = found.groups()
            moved += int(unused) + int(beyond)
            print(f"jobs ahead {'on' if enabled == '1' else 'off'}, mpi:{rank}: idle {idle} ms a band, {sent} sent, "
                  f"{adopted} adopted, {dropped} dropped, rows unused {unused}, beyond {beyond}")
            # Frame 0 has no band before it; every later frame's job went ahead and was adopted.
            want = FRAMES - 1 if enabled == "1" else 0
            if int(sent) != want or int(adopted) != want or int(dropped) != 0:
                sys.exit(f"mpi:{rank}: {sent} job(s) ahead sent, {adopted} adopted, {dropped} dropped; {want} should "
                         f"have gone ahead and been adopted")
        if enabled == "1" and moved == 0:
            sys.exit("the balancer never moved the rows between frames: the rows beyond a job ahead went untested")
    print("jobs_ahead: ok" if in_flight == "1" else "jobs_ahead_two_in_flight: ok")


def ahead_recovery_check(single, cluster, output):
    with open(os.path.join(cluster, "stats.json")) as f:
        stats = json.load(f)["frames"]
    if len(stats) != FRAMES:
        sys.exit(f"{len(stats)} of {FRAMES} frames delivered")
    if "no answer for rows" not in stats[1]["tracers"][1].get("error", ""):
        sys.exit(f"frame 1: rank 2's band should have timed out: {stats[1]['tracers'][1]}")
    warned = re.findall(r"mpi:1: rows \[\d+, \d+\) of frame (\d+) again \(re-rendering another tracer's rows\)", output)
    if "1" not in warned:
        sys.exit("rank 0 should have said that mpi:1 re-rendered rows of frame 1 after the next frame's commit went ahead")
    for f, frame in enumerate(stats):
        name = f"frame_{f:04d}.png"
        (w, h, ca, pa), (_, _, cb, pb) = read_image(os.path.join(single, name)), read_image(os.path.join(cluster, name))
        rows = {p // w for p in range(w * h) if pa[p * ca:p * ca + 3] != pb[p * cb:p * cb + 3]}
        stalled_band = frame["tracers"][1]
        recovered = set(range(stalled_band["row_begin"], stalled_band["row_end"])) \
            if stalled_band["outcome"] in ("timed_out", "threw") and str(f) in warned else set()
        print(f"{name}: {len(rows)} row(s) differ; rows re-rendered after a commit ahead: {len(recovered)}")
        if not rows <= recovered:
            sys.exit(f"{name}: rows {sorted(rows - recovered)} differ outside the re-rendered ones")
    print("ahead_recovery: ok")


def skip_without_viewer(a):
    """`cohort play` needs a window: skip (ctest's 77) where Xvfb or the viewer build is missing."""
    if not shutil.which("xvfb-run"):
        print("SKIP: xvfb-run is not installed")
        sys.exit(77)
    if a.viewer_built.upper() not in ("ON", "1", "TRUE", "YES"):
        print("SKIP: cohort was built without the viewer (COHORT_WITH_VIEWER=OFF)")
        sys.exit(77)


def play(a):
    skip_without_viewer(a)
    os.makedirs(a.out)
    shot = os.path.join(a.out, "play.png")
    testmap = os.path.join(a.testmap_base, "maps", "testmap.map")
    flags = mpiexec_flags(a.mpiexec)
    _, output = run([a.mpiexec] + flags + ["-np", "1", "xvfb-run", "-a", "-s", "-screen 0 1024x768x24", a.cohort, "play",
                                           testmap, "--tracers", "embree,mpi:1,mpi:2", "--frames", "20", "--width",
                                           "160", "--height", "120", "--scale", "1", "--screenshot", shot] +
                    [":"] + flags + ["-np", "2", a.cohort, "node", testmap, "--tracers", "embree"])
    for rank in (1, 2):
        if not re.search(rf"mpi:{rank}: \d+ band\(s\)", output):
            sys.exit(f"mpi:{rank} rendered no band in cohort play")
    run([sys.executable, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "apps", "image_not_uniform.py"),
         shot])
    print("play: ok")


def bench(a):
    os.makedirs(a.out)
    pack = os.path.join(a.out, "scene.cpk")
    run([a.cohort, "pack", a.map, "--out", pack])
    flags = mpiexec_flags(a.mpiexec)
    report = os.path.join(a.out, "bench.json")
    run([a.mpiexec] + flags + ["-np", "1", a.cohort, "bench", "devices", "--scene", pack, "--width", "64", "--height",
                               "48", "--frames", "6", "--warmup", "2", "--mix", "embree,mpi:1,mpi:2", "--json", report,
                               ":"] + flags + ["-np", "2", a.cohort, "node", pack, "--tracers", "embree"])
    with open(report) as f:
        runs = json.load(f)["runs"]
    mix = [r for r in runs if r["tracers"] == ["embree", "mpi:1", "mpi:2"]]
    alone = [r for r in runs if r["tracers"] == ["mpi:1"]]
    if not mix or not alone:
        sys.exit("the remote tracers' runs are missing from the report")
    links = alone[0]["remote"]
    print("mpi:1 alone:", links)
    # Alone, mpi:1 renders every row: at least the whole frame's pixels (16 bytes each as RGBA32F) come back.
    if len(links) != 1 or links[0]["received_bytes_per_frame"] < 64 * 48 * 16 or links[0]["mean_round_trip_ms"] <= 0:
        sys.exit("mpi:1 alone: bytes per frame or round trip not reported")
    # Where the round trip went: the node rendered within it, and its first piece came before the end.
    link = links[0]
    if not 0 < link["mean_node_render_ms"] <= link["mean_node_ms"] <= link["mean_round_trip_ms"]:
        sys.exit(f"mpi:1 alone: the node's render time should lie within its time and the round trip: {link}")
    if not 0 < link["mean_first_piece_ms"] <= link["mean_round_trip_ms"]:
        sys.exit(f"mpi:1 alone: rank 0's wait for the first piece should lie within the round trip: {link}")
    # Frame by frame (no pipeline, no jobs ahead), the node waits between bands: rank 0's turnaround at least.
    if not link["mean_node_idle_ms"] > 0:
        sys.exit(f"mpi:1 alone: the node's idle time between bands is not reported: {link}")
    if len(mix[0]["remote"]) != 2:
        sys.exit("the mix should report both remote tracers")
    print("bench: ok")


def early_announce(a):
    """Rank 0's own frame work (every frame written) far longer than a node's band: announced after that work
    (COHORT_EARLY_ANNOUNCE=0, the order before), bands come back before the next frame is announced and its
    job cannot go ahead (5-9 of 11 bands a node in five runs here; at least 3 of both nodes' required);
    announced at hand-out (the default), at most 2 of them do. Every frame matches the single-process render
    either way."""
    os.makedirs(a.out)
    frames = 12
    args = [a.map, "--width", "320", "--height", "180", "--spp", "1", "--mode", "albedo", "--frames", str(frames), "--write", "all"]
    single = os.path.join(a.out, "single")
    run([a.cohort, "render", "--tracers", "embree", "--out", single] + args)
    flags = mpiexec_flags(a.mpiexec)
    node = [a.cohort, "node", a.map, "--tracers", "embree"]
    pattern = (r"mpi:{}: a job ahead left ([\d.]+) ms a band after its band's job .*?; (\d+) band\(s\) came back "
               r"before the next frame was announced")
    for early in ("1", "0"):
        cluster = os.path.join(a.out, "cluster_" + early)
        env = dict(os.environ, COHORT_EARLY_ANNOUNCE=early)
        if flags:
            flags_env = flags + ["-x", "COHORT_EARLY_ANNOUNCE"]
        else:
            flags_env = flags
        _, output = run([a.mpiexec] + flags_env + ["-np", "1", a.cohort, "render", "--tracers", "mpi:1,mpi:2", "--out",
                                                   cluster] + args + [":"] + flags + ["-np", "1"] + node + [":"] +
                        flags + ["-np", "1"] + node, env=env)
        compare_frames(single, cluster, frames=frames)
        back_total = 0
        for rank in (1, 2):
            found = re.search(pattern.format(rank), output)
            if not found:
                sys.exit(f"mpi:{rank}: no line on when its jobs ahead left")
            after_ms, back = float(found.group(1)), int(found.group(2))
            back_total += back
            print(f"announced at hand-out {early}, mpi:{rank}: a job ahead left {after_ms} ms after its band's job; "
                  f"{back} of {frames - 1} band(s) back before the next frame was announced")
        # Counted over both nodes: on a loaded machine the balancer may give one node few bands (CI once saw a
        # node with 5 bands, 2 of them back early, with the old order).
        if early == "1" and back_total > 2:
            sys.exit(f"{back_total} band(s) came back before the next frame was announced at hand-out")
        # (At most about half a node's: a band that sent no job ahead is an ordinary one, long enough for the next
        # announcement to come while it renders; the band after adopts that job and is short again.)
        if early == "0" and back_total < frames // 4:
            sys.exit(f"only {back_total} band(s) came back before the announcement after rank 0's frame work: the "
                     f"case no longer shows what the early announcement changes")
    print("early_announce: ok")


def play_early_announce(a):
    """`cohort play` with mpi:1 and mpi:2 alone, both ways of announcing. Play's own frame work (blend,
    tone map, the window's present under Xvfb) comes between a frame's hand-out and the next push; announced
    at hand-out, the next job goes ahead before it (as `cohort render`'s, early_announce above)."""
    skip_without_viewer(a)
    os.makedirs(a.out)
    testmap = os.path.join(a.testmap_base, "maps", "testmap.map")
    flags = mpiexec_flags(a.mpiexec)
    frames = 24
    pattern = (r"mpi:{}: a job ahead left ([\d.]+) ms a band after its band's job .*?; (\d+) band\(s\) came back "
               r"before the next frame was announced")
    left_ms = {}
    for early in ("1", "0"):
        shot = os.path.join(a.out, f"play_{early}.png")
        env = dict(os.environ, COHORT_EARLY_ANNOUNCE=early)
        flags_env = flags + ["-x", "COHORT_EARLY_ANNOUNCE"] if flags else flags
        _, output = run([a.mpiexec] + flags_env + ["-np", "1", "xvfb-run", "-a", "-s", "-screen 0 1024x768x24", a.cohort,
                                                   "play", testmap, "--tracers", "mpi:1,mpi:2", "--frames", str(frames),
                                                   "--width", "320", "--height", "180", "--scale", "1", "--mode", "albedo",
                                                   "--screenshot", shot] +
                        [":"] + flags + ["-np", "2", a.cohort, "node", testmap, "--tracers", "embree"], env=env)
        back_total, left = 0, []
        for rank in (1, 2):
            found = re.search(pattern.format(rank), output)
            if not found:
                sys.exit(f"announced at hand-out {early}: mpi:{rank}: no line on when its jobs ahead left")
            left.append(float(found.group(1)))
            back_total += int(found.group(2))
            print(f"announced at hand-out {early}, mpi:{rank}: a job ahead left {found.group(1)} ms after its band's "
                  f"job; {found.group(2)} band(s) back before the next frame was announced")
        left_ms[early] = max(left)
        if early == "1" and back_total > 2:
            sys.exit(f"{back_total} band(s) came back before the next frame was announced at hand-out")
        run([sys.executable, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "apps",
                                          "image_not_uniform.py"), shot])
    if left_ms["1"] >= left_ms["0"]:
        sys.exit(f"announced at hand-out, the jobs ahead left {left_ms['1']} ms after their band's job, no sooner "
                 f"than when play announced a frame at its push ({left_ms['0']} ms)")
    print("play_early_announce: ok")


def link(a):
    """`cohort bench devices` with mpi:1 alone, every rank's sends through an emulated link of 0.1 Gbit/s and
    20 ms one way (COHORT_MPI_LINK): each band's round trip holds the job's way there and the rows' way
    back (2 x 20 ms) and the rows' bytes at the link's rate, on top of what the node and rank 0 spend."""
    os.makedirs(a.out)
    pack = os.path.join(a.out, "scene.cpk")
    run([a.cohort, "pack", a.map, "--out", pack])
    flags = mpiexec_flags(a.mpiexec)
    # Open MPI's launcher passes only the variables it is told of; MPICH's passes them all.
    if flags:
        flags = flags + ["-x", "COHORT_MPI_LINK"]
    env = dict(os.environ, COHORT_MPI_LINK="0.1gbit,20ms")
    report = os.path.join(a.out, "bench.json")
    _, output = run([a.mpiexec] + flags + ["-np", "1", a.cohort, "bench", "devices", "--scene", pack, "--width", "64",
                                           "--height", "48", "--frames", "4", "--warmup", "1", "--mix", "mpi:1",
                                           "--json", report, ":"] + flags + ["-np", "1", a.cohort, "node", pack,
                                                                             "--tracers", "embree"], env=env)
    if "emulated link of 0.1 Gbit/s and 20 ms one way" not in output:
        sys.exit("no rank said it emulates the link")
    with open(report) as f:
        runs = json.load(f)["runs"]
    alone = [r for r in runs if r["tracers"] == ["mpi:1"]]
    if not alone or len(alone[0]["remote"]) != 1:
        sys.exit("mpi:1's run is missing from the report")
    remote = alone[0]["remote"][0]
    print("mpi:1 over the link:", remote)
    rows_ms = remote["received_bytes_per_frame"] * 8 / 0.1e9 * 1e3
    wire_ms = remote["mean_round_trip_ms"] - remote["mean_node_ms"]
    if wire_ms < 40 + rows_ms * 0.9:
        sys.exit(f"the round trip beyond the node's time is {wire_ms:.1f} ms; the link alone should take "
                 f"{40 + rows_ms:.1f} ms (2 x 20 ms and {remote['received_bytes_per_frame']} bytes at 0.1 Gbit/s)")
    print(f"link: ok ({wire_ms:.1f} ms on the wire, {40 + rows_ms:.1f} ms emulated)")


class JoinLauncher:
    """Separately launched jobs (rank 0 with --node-port, each node with its own mpiexec -np 1) that meet through
    rank 0's port (MPI_Comm_join). Open MPI joins such jobs only through its name server: ompi-server runs for
    the test and every mpirun is pointed at it (--ompi-server file:URI). MPICH needs nothing."""

    def __init__(self, a):
        self.a = a
        self.flags = []
        self.env = dict(os.environ)
        self.server = None
        self.jobs = []
        version = subprocess.run([a.mpiexec, "--version"], capture_output=True, text=True).stdout
        if "Open MPI" in version or "OpenRTE" in version:
            server = os.path.join(os.path.dirname(a.mpiexec), "ompi-server")
            if not os.path.exists(server):
                server = shutil.which("ompi-server")
            if not server:
                print("SKIP: Open MPI without ompi-server: separately launched jobs cannot connect")
                sys.exit(77)
            uri = os.path.join(a.out, "ompi-server.uri")
            self.server = subprocess.Popen([server, "--no-daemonize", "-r", uri])
            for _ in range(100):
                if os.path.exists(uri) and os.path.getsize(uri) > 0:
                    break
                time.sleep(0.1)
            else:
                sys.exit("ompi-server wrote no URI")
            self.flags = ["--ompi-server", "file:" + uri]

    def start(self, name, command):
        log = os.path.join(self.a.out, name + ".log")
        full = [self.a.mpiexec] + self.flags + ["-np", "1"] + command
        print(f"$ {' '.join(full)}  > {log}", flush=True)
        job = subprocess.Popen(full, stdout=open(log, "w"), stderr=subprocess.STDOUT, env=self.env)
        job.log = log
        job.name = name
        self.jobs.append(job)
        return job

    def wait_for_line(self, job, pattern, timeout=90):
        end = time.time() + timeout
        while time.time() < end:
            if re.search(pattern, self.output(job)):
                return
            if job.poll() is not None and not re.search(pattern, self.output(job)):
                break
            time.sleep(0.1)
        self.dump()
        sys.exit(f"{job.name}: no line matching {pattern!r}")

    @staticmethod
    def output(job):
        with open(job.log) as f:
            return f.read()

    def finish(self, job, timeout=240):
        try:
            return job.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            self.dump()
            sys.exit(f"{job.name} did not end within {timeout} s")

    def dump(self):
        for job in self.jobs:
            print(f"---- {job.name} (exit {job.poll()}):\n{self.output(job)[-5000:]}")

    def close(self):
        for job in self.jobs:
            if job.poll() is None:
                job.kill()
        if self.server:
            self.server.terminate()
            self.server.wait()


class JoinedRun:
    """What the join cases share: the single-process render to compare with, and a JoinLauncher for rank 0 with
    a port (tracers embree, mpi:1, mpi:2; waiting up to 120 s for its first nodes) and for nodes on Embree that
    join it. With band_timeout_ms every job gets COHORT_MPI_BAND_TIMEOUT_MS."""

    def __init__(self, a, frames, band_timeout_ms=None):
        os.makedirs(a.out)
        self.frames = frames
        args = ["--width", "192", "--height", "128", "--spp", "2", "--frames", str(frames), "--write", "last",
                "--balancer", "perfect-smooth"]
        self.single, self.cluster = os.path.join(a.out, "single"), os.path.join(a.out, "cluster")
        run([a.cohort, "render", a.map, "--tracers", "embree", "--out", self.single] + args)
        self.port = os.path.join(a.out, "port")
        self.jobs = JoinLauncher(a)
        flags = []
        if band_timeout_ms is not None:
            self.jobs.env["COHORT_MPI_BAND_TIMEOUT_MS"] = str(band_timeout_ms)
            flags = ["-x", "COHORT_MPI_BAND_TIMEOUT_MS"] if self.jobs.flags else []
        self.rank0 = flags + [a.cohort, "render", a.map, "--tracers", "embree,mpi:1,mpi:2", "--node-port", self.port,
                              "--node-wait", "120", "--out", self.cluster] + args
        self.node = [a.cohort, "node", a.map, "--tracers", "embree", "--join", self.port]

    def stats(self):
        with open(os.path.join(self.cluster, "stats.json")) as f:
            return json.load(f)["frames"]

    def last_frame_differs(self):
        return last_frame_differs(self.single, self.cluster, self.frames)


def last_frame_differs(single, cluster, frames):
    name = f"frame_{frames - 1:04d}.png"
    (w, h, ca, pa), (_, _, cb, pb) = read_image(os.path.join(single, name)), read_image(os.path.join(cluster, name))
    differing = sum(1 for p in range(w * h) if pa[p * ca:p * ca + 3] != pb[p * cb:p * cb + 3])
    print(f"{name}: {differing} of {w * h} pixels differ")
    return differing


def killed_joined(a):
    """The killed case with nodes that joined through rank 0's port (each its own mpiexec): rank 2 kills itself
    before its band of frame 1; frame 1 is the one late frame, every frame is delivered, the surviving node
    renders every frame, the last frame matches the single-process render, and rank 0 ends cleanly."""
    frames = 400
    session = JoinedRun(a, frames, band_timeout_ms=1000)
    jobs, node = session.jobs, session.node
    try:
        rank0 = jobs.start("rank0", session.rank0)
        survivor = jobs.start("node1", node + ["--as", "1"])
        dying = jobs.start("node2", node + ["--as", "2", "--die-frame", "1"])
        code, survived, died = jobs.finish(rank0), jobs.finish(survivor), jobs.finish(dying)
        jobs.dump()
    finally:
        jobs.close()
    if code != 0 or survived != 0:
        sys.exit(f"exit statuses: rank 0 {code}, the surviving node {survived}")
    if died == 0 or "killing itself before frame 1" not in JoinLauncher.output(dying):
        sys.exit("rank 2 should have killed itself before frame 1")
    stats = session.stats()
    late = [f["frame"] for f in stats if f["wall_ms"] > 500]
    outcome = [{t["name"]: t["outcome"] for t in f["tracers"]} for f in stats]
    print("late frames:", late)
    if len(stats) != frames:
        sys.exit(f"{len(stats)} of {frames} frames delivered")
    if late != [1]:
        sys.exit(f"the death should make frame 1, and only it, late: {late}")
    if any(o["mpi:2"] == "rendered" for o in outcome[1:]) or any(o["mpi:1"] != "rendered" for o in outcome):
        sys.exit("the killed node cannot have rendered after frame 0, and the surviving one should render every frame")
    away_check(stats, "mpi:2", 1)
    if session.last_frame_differs():
        sys.exit("the last frame differs from the single-process render")
    print("killed (nodes joined on their own launch): ok")


def join(a):
    """Rank 0 alone with a port; two nodes started on their own join mpi:1 and mpi:2 before the first frame
    (--node-wait) and render every frame; the last frame matches the single-process render. Before that, a
    node that runs another version and one that asks for the busy mpi:1 are refused, with the reason logged
    on both sides, a connection that says nothing is dropped after 5 s, and rank 0 goes on. A node whose
    port file never appears fails after its --join-timeout."""
    session = JoinedRun(a, 300)
    jobs, node = session.jobs, session.node
    # A port file that never appears: the node says so after its bounded wait and fails.
    code, output = run([a.mpiexec] + jobs.flags + ["-np", "1", a.cohort, "node", a.map, "--join",
                                                   os.path.join(a.out, "no_such_port"), "--join-timeout", "1"],
                       env=jobs.env, expect_ok=False)
    if code == 0 or "no port in" not in output:
        jobs.close()
        sys.exit("a node whose port file never appears should fail after --join-timeout, saying so")
    try:
        rank0 = jobs.start("rank0", session.rank0)
        # In an order that leaves nothing to chance: rank 0 waits for mpi:2's node (--node-wait) until the end.
        other = jobs.start("other_version", node + ["--as", "0", "--announce-version", "0.0.0-test"])
        if jobs.finish(other, timeout=120) == 0:
            jobs.dump()
            sys.exit("the node of another version should end with an error")
        nodes = [jobs.start("node1", node + ["--as", "1"])]
        jobs.wait_for_line(rank0, r"mpi:1: node joined through the port")
        busy = jobs.start("busy", node + ["--as", "1"])
        if jobs.finish(busy, timeout=120) == 0:
            jobs.dump()
            sys.exit("the node that asked for the busy mpi:1 should end with an error")
        # A connection that says nothing is dropped after a bounded wait, and rank 0 goes on waiting for mpi:2.
        with open(session.port) as f:
            host, tcp_port = f.read().split()
        silent = socket.create_connection((host, int(tcp_port)), timeout=10)
        jobs.wait_for_line(rank0, r"dropped a connection to the node port that did not say it joins within 5 s", 30)
        silent.close()
        nodes.append(jobs.start("node2", node + ["--as", "2"]))
        code = jobs.finish(rank0)
        codes = [jobs.finish(n) for n in nodes]
        output = jobs.output(rank0)
        jobs.dump()
        if code != 0 or any(codes):
            sys.exit(f"exit statuses: rank 0 {code}, nodes {codes}")
        if not re.search(r"refused a node that joined: mpi:1 is busy", output):
            sys.exit("rank 0 did not log why it refused the node that asked for the busy mpi:1")
        if "rank 0 refused this node: mpi:1 is busy" not in jobs.output(busy):
            sys.exit("the node that asked for the busy mpi:1 did not log the refusal")
        if not re.search(r"refused a node that joined: version mismatch: rank 0 runs Cohort \S+ .* runs Cohort "
                         r"0\.0\.0-test", output):
            sys.exit("rank 0 did not name both versions when it refused the other version")
        if "rank 0 refused this node: version mismatch" not in jobs.output(other):
            sys.exit("the node of another version did not log the refusal")
    finally:
        jobs.close()
    if session.last_frame_differs():
        sys.exit("the last frame differs from the single-process render")
    outcomes = tracer_outcomes(session.cluster)
    for f, o in enumerate(outcomes):
        if o.get("mpi:1") != "rendered" or o.get("mpi:2") != "rendered":
            sys.exit(f"frame {f}: a node that joined did not render its band: {o}")
    for found in re.finditer(r"mpi:(\d): the node that joined delivered its first band \(frame (\d+)\) (\d+) ms after it "
                             r"connected", output):
        print(f"mpi:{found.group(1)}: first band (frame {found.group(2)}) {found.group(3)} ms after its connect")
    print("join: ok")


# The fresh node's full resync takes this much longer in the rejoin cases (--resync-delay-ms): a large map's
# upload and BVH build on the test's small one. A first band that waited for it would be a late frame.
RESYNC_DELAY_MS = 300
# How many frames after the slot's return the rejoin cases still call a frame over the lateness bound a failure.
AFTER_RETURN = 100


def rejoin(a):
    """mpi:2's node dies before its band of frame 5 (--die-frame); once it is gone a fresh node joins mpi:2, its
    full resync taking RESYNC_DELAY_MS longer to apply. The dead node's band times out (the one late frame), its
    rows go to the others while the newcomer takes its full resync on the side (away: no rows, nobody waits for
    it) and renders a warm-up band, until it says it is ready; then the slot renders again. No frame after the
    death's is late up to AFTER_RETURN frames after the return (the newcomer's first band included), every frame
    is delivered and the last matches the single-process render. With COHORT_MPI_WARM_UP=0 the newcomer's first band waits for its resync and is a
    second late frame: this case then fails."""
    frames = 1500
    die = 5
    session = JoinedRun(a, frames, band_timeout_ms=1000)
    jobs, node = session.jobs, session.node
    try:
        rank0, first, died_at = start_with_mpi2_dying(session, die)
        fresh = jobs.start("node2_again", node + ["--as", "2", "--resync-delay-ms", str(RESYNC_DELAY_MS)])
        output = finish_rejoined_run(jobs, rank0, (first, fresh))
        fresh_output = jobs.output(fresh)
    finally:
        jobs.close()
    stats = session.stats()
    back = rejoined_check(session, stats, output, die, frames)
    found = re.findall(r"mpi:2: the node that joined delivered its first band \(frame (\d+)\) (\d+) ms after it "
                       r"connected", output)
    if len(found) != 2 or int(found[-1][0]) != back:
        sys.exit(f"rank 0 should have logged the first band of both nodes that joined mpi:2, the second's in frame {back}")
    ready_check(output, fresh_output)
    print(f"mpi:2's new node: first band (frame {found[-1][0]}) {found[-1][1]} ms after its connect; "
          f"{(time.time() - died_at):.1f} s from the death to the end of the run")
    print("rejoin: ok")


def start_with_mpi2_dying(session, die):
    """Rank 0 and two nodes that join it, the one of mpi:2 killing itself before frame `die`. Returns rank 0's and
    mpi:1's jobs and when mpi:2's died, once its band has timed out: the slot is free for a newcomer only then
    (until then mpi:2 is busy, its node answers)."""
    jobs, node = session.jobs, session.node
    rank0 = jobs.start("rank0", session.rank0)
    first = jobs.start("node1", node + ["--as", "1"])
    dying = jobs.start("node2", node + ["--as", "2", "--die-frame", str(die)])
    jobs.finish(dying, timeout=120)
    died_at = time.time()
    if f"killing itself before frame {die}" not in jobs.output(dying):
        jobs.dump()
        sys.exit(f"node2 ended without dying at frame {die}")
    jobs.wait_for_line(rank0, r"mpi:2: no answer for rows")
    return rank0, first, died_at


def finish_rejoined_run(jobs, rank0, nodes, let_go=()):
    """Waits for rank 0 and the nodes, then for those it let go (whatever their status), prints every log, and
    ends the case unless rank 0 and every node exited with 0. Returns rank 0's output."""
    code = jobs.finish(rank0)
    codes = [jobs.finish(n) for n in nodes]
    for job in let_go:
        jobs.finish(job, timeout=60)
    output = jobs.output(rank0)
    jobs.dump()
    if code != 0 or any(codes):
        sys.exit(f"exit statuses: rank 0 {code}, nodes {codes}")
    return output


def rejoined_check(session, stats, output, die, frames, lost_band_ms=500, late_while_away=True):
    """What the rejoin cases check of the frames: all delivered; mpi:2's band of frame `die` timed out; the slot
    away (not asked, nothing re-rendered) until its new node renders, and from then on every frame with rows;
    no frame late after the death's up to AFTER_RETURN frames after the return (the newcomer's first band
    included); the last frame matches the single-process render. The death's frame waits for the band timeout:
    over lost_band_ms, and only it. Without late_while_away the frames over 3x the median are looked for only
    from the return on (the slot's time away holds three node starts in rejoin_unready, each loading its map on
    the VM's 2 cores beside rank 0; the rejoin case checks that time). Returns the frame the slot rendered
    again."""
    if len(stats) != frames:
        sys.exit(f"{len(stats)} of {frames} frames delivered")
    outcome = [{t["name"]: t for t in f["tracers"]} for f in stats]
    slot = [o["mpi:2"]["outcome"] for o in outcome]
    gone = [f for f, s in enumerate(slot) if s != "rendered"]
    late = [f["frame"] for f in stats if f["wall_ms"] > lost_band_ms]
    back = next((f for f in range(die + 1, frames) if slot[f] == "rendered"), None)
    print(f"mpi:2 away in frames {gone[0] if gone else '-'}..{gone[-1] if gone else '-'} ({len(gone)} frames), back from "
          f"frame {back}; late frames (over {lost_band_ms} ms): {late}")
    if back is None:
        sys.exit("the fresh node never rendered mpi:2's rows (did it join before the run ended?)")
    if slot[die] == "rendered" or "no answer for rows" not in outcome[die]["mpi:2"].get("error", ""):
        sys.exit(f"frame {die}: the dead node's band should have timed out: {outcome[die]['mpi:2']}")
    if any(s != "rendered" for s in slot[back:]):
        sys.exit("once back, mpi:2 should render every frame")
    last = outcome[-10:]
    if any(o["mpi:2"]["row_end"] <= o["mpi:2"]["row_begin"] for o in last):
        sys.exit("mpi:2 should have rows in the last frames")
    if late != [die]:
        sys.exit(f"the death should make frame {die}, and only it, late: {late}")
    away_check(stats, "mpi:2", die, back, check_late=late_while_away)
    times = [f["wall_ms"] for f in stats]
    around = times[max(back - 3, 0):back + 4]
    print(f"frame times around the rejoin (frames {max(back - 3, 0)}..{back + 3}): "
          f"{', '.join(f'{t:.1f}' for t in around)} ms; median of the run {sorted(times)[len(times) // 2]:.1f} ms")
    # The newcomer's first band is an ordinary one: from the death to AFTER_RETURN frames after the return, only
    # the death's frame may be late (issue 19: "A killed node costs at most one late frame"). Not to the end of
    # the run: on the shared 2-core VM the scheduler alone stretches a frame past 25 ms now and then (seen
    # 900 frames after the return under MPICH), which says nothing of the newcomer.
    late = late_after_fault(stats, die if late_while_away else back, min(back + AFTER_RETURN, len(stats)))
    if len(late) > 1 or (late and late[0] != die):
        sys.exit(f"after the death's frame {die}, no frame should be late, the newcomer's first band (frame {back}) "
                 f"included: {late}")
    if session.last_frame_differs():
        sys.exit("the last frame differs from the single-process render")
    return back


def ready_check(output, node_output):
    """The newcomer applied its delayed full resync and a warm-up band on the side and said so; rank 0 logged its
    ready with those times before its first band."""
    ready = re.search(r"mpi:2: the node that joined is ready (\d+) ms after it connected \(full resync applied in "
                      r"([\d.]+) ms, warm-up band ([\d.]+) ms\)", output)
    if not ready:
        sys.exit("rank 0 did not log the newcomer's ready")
    if float(ready.group(2)) < RESYNC_DELAY_MS:
        sys.exit(f"the newcomer's full resync took {ready.group(2)} ms, less than its {RESYNC_DELAY_MS} ms delay")
    if float(ready.group(3)) <= 0.0:
        sys.exit("the newcomer rendered no warm-up band (the dead node's last band)")
    if not re.search(r"node \d+: ready \(full resync applied in [\d.]+ ms, warm-up band [\d.]+ ms\)", node_output):
        sys.exit("the newcomer did not log its ready")
    if output.index(ready.group(0)) > output.rindex("mpi:2: the node that joined delivered its first band"):
        sys.exit("the newcomer delivered its first band before it was ready")
    print(f"mpi:2's new node: ready {ready.group(1)} ms after its connect (full resync {ready.group(2)} ms, warm-up "
          f"band {ready.group(3)} ms)")


def rejoin_unready(a):
    """As rejoin, with band timeout 300 ms, but the first node that joins mpi:2 after the death takes 6 s to
    apply its full resync: it does not say it is ready within ten times the band timeout, so rank 0 lets it go
    (logged, with the reason) and frees the slot, the frames going on without it meanwhile (none re-rendered); a
    second newcomer then joins and renders. Its first band is not late (up to AFTER_RETURN frames after the
    return), and the last frame matches the single-process render."""
    frames = 4000
    die = 5
    session = JoinedRun(a, frames, band_timeout_ms=300)
    jobs, node = session.jobs, session.node
    try:
        rank0, first, _ = start_with_mpi2_dying(session, die)
        # Let go, it hears nothing more from rank 0 and leaves after its --idle-timeout.
        slow = jobs.start("node2_slow", node + ["--as", "2", "--resync-delay-ms", "6000", "--idle-timeout", "8"])
        jobs.wait_for_line(rank0, r"mpi:2: the node that joined did not say it is ready within 3000 ms", 60)
        fresh = jobs.start("node2_again", node + ["--as", "2", "--resync-delay-ms", str(RESYNC_DELAY_MS)])
        output = finish_rejoined_run(jobs, rank0, (first, fresh), let_go=(slow,))
        fresh_output = jobs.output(fresh)
    finally:
        jobs.close()
    stats = session.stats()
    rejoined_check(session, stats, output, die, frames, lost_band_ms=150, late_while_away=False)
    if len(re.findall(r"mpi:2: node joined through the port", output)) != 3:
        sys.exit("three nodes should have joined mpi:2: the first, the slow one and the last")
    if not re.search(r"mpi:2: 3 node\(s\) joined through the port; the last delivered its first band \d+ ms after its "
                     r"connect \(ready after \d+ ms: .*\); 1 let go for not saying ready in time", output):
        sys.exit("rank 0's summary of mpi:2 should count three nodes joined and one let go")
    ready_check(output, fresh_output)
    print("rejoin_unready: ok")


def play_join(a):
    """`cohort play` as rank 0 with a port (--node-port, --node-wait) under a virtual display: a node started on
    its own joins mpi:1 before the first frame, renders bands in play, and both end with status 0; the
    screenshot is an image, not a uniform colour."""
    skip_without_viewer(a)
    os.makedirs(a.out)
    shot, port = os.path.join(a.out, "play.png"), os.path.join(a.out, "port")
    testmap = os.path.join(a.testmap_base, "maps", "testmap.map")
    jobs = JoinLauncher(a)
    try:
        rank0 = jobs.start("rank0", ["xvfb-run", "-a", "-s", "-screen 0 1024x768x24", a.cohort, "play", testmap,
                                     "--tracers", "embree,mpi:1", "--node-port", port, "--node-wait", "120",
                                     "--frames", "20", "--width", "160", "--height", "120", "--scale", "1",
                                     "--screenshot", shot])
        node = jobs.start("node1", [a.cohort, "node", testmap, "--tracers", "embree", "--join", port, "--as", "1"])
        code, node_code = jobs.finish(rank0), jobs.finish(node)
        jobs.dump()
    finally:
        jobs.close()
    if code != 0 or node_code != 0:
        sys.exit(f"exit statuses: rank 0 {code}, the node {node_code}")
    if "rank 0 welcomed this node as mpi:1" not in JoinLauncher.output(node):
        sys.exit("the node was not welcomed as mpi:1")
    if not re.search(r"mpi:1: [1-9]\d* band\(s\)", JoinLauncher.output(rank0)):
        sys.exit("mpi:1 rendered no band in cohort play")
    run([sys.executable, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "apps", "image_not_uniform.py"),
         shot])
    print("play_join: ok")


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("case", choices=["match", "mixed", "stall", "killed", "version", "load_error", "bench", "protocol", "replay",
                                           "play", "link", "bad_piece", "ahead", "ahead_recovery", "jobs_ahead",
                                           "jobs_ahead_two_in_flight",
                                           "early_announce", "match_rgb9e5", "play_early_announce", "join", "rejoin",
                                           "play_join", "rejoin_unready"])
    parser.add_argument("--mpiexec", required=True)
    parser.add_argument("--cohort", required=True)
    parser.add_argument("--map", required=True)
    parser.add_argument("--broken-map")
    parser.add_argument("--protocol-check")
    parser.add_argument("--testmap-base")
    parser.add_argument("--viewer-built", default="OFF")
    parser.add_argument("--out", required=True)
    a = parser.parse_args()

    shutil.rmtree(a.out, ignore_errors=True)
    if a.case in ("stall", "killed"):
        stall(a, killed=a.case == "killed")
        return
    if a.case == "bench":
        bench(a)
        return
    if a.case == "join":
        join(a)
        return
    if a.case == "rejoin":
        rejoin(a)
        return
    if a.case == "play_join":
        play_join(a)
        return
    if a.case == "rejoin_unready":
        rejoin_unready(a)
        return
    if a.case == "link":
        link(a)
        return
    if a.case == "replay":
        replay(a)
        return
    if a.case in ("ahead", "ahead_recovery"):
        ahead(a, stalled=a.case == "ahead_recovery")
        return
    if a.case == "play":
        play(a)
        return
    if a.case in ("jobs_ahead", "jobs_ahead_two_in_flight"):
        jobs_ahead(a, in_flight="2" if a.case == "jobs_ahead_two_in_flight" else "1")
        return
    if a.case == "early_announce":
        early_announce(a)
        return
    if a.case == "play_early_announce":
        play_early_announce(a)
        return
    if a.case == "bad_piece":
        bad_piece(a)
        return
    if a.case == "protocol":
        _, output = run([a.mpiexec] + mpiexec_flags(a.mpiexec) + ["-np", "2", a.protocol_check])
        if "FAILED" in output or output.count("ok: ") < 8:
            sys.exit("protocol check failed")
        print("protocol: ok")
        return
    single, cluster = os.path.join(a.out, "single"), os.path.join(a.out, "cluster")
    render_args = RENDER_ARGS + (["--band-format", "rgb9e5"] if a.case == "match_rgb9e5" else [])
    run([a.cohort, "render", a.map, "--tracers", "embree", "--out", single] + render_args)

    env = dict(os.environ)
    node1 = [a.cohort, "node", a.map, "--tracers", "embree"]
    node2 = [a.cohort, "node", a.map, "--tracers", "embree"]
    if a.case == "mixed":
        node1 = [a.cohort, "node", a.map, "--tracers", "embree,opencl:0"]
        node2 = [a.cohort, "node", a.map, "--tracers", "opencl:0"]
    if a.case == "version":
        node1 += ["--announce-version", "0.0.0-test"]
    if a.case == "load_error":
        node1 = [a.cohort, "node", a.broken_map, "--tracers", "embree"]
    flags = mpiexec_flags(a.mpiexec)
    command = ([a.mpiexec] + flags + ["-np", "1", a.cohort, "render", a.map, "--tracers", "embree,mpi:1,mpi:2",
                                      "--out", cluster] + render_args +
               [":"] + flags + ["-np", "1"] + node1 + [":"] + flags + ["-np", "1"] + node2)
    code, output = run(command, env=env, expect_ok=a.case in ("match", "mixed", "match_rgb9e5"))
    compare_frames(single, cluster, tolerant=a.case == "mixed")
    outcomes = tracer_outcomes(cluster)
    print("outcomes per frame:", outcomes)

    if a.case in ("match", "mixed", "match_rgb9e5"):
        for f, o in enumerate(outcomes):
            if o.get("mpi:1") != "rendered" or o.get("mpi:2") != "rendered":
                sys.exit(f"frame {f}: a remote tracer did not render its band: {o}")
    if a.case == "match_rgb9e5":
        for rank in (1, 2):
            if not re.search(rf"node {rank}: shutdown .* KiB of colour rows a band as rgb9e5 \(4 bytes a pixel\)", output):
                sys.exit(f"node {rank} did not log its rows as RGB9E5, 4 bytes a pixel")
    elif a.case == "version":
        if not re.search(r"rank 0 runs Cohort \S+ .*rank 1 .* runs Cohort 0\.0\.0-test", output):
            sys.exit("rank 0 did not name both versions")
        if "refused this node" not in output:
            sys.exit("rank 1 did not report the refusal")
        if any("mpi:1" in o for o in outcomes):
            sys.exit("the refused node still took part")
    elif a.case == "load_error":
        if not re.search(r"mpi:1: the node could not start \(its scene or its tracers\) and leaves: .*:\d+", output):
            sys.exit("rank 0 did not log the node's file:line reason")
        if any("mpi:1" in o for o in outcomes):
            sys.exit("the node that could not load its map still took part")
    print(f"{a.case}: ok")


if __name__ == "__main__":
    main()
