#!/usr/bin/env python3
"""Generate Cohort's Doom 3-format test maps (deterministic: same bytes on every run).

Default: the small bundled test map; writes maps/, materials/, textures/, lights/ and README.md under
--out (default assets/testmap).

--large: the large map for scaling tests (not committed: generate it into a build folder). A lattice
of rooms on two levels joined by corridors and stairwells, skylight shafts, >= 40 areas, >= 300k world
triangles (bezier cove patches, arch ribs, round pillars, pipe runs, stairs, handrails, trims),
>= 256 lights of every kind (point, textured with falloff image, noshadows, nospecular, rotated,
projected with and without start/end, parallel) and >= 100 func_static props instancing four .proc
models. The same --seed and --size give the same bytes. Writes maps/largemap.{map,proc} and the
test map's materials and textures under --out (default build/assets/largemap), e.g.

    python3 tools/gen_testmap.py --large --out build/default/assets/largemap
    cohort info largemap --base build/default/assets/largemap
    cohort pack build/default/assets/largemap/maps/largemap.map --out largemap.cpk
"""
import hashlib
import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from testmap.checks import CheckError  # noqa: E402
from testmap.generate import build  # noqa: E402
from testmap.largemap import build_large  # noqa: E402


def main():
    repo = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", default=None,
                        help="output folder laid out like a Doom 3 base folder (default: assets/testmap, "
                             "with --large build/assets/largemap)")
    parser.add_argument("--check-only", action="store_true", help="build and self-check, write nothing")
    parser.add_argument("--large", action="store_true",
                        help="generate the large map (maps/largemap.*) instead of the small test map")
    parser.add_argument("--seed", type=int, default=1, help="--large: layout seed (default 1)")
    parser.add_argument("--size", default="6x5",
                        help="--large: rooms as COLSxROWS (default 6x5; the targets need at least 6x5)")
    parser.add_argument("--digest", action="store_true", help="print a SHA-256 over every file's path and bytes")
    args = parser.parse_args()
    if args.out is None:
        args.out = os.path.join(repo, "build", "assets", "largemap") if args.large else \
            os.path.join(repo, "assets", "testmap")

    try:
        if args.large:
            cols, rows = (int(v) for v in args.size.lower().split("x"))
            default_size = (cols, rows) == (6, 5)
            files, stats = build_large(args.seed, cols, rows, check_targets=default_size)
        else:
            files, stats = build()
    except CheckError as error:
        print("gen_testmap: self-check failed: %s" % error, file=sys.stderr)
        return 1

    if not args.check_only:
        for path, data in sorted(files.items()):
            target = os.path.join(args.out, path)
            os.makedirs(os.path.dirname(target), exist_ok=True)
            with open(target, "wb") as handle:
                handle.write(data)

    if args.digest:
        digest = hashlib.sha256()
        for path, data in sorted(files.items()):
            digest.update(path.encode("utf-8") + b"\0" + str(len(data)).encode("ascii") + b"\0" + data)
        print("digest: sha256 %s" % digest.hexdigest())
    name = "largemap" if args.large else "testmap"
    print("%s: %d areas, %d portals, %d nodes" % (name, stats["areas"], stats["portals"], stats["nodes"]))
    if args.large:
        print("  layout: seed %d, %dx%d rooms, %d corridors, %d stairwells, %d skylight shafts, %d patches"
              % (stats["seed"], stats["size"][0], stats["size"][1], stats["corridors"], stats["stairwells"],
                 stats["shafts"], stats["patches"]))
    print("  triangles: %d in areas, %d in %d inline models" % (stats["area_triangles"], stats["model_triangles"],
                                                                 len(stats["inline_models"])))
    print("  watertight: %d shell edges closed, %d portal rim edges" % (stats["shell_edges"],
                                                                      stats["portal_rim_edges"]))
    print("  materials: %d, images: %d" % (len(stats["materials"]), stats["images"]))
    print("  lights: %d point, %d projected, %d parallel" % (stats["lights_point"], stats["lights_projected"],
                                                          stats["lights_parallel"]))
    if args.large:
        print("  props: %d func_static instancing %d models" % (stats["props"], len(stats["inline_models"])))
    print("  entities: %d, files: %d, %.1f KiB%s" % (len(stats["entities"]), len(files), stats["bytes"] / 1024.0,
                                                    "" if args.check_only else " -> " + args.out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
