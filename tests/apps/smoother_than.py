#!/usr/bin/env python3
"""Usage: smoother_than.py FILTERED UNFILTERED [RATIO]
Checks that FILTERED (PNG or binary PPM, as image_not_uniform.py reads them) has less pixel-to-pixel
variation than UNFILTERED: the mean absolute luminance difference between horizontal neighbours must be
below RATIO (default 0.9) times the other's. Standard library only."""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from image_not_uniform import read_png, read_ppm  # noqa: E402


def neighbour_difference(path):
    with open(path, "rb") as f:
        data = f.read()
    width, height, channels, pixels = (read_png if data[:4] == b"\x89PNG" else read_ppm)(data)
    colour = min(channels, 3)
    lum = [sum(pixels[i:i + colour]) / colour for i in range(0, len(pixels), channels)]
    total = sum(abs(lum[y * width + x + 1] - lum[y * width + x]) for y in range(height) for x in range(width - 1))
    return total / (height * (width - 1))


def main():
    filtered, unfiltered = neighbour_difference(sys.argv[1]), neighbour_difference(sys.argv[2])
    ratio = float(sys.argv[3]) if len(sys.argv) > 3 else 0.9
    print(f"neighbour difference: {filtered:.2f} filtered, {unfiltered:.2f} unfiltered")
    if not filtered < ratio * unfiltered:
        sys.exit(f"FAIL: the filtered image is not smoother (needs < {ratio} x)")


if __name__ == "__main__":
    main()
