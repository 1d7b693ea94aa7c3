#!/usr/bin/env python3
"""Generate Cohort's Doom 3-format test map (deterministic: same bytes on every run).

Writes maps/, materials/, textures/, lights/ and README.md under --out (default assets/testmap).
"""
import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from testmap.checks import CheckError  # noqa: E402
from testmap.generate import build  # noqa: E402


def main():
    repo = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", default=os.path.join(repo, "assets", "testmap"),
                        help="output folder laid out like a Doom 3 base folder (default: assets/testmap)")
    parser.add_argument("--check-only", action="store_true", help="build and self-check, write nothing")
    args = parser.parse_args()

    try:
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

    print("testmap: %d areas, %d portals, %d nodes" % (stats["areas"], stats["portals"], stats["nodes"]))
    print("  triangles: %d in areas, %d in %d inline models" % (stats["area_triangles"], stats["model_triangles"],
                                                                 len(stats["inline_models"])))
    print("  watertight: %d shell edges closed, %d portal rim edges" % (stats["shell_edges"],
                                                                      stats["portal_rim_edges"]))
    print("  materials: %d, images: %d" % (len(stats["materials"]), stats["images"]))
    print("  lights: %d point, %d projected, %d parallel" % (stats["lights_point"], stats["lights_projected"],
                                                          stats["lights_parallel"]))
    print("  entities: %d, files: %d, %.1f KiB%s" % (len(stats["entities"]), len(files), stats["bytes"] / 1024.0,
                                                    "" if args.check_only else " -> " + args.out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
