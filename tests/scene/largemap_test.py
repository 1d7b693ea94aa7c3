#!/usr/bin/env python3
"""Checks for the large generated map (tools/gen_testmap.py --large), driven by tests/scene/largemap.cmake.

  generate      --repo R --out D            clear D and generate the map into it (the ctest fixture)
  deterministic --repo R --out D            generate again in memory, in a fresh process with another
                                            hash seed, and compare a digest with the files in D;
                                            then --seed 2 --size 3x3 must pass the self-checks too
  info          --cohort EXE --out D        `cohort info` on D: no warnings, the generator's counts, and
                                            the targets (>= 40 areas, >= 300k world triangles, >= 256
                                            lights of all three types, >= 100 func_static props)
  frames        --cohort EXE --out D        `cohort render` of D on Embree along a fast spin, every frame
                                            written as HDR: every pixel of every frame is finite
"""
import argparse
import hashlib
import os
import re
import shutil
import struct
import subprocess
import sys
import tempfile
import time

from tree_files import read_tree


def generator(repo):
    return [sys.executable, os.path.join(repo, "tools", "gen_testmap.py"), "--large"]


def tree_digest(root):
    """The same digest as gen_testmap.py --digest: sorted relative paths, their lengths and bytes."""
    files = read_tree(root)
    digest = hashlib.sha256()
    for path, data in sorted(files.items()):
        digest.update(path.encode("utf-8") + b"\0" + str(len(data)).encode("ascii") + b"\0" + data)
    return digest.hexdigest(), len(files), sum(len(d) for d in files.values())


def generate(args):
    if os.path.isdir(args.out):
        shutil.rmtree(args.out)
    start = time.time()
    result = subprocess.run(generator(args.repo) + ["--out", args.out], capture_output=True, text=True)
    print(result.stdout + result.stderr)
    if result.returncode != 0:
        print("FAIL: generator exited with %d" % result.returncode)
        return 1
    print("generated in %.1f s" % (time.time() - start))
    return 0


def deterministic(args):
    on_disk, count, size = tree_digest(args.out)
    env = dict(os.environ, PYTHONHASHSEED="12345")
    result = subprocess.run(generator(args.repo) + ["--check-only", "--digest"], capture_output=True, text=True,
                            env=env)
    print(result.stdout + result.stderr)
    if result.returncode != 0:
        print("FAIL: generator exited with %d" % result.returncode)
        return 1
    match = re.search(r"digest: sha256 ([0-9a-f]{64})", result.stdout)
    if not match:
        print("FAIL: no digest in the generator's output")
        return 1
    print("on disk: %d files, %d bytes, sha256 %s" % (count, size, on_disk))
    if match.group(1) != on_disk:
        print("FAIL: a second generation differs from the files written by the first")
        return 1
    # Another seed on a smaller lattice must pass the same self-checks and differ.
    result = subprocess.run(generator(args.repo) + ["--check-only", "--digest", "--seed", "2", "--size", "3x3"],
                            capture_output=True, text=True)
    print(result.stdout + result.stderr)
    if result.returncode != 0:
        print("FAIL: --seed 2 --size 3x3 exited with %d" % result.returncode)
        return 1
    if on_disk in result.stdout:
        print("FAIL: another seed and size gave the same bytes")
        return 1
    return 0


