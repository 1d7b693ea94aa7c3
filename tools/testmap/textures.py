"""Procedural images for the test map: diffuse, normal ("_local"), height ("_h"), specular ("_s") maps,
decals with alpha, light gels and falloff. Each image is (rows top-first, channels, rle)."""
import math

from .noise import fbm, hash01


def clamp8(v):
    return max(0, min(255, int(round(v * 255.0))))


def rgb(r, g, b):
    return (clamp8(r), clamp8(g), clamp8(b))


def rgba(r, g, b, a):
    return (clamp8(r), clamp8(g), clamp8(b), clamp8(a))


def make_image(size_x, size_y, pixel):
    return [[pixel(x, y) for x in range(size_x)] for y in range(size_y)]


def height_to_normal_rows(height, strength):
    """Tangent-space normal map, encoded n*0.5+0.5 in RGB: X along +s (image right), Y along +t
    (image down: row order, t grows with the row), Z out of the surface. Same convention as the
    engine's heightmap() program, which computes (-dh/ds, -dh/dt, 1).
    """
    h = len(height)
    w = len(height[0])
    rows = []
    for y in range(h):
        row = []
        for x in range(w):
            dx = (height[y][(x + 1) % w] - height[y][(x - 1) % w]) * 0.5
            dy_down = (height[(y + 1) % h][x] - height[(y - 1) % h][x]) * 0.5
            nx = -dx * strength
            ny = -dy_down * strength
            length = math.sqrt(nx * nx + ny * ny + 1.0)
            row.append(rgb((nx / length) * 0.5 + 0.5, (ny / length) * 0.5 + 0.5, (1.0 / length) * 0.5 + 0.5))
        rows.append(row)
    return rows


def height_to_gray_rows(height):
    return [[rgb(v, v, v) for v in row] for row in height]


def bevel(distance, width):
    """0 at an edge rising to 1 at `width` pixels inside, smooth."""
    t = max(0.0, min(1.0, distance / width))
    return t * t * (3.0 - 2.0 * t)


# --- height fields ---------------------------------------------------------------------------------

def tiles_height(size, tiles, seed):
    cell = size // tiles

    def h(x, y):
        lx, ly = x % cell, y % cell
        edge = min(lx, ly, cell - 1 - lx, cell - 1 - ly)
        return 0.15 + 0.8 * bevel(edge - 1, 3) + 0.05 * fbm(x, y, size, 8, 3, seed)
    return [[h(x, y) for x in range(size)] for y in range(size)]


