#!/usr/bin/env python3
"""Usage: closer_to.py REFERENCE CANDIDATE MAX_ERROR [OTHER ...]
Mean absolute difference per channel (0-255) of 8-bit PNG or PPM images of one size against REFERENCE:
passes when CANDIDATE's is at most MAX_ERROR and below every OTHER's. Prints each. Standard library only
(the readers of image_not_uniform.py)."""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from compare_images import read_image  # noqa: E402


def mean_error(reference, path):
    (wr, hr, cr, r), (w, h, c, a) = reference, read_image(path)
    if (w, h) != (wr, hr):
        sys.exit(f"{path}: {w}x{h}, the reference is {wr}x{hr}")
    total = sum(abs(r[p * cr + k] - a[p * c + k]) for p in range(w * h) for k in range(3))
    return total / float(3 * w * h)


def main():
    if len(sys.argv) < 4:
        sys.exit(__doc__)
    reference = read_image(sys.argv[1])
    limit = float(sys.argv[3])
    candidate = mean_error(reference, sys.argv[2])
    print(f"{sys.argv[2]}: mean error {candidate:.3f} (at most {limit})")
    ok = candidate <= limit
    for other in sys.argv[4:]:
        e = mean_error(reference, other)
        print(f"{other}: mean error {e:.3f}")
        ok = ok and candidate < e
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