def info(args):
    start = time.time()
    result = subprocess.run([args.cohort, "info", "largemap", "--base", args.out], capture_output=True, text=True)
    elapsed = time.time() - start
    text = result.stdout + result.stderr
    print(text)
    print("cohort info took %.2f s" % elapsed)
    failures = []
    if result.returncode != 0:
        failures.append("cohort info exited with %d" % result.returncode)

    def number(pattern, source=text, what=None):
        match = re.search(pattern, source, re.M)
        if not match:
            failures.append("no match for %r (%s)" % (pattern, what or "cohort info"))
            return [-1] * max(1, len(re.findall(r"\(\\d\+\)", pattern)))
        return [int(g) for g in match.groups()]

    with open(os.path.join(args.out, "README.md")) as handle:
        readme = handle.read()
    want_areas, = number(r"^- areas: (\d+)", readme, "README")
    want_tris, = number(r"^- world triangles: (\d+)", readme, "README")
    want_lights, want_point, want_proj, want_par = number(
        r"^- lights: (\d+) \((\d+) point, (\d+) projected, (\d+) parallel\)", readme, "README")
    want_props, = number(r"^- props: (\d+) func_static", readme, "README")

    areas, = number(r"^areas\s+(\d+)")
    tris, = number(r"^triangles\s+(\d+) world")
    lights, point, proj, par = number(r"^lights\s+(\d+): (\d+) point, (\d+) projected, (\d+) parallel")
    props, = number(r"^\s+func_static (\d+)")
    warnings, = number(r"^warnings\s+(\d+)")
    missing, = number(r"\((\d+) missing")

    for name, got, want in (("areas", areas, want_areas), ("world triangles", tris, want_tris),
                            ("lights", lights, want_lights), ("point lights", point, want_point),
                            ("projected lights", proj, want_proj), ("parallel lights", par, want_par),
                            ("func_static props", props, want_props)):
        if got != want:
            failures.append("%s: cohort info says %d, the generator wrote %d" % (name, got, want))
    for name, got, minimum in (("areas", areas, 40), ("world triangles", tris, 300000), ("lights", lights, 256),
                               ("point lights", point, 1), ("projected lights", proj, 1),
                               ("parallel lights", par, 1), ("func_static props", props, 100)):
        if got < minimum:
            failures.append("%s: %d, the target is at least %d" % (name, got, minimum))
    if warnings != 0:
        failures.append("%d warnings" % warnings)
    if missing != 0:
        failures.append("%d missing materials" % missing)
    for failure in failures:
        print("FAIL: " + failure)
    return 1 if failures else 0


def nonfinite_in_pfm(path):
    """Non-finite values in a PFM (the HDR `cohort render` writes without OpenImageIO)."""
    with open(path, "rb") as f:
        kind = f.readline().strip()
        width, height = (int(v) for v in f.readline().split())
        scale = float(f.readline())
        channels = 3 if kind == b"PF" else 1
        count = width * height * channels
        values = struct.unpack(("<" if scale < 0 else ">") + "%df" % count, f.read(4 * count))
    return sum(1 for v in values if v != v or v in (float("inf"), float("-inf")))


def nonfinite_in_exr(path):
    """Non-finite values in an EXR, counted by oiiotool --stats (NanCount and InfCount per channel)."""
    oiiotool = shutil.which("oiiotool")
    if not oiiotool:
        raise RuntimeError("oiiotool is needed to read %s" % path)
    text = subprocess.run([oiiotool, "--stats", path], capture_output=True, text=True, check=True).stdout
    counts = re.findall(r"(?:NanCount|InfCount):((?:\s+\d+)+)", text)
    if len(counts) != 2:
        raise RuntimeError("oiiotool --stats gave no NaN/Inf counts for %s:\n%s" % (path, text))
    return sum(int(v) for line in counts for v in line.split())


def frames(args):
    out = tempfile.mkdtemp(prefix="largemap_frames_")
    try:
        cmd = [args.cohort, "render", "largemap", "--base", args.out, "--tracers", "embree", "--width", "96",
               "--height", "54", "--spp", "1", "--bounces", "1", "--frames", "4", "--camera-path", "spin-fast",
               "--no-convergence", "--band-format", "rgba32f", "--out", out]
        result = subprocess.run(cmd, capture_output=True, text=True)
        if result.returncode != 0:
            print(result.stdout + result.stderr)
            print("FAIL: cohort render exited with %d" % result.returncode)
            return 1
        images = sorted(f for f in os.listdir(out) if f.endswith((".exr", ".pfm")))
        if len(images) != 4:
            print("FAIL: expected 4 HDR frames, found %s" % images)
            return 1
        bad = 0
        for name in images:
            path = os.path.join(out, name)
            n = nonfinite_in_exr(path) if name.endswith(".exr") else nonfinite_in_pfm(path)
            print("%s: %d non-finite values" % (name, n))
            bad += n
        if bad:
            print("FAIL: %d non-finite values in the large map's frames" % bad)
            return 1
        print("PASS: every pixel of %d frames is finite" % len(images))
        return 0
    finally:
        shutil.rmtree(out, ignore_errors=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("mode", choices=("generate", "deterministic", "info", "frames"))
    parser.add_argument("--repo", default=os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
    parser.add_argument("--out", required=True, help="the large map's base folder")
    parser.add_argument("--cohort", help="the cohort executable (info, frames)")
    args = parser.parse_args()
    return {"generate": generate, "deterministic": deterministic, "info": info, "frames": frames}[args.mode](args)


if __name__ == "__main__":
    sys.exit(main())
