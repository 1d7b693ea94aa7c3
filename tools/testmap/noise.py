"""Deterministic, tileable value noise from an integer hash (no global RNG state, same bytes everywhere)."""
import math


def hash01(x, y, seed):
    h = (x * 374761393 + y * 668265263 + seed * 1442695041) & 0xFFFFFFFF
    h = ((h ^ (h >> 13)) * 1274126177) & 0xFFFFFFFF
    h ^= h >> 16
    return h / 4294967295.0


def _smooth(t):
    return t * t * (3.0 - 2.0 * t)


def value_noise(u, v, period, seed):
    """Noise in [0,1] on a lattice of `period` cells that wraps (u, v in lattice units)."""
    iu = math.floor(u)
    iv = math.floor(v)
    fu = _smooth(u - iu)
    fv = _smooth(v - iv)
    x0, x1 = iu % period, (iu + 1) % period
    y0, y1 = iv % period, (iv + 1) % period
    a = hash01(x0, y0, seed)
    b = hash01(x1, y0, seed)
    c = hash01(x0, y1, seed)
    d = hash01(x1, y1, seed)
    top = a + (b - a) * fu
    bottom = c + (d - c) * fu
    return top + (bottom - top) * fv


def fbm(x, y, size, cells, octaves, seed):
    """Fractal sum of value noise, tileable over a `size`-pixel image, normalised to [0,1]."""
    total = 0.0
    amplitude = 1.0
    norm = 0.0
    for octave in range(octaves):
        period = cells << octave
        scale = period / size
        total += amplitude * value_noise(x * scale, y * scale, period, seed + 7919 * octave)
        norm += amplitude
        amplitude *= 0.5
    return total / norm