def bricks_height(size, seed):
    brick_w, brick_h = size // 2, size // 4

    def h(x, y):
        row = y // brick_h
        sx = (x + (brick_w // 2 if row % 2 else 0)) % size
        lx, ly = sx % brick_w, y % brick_h
        edge = min(lx, ly, brick_w - 1 - lx, brick_h - 1 - ly)
        brick_id = (sx // brick_w) + 2 * row
        rough = 0.1 * fbm(x, y, size, 16, 3, seed + brick_id)
        return 0.1 + 0.75 * bevel(edge - 1, 4) + rough
    return [[h(x, y) for x in range(size)] for y in range(size)]


def grooves_height(size, period, seed):
    def h(x, y):
        phase = (y % period) / period
        groove = 0.5 + 0.5 * math.cos(phase * 2.0 * math.pi)
        return 1.0 - groove ** 8 + 0.05 * fbm(x, y, size, 8, 2, seed)
    return [[h(x, y) for x in range(size)] for y in range(size)]


def planks_height(size, planks, seed):
    width = size // planks

    def h(x, y):
        lx = x % width
        frame = min(x, y, size - 1 - x, size - 1 - y)
        plank = 0.2 + 0.7 * bevel(min(lx, width - 1 - lx), 2)
        border = 1.0 if frame < 10 else plank * bevel(frame - 10, 2) + (1.0 - bevel(frame - 10, 2)) * 0.1
        grain = 0.08 * fbm(x * 0.25, y * 4.0, size, 8, 3, seed)
        return min(1.0, border + grain)
    return [[h(x, y) for x in range(size)] for y in range(size)]


def noise_height(size, cells, seed):
    return [[fbm(x, y, size, cells, 4, seed) for x in range(size)] for y in range(size)]


def grate_mask(x, y, size):
    """1 on the bars, 0 in the holes: 8x8 square holes with 4-pixel bars."""
    cell = size // 8
    lx, ly = x % cell, y % cell
    bar = 4
    return 1.0 if (lx < bar or ly < bar) else 0.0


# --- image set -------------------------------------------------------------------------------------

def build_images():
    """Returns {relative path: (rows, channels, rle)} in a fixed order."""
    images = {}
    size = 128

    def add(path, rows, channels=3, rle=False):
        images[path] = (rows, channels, rle)

    tex = "textures/testmap/"

    tiles_h = tiles_height(size, 4, 11)
    add(tex + "tiles_d.tga", make_image(size, size, lambda x, y: _tiles_colour(x, y, size, tiles_h)))
    add(tex + "tiles_local.tga", height_to_normal_rows(noise_height(size, 16, 12), 8.0))
    add(tex + "tiles_h.tga", height_to_gray_rows(tiles_h), rle=True)
    add(tex + "tiles_s.tga", make_image(size, size, lambda x, y: rgb(*([0.15 + 0.5 * tiles_h[y][x]] * 3))))

    bricks_h = bricks_height(size, 21)
    add(tex + "bricks_d.tga", make_image(size, size, lambda x, y: _bricks_colour(x, y, size, bricks_h)))
    add(tex + "bricks_local.tga", height_to_normal_rows(bricks_h, 6.0))
    add(tex + "bricks_s.tga", make_image(size, size, lambda x, y: rgb(*([0.05 + 0.2 * bricks_h[y][x]] * 3))),
        rle=True)

    concrete_h = noise_height(size, 8, 31)
    add(tex + "concrete_d.tga", make_image(size, size, lambda x, y: _tint(0.42, 0.41, 0.39,
                                                                           0.6 + 0.5 * concrete_h[y][x])))
    add(tex + "concrete_h.tga", height_to_gray_rows(concrete_h))

    grooves_h = grooves_height(size, 16, 41)
    add(tex + "metalfloor_d.tga", make_image(size, size, lambda x, y: _tint(0.35, 0.37, 0.4,
                                                                           0.55 + 0.45 * grooves_h[y][x])))
    add(tex + "metalfloor_local.tga", height_to_normal_rows(grooves_h, 5.0))
    add(tex + "metalfloor_s.tga", make_image(size, size, lambda x, y: rgb(*([0.3 + 0.5 * grooves_h[y][x]] * 3))))

    ceiling_h = tiles_height(size, 2, 51)
    add(tex + "ceiling_d.tga", make_image(size, size, lambda x, y: _tint(0.7, 0.7, 0.68,
                                                                         0.7 + 0.3 * ceiling_h[y][x])))
    add(tex + "ceiling_local.tga", height_to_normal_rows(ceiling_h, 4.0), rle=True)

    planks_h = planks_height(size, 4, 61)
    add(tex + "crate_d.tga", make_image(size, size, lambda x, y: _tint(0.55, 0.38, 0.2,
                                                                       0.45 + 0.6 * planks_h[y][x])))
    add(tex + "crate_local.tga", height_to_normal_rows(planks_h, 5.0))
    add(tex + "crate_s.tga", make_image(size, size, lambda x, y: rgb(*([0.1 * planks_h[y][x]] * 3))), rle=True)

    metal_h = noise_height(size, 32, 71)
    add(tex + "metal_d.tga", make_image(size, size, lambda x, y: _tint(0.5, 0.52, 0.56,
                                                                       0.75 + 0.35 * metal_h[y][x])))
    add(tex + "metal_local.tga", height_to_normal_rows(metal_h, 1.0))
    add(tex + "metal_s.tga", make_image(size, size, lambda x, y: rgb(*([0.5 + 0.4 * metal_h[y][x]] * 3))))

    wood_h = [[fbm(x * 0.2, y * 3.0, size, 8, 3, 81) for x in range(size)] for y in range(size)]
    add(tex + "wood_d.tga", make_image(size, size, lambda x, y: _tint(0.45, 0.27, 0.13,
                                                                      0.6 + 0.6 * wood_h[y][x])))
    add(tex + "wood_local.tga", height_to_normal_rows(wood_h, 2.0))

    add(tex + "grate_d.tga", make_image(size, size, lambda x, y: _grate_colour(x, y, size)), channels=4)
    grate_h = [[grate_mask(x, y, size) for x in range(size)] for y in range(size)]
    add(tex + "grate_local.tga", height_to_normal_rows(grate_h, 3.0))

    add(tex + "glass_d.tga", make_image(64, 64, lambda x, y: rgba(0.55, 0.75, 0.8,
                                                                  0.25 + 0.15 * fbm(x, y, 64, 4, 2, 91))),
        channels=4)
    add(tex + "blood.tga", make_image(size, size, lambda x, y: _blood(x, y, size)), channels=4, rle=True)
    add(tex + "sign.tga", make_image(size, 64, _sign), channels=4)
    add(tex + "lightpanel_d.tga", make_image(64, 64, _light_panel))
    add(tex + "sky_d.tga", make_image(size, size, lambda x, y: _tint(0.55, 0.72, 1.0,
                                                                     0.8 + 0.4 * fbm(x, y, size, 4, 4, 101))))

    add(tex + "leaves_d.tga", make_image(64, 64, lambda x, y: _tint(0.22, 0.5, 0.16,
                                                                    0.6 + 0.6 * fbm(x, y, 64, 8, 3, 131))))
    for suffix, view in SKY_CAMERA_VIEWS:
        add("env/testmap_sky" + suffix + ".tga", make_image(SKY_FACE, SKY_FACE, lambda x, y, v=view: _sky_view(x, y, v)))

    add("lights/testmap_gel.tga", make_image(size, size, lambda x, y: _gel(x, y, size)))
    add("lights/testmap_round.tga", make_image(size, size, lambda x, y: _round_spot(x, y, size)))
    add("lights/testmap_falloff.tga", make_image(64, 8, lambda x, y: _falloff(x, 64)), rle=True)
    return images


# The six images of a cameraCubeMap (doom3-content.md section 8), each an ordinary 90-degree view:
# (suffix, (forward, right, up)). forward, back, left, right look along +X, -X, +Y, -Y with image-up +Z;
# up and down are the forward view pitched up and down.
SKY_CAMERA_VIEWS = (
    ("_forward", ((1, 0, 0), (0, -1, 0), (0, 0, 1))),
    ("_back", ((-1, 0, 0), (0, 1, 0), (0, 0, 1))),
    ("_left", ((0, 1, 0), (1, 0, 0), (0, 0, 1))),
    ("_right", ((0, -1, 0), (-1, 0, 0), (0, 0, 1))),
    ("_up", ((0, 0, 1), (0, -1, 0), (-1, 0, 0))),
    ("_down", ((0, 0, -1), (0, -1, 0), (1, 0, 0))),
)
SKY_FACE = 64
SKY_SUN = (0.48, 0.6, 0.64)   # unit direction toward the painted sun


def _sky_view(x, y, view):
    """Pixel (x, y) of a camera image of the sky: the world direction through it, then the sky's colour
    there. If the loader turns the faces right, the cube shows one seamless sky."""
    forward, right, up = view
    sx = (2.0 * (x + 0.5) / SKY_FACE) - 1.0
    sy = 1.0 - (2.0 * (y + 0.5) / SKY_FACE)
    d = [forward[i] + sx * right[i] + sy * up[i] for i in range(3)]
    length = math.sqrt(sum(c * c for c in d))
    d = [c / length for c in d]
    if d[2] < 0.0:   # ground below the horizon, darker with depth
        k = 0.55 + 0.45 * (1.0 + d[2])
        return rgb(0.32 * k, 0.28 * k, 0.22 * k)
    zenith, horizon = (0.16, 0.34, 0.78), (0.78, 0.85, 0.95)
    t = math.sqrt(d[2])
    sky = [horizon[i] + (zenith[i] - horizon[i]) * t for i in range(3)]
    sun = sum(d[i] * SKY_SUN[i] for i in range(3))
    glow = max(0.0, sun) ** 64 * 0.6 + (1.0 if sun > 0.995 else 0.0)
    return rgb(*[min(1.0, c + glow) for c in sky])


def _tint(r, g, b, k):
    return rgb(r * k, g * k, b * k)


def _tiles_colour(x, y, size, height):
    cell = size // 4
    checker = ((x // cell) + (y // cell)) % 2
    base = (0.62, 0.6, 0.55) if checker else (0.3, 0.33, 0.38)
    k = 0.5 + 0.5 * height[y][x]
    return rgb(base[0] * k, base[1] * k, base[2] * k)


def _bricks_colour(x, y, size, height):
    row = y // (size // 4)
    brick_w = size // 2
    sx = (x + (brick_w // 2 if row % 2 else 0)) % size
    variation = hash01(sx // brick_w, row, 5)
    if height[y][x] < 0.3:
        return _tint(0.55, 0.53, 0.5, 0.7 + height[y][x])
    return _tint(0.55 + 0.15 * variation, 0.25 + 0.05 * variation, 0.18, 0.6 + 0.5 * height[y][x])


def _grate_colour(x, y, size):
    if grate_mask(x, y, size) > 0.5:
        k = 0.5 + 0.3 * fbm(x, y, size, 16, 2, 111)
        return rgba(0.4 * k, 0.42 * k, 0.45 * k, 1.0)
    return rgba(0.0, 0.0, 0.0, 0.0)


def _blood(x, y, size):
    c = size / 2.0
    r = math.hypot(x - c, y - c) / c
    splat = 0.65 + 0.35 * fbm(x, y, size, 6, 3, 121) - r
    drip = 1.0 if (abs(x - c - 10) < 3 and y > c and y < c + 50 * fbm(x, 0, size, 4, 1, 122) + 10) else 0.0
    alpha = max(0.0, min(1.0, max(splat * 4.0, drip)))
    return rgba(0.35, 0.02, 0.02, alpha)


def _sign(x, y):
    """A yellow 'EXIT'-style panel: border plus stripes, alpha cut to the panel shape."""
    if x < 2 or y < 2 or x > 125 or y > 61:
        return rgba(0, 0, 0, 0)
    border = x < 8 or y < 8 or x > 119 or y > 55
    stripe = ((x + y) // 8) % 2 == 0 and 20 < x < 108 and 24 < y < 40
    if border or stripe:
        return rgba(0.08, 0.08, 0.08, 1.0)
    return rgba(0.95, 0.75, 0.1, 1.0)


def _light_panel(x, y):
    edge = min(x, y, 63 - x, 63 - y)
    if edge < 3:
        return rgb(0.2, 0.2, 0.2)
    k = 0.85 + 0.15 * math.cos((x - 32) / 64.0 * math.pi)
    return rgb(k, k, 0.92 * k)


def _gel(x, y, size):
    """Colourful stained-glass gel: coloured sectors, a ring and a dark cross."""
    u = (x + 0.5) / size * 2.0 - 1.0
    v = (y + 0.5) / size * 2.0 - 1.0
    angle = math.atan2(v, u)
    sector = int(((angle + math.pi) / (2.0 * math.pi)) * 6.0) % 6
    palette = [(1.0, 0.2, 0.2), (1.0, 0.8, 0.1), (0.2, 1.0, 0.3), (0.1, 0.8, 1.0), (0.3, 0.3, 1.0), (1.0, 0.3, 0.9)]
    r = math.hypot(u, v)
    if abs(u) < 0.04 or abs(v) < 0.04 or abs(r - 0.55) < 0.04:
        return rgb(0.05, 0.05, 0.05)
    colour = palette[sector]
    vignette = max(0.0, 1.0 - r ** 4)
    return rgb(colour[0] * vignette, colour[1] * vignette, colour[2] * vignette)


def _round_spot(x, y, size):
    u = (x + 0.5) / size * 2.0 - 1.0
    v = (y + 0.5) / size * 2.0 - 1.0
    r = math.hypot(u, v)
    k = max(0.0, 1.0 - r * r) ** 2
    return rgb(k, k, k)


def _falloff(x, width):
    f = (x + 0.5) / width * 2.0 - 1.0
    k = max(0.0, 1.0 - f * f) ** 2
    return rgb(k, k, k)
