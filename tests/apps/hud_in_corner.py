#!/usr/bin/env python3
"""Usage: hud_in_corner.py WINDOW_SHOT FRAME_SHOT HUD_ROWS
`cohort play` draws its HUD layer only as large as the HUD, at the window's top-left corner. With the
frame at the window's size (scale 1), the window as drawn must match the frame below the HUD's rows
(nothing blended there) and be darker than the frame in the top-left corner (the margin of the HUD's translucent box).
Standard library only."""
import sys

from image_not_uniform import read_png, read_ppm


def load(path):
    with open(path, "rb") as f:
        data = f.read()
    width, height, channels, pixels = (read_png if data[:4] == b"\x89PNG" else read_ppm)(data)
    lum = [sum(pixels[i:i + 3]) / 3 for i in range(0, len(pixels), channels)]
    return width, height, lum


def mean(lum, width, x0, y0, x1, y1):
    values = [lum[y * width + x] for y in range(y0, y1) for x in range(x0, x1)]
    return sum(values) / len(values)


def main():
    (ww, wh, window), (fw, fh, frame) = load(sys.argv[1]), load(sys.argv[2])
    hud_rows = int(sys.argv[3])
    if (ww, wh) != (fw, fh):
        sys.exit(f"FAIL: window {ww}x{wh} and frame {fw}x{fh} differ (run at --scale 1)")
    below = max(abs(a - b) for a, b in zip(window[hud_rows * ww:], frame[hud_rows * fw:]))
    # The box's left margin, left of the text (3 pixels at the HUD's scale 1, windows under 700 rows high).
    corner_window, corner_frame = mean(window, ww, 0, 0, 3, 60), mean(frame, fw, 0, 0, 3, 60)
    print(f"largest difference below row {hud_rows}: {below:.1f}; box's left margin: window {corner_window:.1f}, "
          f"frame {corner_frame:.1f}")
    if below > 3:
        sys.exit("FAIL: the window differs from the frame below the HUD (the HUD was drawn elsewhere or stretched)")
    if corner_frame < 20:
        sys.exit("FAIL: the frame's top-left corner is too dark to see the HUD's box over it")
    if corner_window > 0.8 * corner_frame:
        sys.exit("FAIL: no HUD box darkens the window's top-left corner")


if __name__ == "__main__":
    main()
