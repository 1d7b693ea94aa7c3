#!/usr/bin/env python3
"""Usage: compare_images.py A B (same|differ)
Compares two 8-bit PNG or binary PPM images of one size: `same` passes when every byte matches,
`differ` when at least 0.1% of the pixels differ. Prints the share of differing pixels. Standard
library only (the readers of image_not_uniform.py)."""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from image_not_uniform import read_png, read_ppm  # noqa: E402


def read_image(path):
    with open(path, "rb") as f:
        data = f.read()
    return (read_png if data[:4] == b"\x89PNG" else read_ppm)(data)


def main():
    if len(sys.argv) != 4 or sys.argv[3] not in ("same", "differ"):
        sys.exit(__doc__)
    (wa, ha, ca, a), (wb, hb, cb, b) = read_image(sys.argv[1]), read_image(sys.argv[2])
    if (wa, ha) != (wb, hb):
        sys.exit(f"sizes differ: {wa}x{ha} against {wb}x{hb}")
    differing = sum(1 for p in range(wa * ha) if a[p * ca:p * ca + 3] != b[p * cb:p * cb + 3])
    share = differing / float(wa * ha)
    print(f"{differing} of {wa * ha} pixels differ ({100.0 * share:.2f}%)")
    ok = differing == 0 if sys.argv[3] == "same" else share >= 0.001
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
