"""Truevision TGA writer: 24/32-bit, uncompressed (type 2) or run-length encoded (type 10).

Pixels are given top row first as a list of rows of (r, g, b[, a]) integer tuples; the file is written
bottom-left origin (the TGA default), which every reader handles.
"""
import struct


def _pixel_bytes(pixel, channels):
    r, g, b = pixel[0], pixel[1], pixel[2]
    if channels == 4:
        return bytes((b, g, r, pixel[3]))
    return bytes((b, g, r))


def _rle_row(row_bytes):
    """Encode one scanline (list of per-pixel byte strings) as TGA RLE packets (max 128 pixels each)."""
    out = bytearray()
    i = 0
    n = len(row_bytes)
    while i < n:
        run = 1
        while i + run < n and run < 128 and row_bytes[i + run] == row_bytes[i]:
            run += 1
        if run > 1:
            out.append(0x80 | (run - 1))
            out += row_bytes[i]
            i += run
            continue
        start = i
        i += 1
        while i < n and i - start < 128 and not (i + 1 < n and row_bytes[i + 1] == row_bytes[i]):
            i += 1
        out.append(i - start - 1)
        for p in row_bytes[start:i]:
            out += p
    return bytes(out)


def encode_tga(rows, channels, rle=False):
    height = len(rows)
    width = len(rows[0])
    if channels not in (3, 4):
        raise ValueError("TGA channels must be 3 or 4")
    descriptor = 8 if channels == 4 else 0  # alpha bits; origin bottom-left
    header = struct.pack("<BBBHHBHHHHBB", 0, 0, 10 if rle else 2, 0, 0, 0, 0, 0,
                         width, height, channels * 8, descriptor)
    body = bytearray()
    for row in reversed(rows):
        pixels = [_pixel_bytes(p, channels) for p in row]
        if rle:
            body += _rle_row(pixels)
        else:
            for p in pixels:
                body += p
    return header + bytes(body)


def decode_tga(data):
    """Decoder used by the self-checks (and tests): returns (width, height, channels, rows top-first)."""
    (_, _, kind, _, _, _, _, _, width, height, bits, descriptor) = struct.unpack("<BBBHHBHHHHBB", data[:18])
    channels = bits // 8
    pos = 18
    pixels = []
    total = width * height
    if kind == 2:
        for _ in range(total):
            pixels.append(data[pos:pos + channels])
            pos += channels
    elif kind == 10:
        while len(pixels) < total:
            packet = data[pos]
            pos += 1
            count = (packet & 0x7F) + 1
            if packet & 0x80:
                px = data[pos:pos + channels]
                pos += channels
                pixels.extend([px] * count)
            else:
                for _ in range(count):
                    pixels.append(data[pos:pos + channels])
                    pos += channels
    else:
        raise ValueError("unsupported TGA type %d" % kind)
    rows = []
    for y in range(height):
        row = []
        for x in range(width):
            p = pixels[y * width + x]
            rgba = (p[2], p[1], p[0]) + ((p[3],) if channels == 4 else ())
            row.append(rgba)
        rows.append(row)
    if not descriptor & 0x20:
        rows.reverse()
    return width, height, channels, rows
