#!/usr/bin/env python3
"""Writes the tiny TGA fixtures under base/ (run from tests/scene/data). Each is a few texels with
values the tests check, in the encodings the TGA reader must handle."""
import struct


def tga(path, w, h, pixels, bits=24, top_first=False, rle=False):
    """pixels: rows top to bottom of (r, g, b, a) tuples."""
    rows = pixels if top_first else list(reversed(pixels))
    bpp = bits // 8
    data = bytearray()
    for row in rows:
        for r, g, b, a in row:
            data += bytes([b, g, r, a][:bpp])
    if rle:
        packed = bytearray()
        for i in range(0, len(data), bpp):  # one raw packet per pixel: legal, exercises the path
            packed += bytes([0]) + data[i:i + bpp]
        data = packed
    kind = 10 if rle else 2
    header = struct.pack('<BBBHHBHHHHBB', 0, 0, kind, 0, 0, 0, 0, 0, w, h, bits, 0x20 if top_first else 0)
    with open(path, 'wb') as f:
        f.write(header + data)


def solid(w, h, c):
    return [[c] * w for _ in range(h)]


tga('base/textures/test/floor.tga', 2, 2, [[(255, 0, 0, 255), (0, 255, 0, 255)],
                                           [(0, 0, 255, 255), (255, 255, 255, 255)]])
tga('base/textures/test/floor_local.tga', 2, 2, solid(2, 2, (128, 128, 255, 255)))
tga('base/textures/test/floor_h.tga', 2, 2, solid(2, 2, (0, 0, 0, 255)), top_first=True)
tga('base/textures/test/floor_s.tga', 1, 1, solid(1, 1, (64, 64, 64, 255)), rle=True)
tga('base/textures/test/wall.tga', 2, 1, [[(10, 20, 30, 255), (40, 50, 60, 255)]], rle=True, top_first=True)
tga('base/textures/test/wall_h.tga', 4, 4, [[(x * 60, x * 60, x * 60, 255) for x in range(4)] for _ in range(4)])
tga('base/textures/test/grate.tga', 2, 2, [[(200, 200, 200, 255), (200, 200, 200, 0)],
                                           [(200, 200, 200, 0), (200, 200, 200, 255)]], bits=32)
tga('base/textures/test/glass.tga', 1, 1, solid(1, 1, (100, 150, 200, 128)), bits=32)
tga('base/textures/test/panel.tga', 1, 1, solid(1, 1, (255, 240, 200, 255)))
tga('base/lights/test_gel.tga', 2, 2, solid(2, 2, (255, 255, 255, 255)))
tga('base/lights/test_falloff.tga', 4, 1, [[(255, 0, 0, 255), (170, 0, 0, 255), (85, 0, 0, 255), (0, 0, 0, 255)]])
