#!/usr/bin/env python3
"""Usage: image_not_uniform.py IMAGE [WIDTH HEIGHT]
Checks that an 8-bit PNG (RGB/RGBA, non-interlaced) or binary PPM shows a picture: the right size
when asked, not one flat colour, not (nearly) black. Standard library only."""
import struct
import sys
import zlib


def read_png(data):
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError("not a PNG")
    pos, idat, header = 8, b"", None
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    width, height, depth, color, _, _, interlace = header
    channels = {2: 3, 6: 4, 0: 1, 4: 2}[color]
    if depth != 8 or interlace:
        raise ValueError("only 8-bit non-interlaced PNGs are checked")
    raw = zlib.decompress(idat)
    stride = width * channels
    rows, prev = [], bytearray(stride)
    for y in range(height):
        start = y * (stride + 1)
        kind, line = raw[start], bytearray(raw[start + 1:start + 1 + stride])
        for i in range(stride):
            a = line[i - channels] if i >= channels else 0
            b = prev[i]
            c = prev[i - channels] if i >= channels else 0
            if kind == 1:
                line[i] = (line[i] + a) & 255
            elif kind == 2:
                line[i] = (line[i] + b) & 255
            elif kind == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif kind == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(bytes(line))
        prev = line
    return width, height, channels, b"".join(rows)


def read_ppm(data):
    fields, pos = [], 2
    if data[:2] != b"P6":
        raise ValueError("not a binary PPM")
    while len(fields) < 3:
        while data[pos:pos + 1].isspace():
            pos += 1
        end = pos
        while not data[end:end + 1].isspace():
            end += 1
        fields.append(int(data[pos:end]))
        pos = end
    width, height, _ = fields
    return width, height, 3, data[pos + 1:pos + 1 + width * height * 3]


def main():
    path = sys.argv[1]
    with open(path, "rb") as f:
        data = f.read()
    width, height, channels, pixels = (read_png if data[:4] == b"\x89PNG" else read_ppm)(data)
    colour = min(channels, 3)
    lum = [sum(pixels[i:i + colour]) / colour for i in range(0, len(pixels), channels)]
    mean = sum(lum) / len(lum)
    spread = (sum((v - mean) ** 2 for v in lum) / len(lum)) ** 0.5
    distinct = len({pixels[i:i + colour] for i in range(0, len(pixels), channels)})
    print(f"{path}: {width}x{height}, mean {mean:.1f}, std {spread:.1f}, {distinct} distinct colours")
    if width * height == 0:
        sys.exit("FAIL: empty image")
    if len(sys.argv) >= 4 and (width, height) != (int(sys.argv[2]), int(sys.argv[3])):
        sys.exit(f"FAIL: expected {sys.argv[2]}x{sys.argv[3]}")
    if distinct < 16 or spread < 2.0:
        sys.exit("FAIL: the image is (nearly) uniform")
    if mean < 2.0:
        sys.exit("FAIL: the image is black")


if __name__ == "__main__":
    main()
