"""The large generated map (`gen_testmap.py --large`): a Doom 3-scale level for scaling tests.

A lattice of rooms (COLS x ROWS) on two floor levels, joined by corridors; a corridor between rooms on
different levels is a stairwell (steps carved out of it as solids). Some rooms have a skylight shaft.
The world shell comes from the same grid builder as the small map (shell.py), so the same checks
apply: one closed, consistently wound shell, portals that are single rectangles, a node tree that
puts every cell and every entity in its area. Detail surfaces (not part of the shell) carry most of
the triangles: curved cove patches where walls meet ceilings, arch ribs swept along bezier curves,
round pillars, pipe runs with elbows, stair handrails, trims, light panels. Props are func_static
entities instancing a few shared .proc models. Every kind of light the loader reads is used.

Deterministic: everything comes from one seeded generator that only uses random.Random.random(),
whose sequence is stable across Python versions; numbers are written by numbers.fmt.
"""
import math
import random

from . import checks, materials
from .bsp import build_nodes
from .layout import M, inline_models as testmap_models, texel_scale_for, yaw_rotation
from .map_writer import brush_text, map_text, patch_text
from .mesh import Mesh, add_box, cross, dot, sub
from .numbers import fmt_vec
from .portals import merge_portals
from .proc_writer import proc_text
from .shell import Box, Grid, build_shell
from .tga import encode_tga

MAP_NAME = "largemap"
GAP = 192            # corridor length between neighbouring rooms (8 steps of RUN)
HALF_CORRIDOR = 64   # corridors and skylight shafts are 128 wide, centred on the room
STEPS, RISE, RUN = 8, 12, 24
UPPER = STEPS * RISE  # floor of the raised level (96)
CORRIDOR_HEIGHT = 128
SHAFT_HEIGHT = 160

# What the generator promises (checked on every run, whatever the seed).
TARGETS = {"areas": 40, "area_triangles": 300000, "lights": 256, "props": 100}


class Rng:
    """Seeded choices built only on random() so the sequence never depends on library details."""

    def __init__(self, seed):
        self._r = random.Random(seed)

    def real(self, lo, hi):
        return lo + (hi - lo) * self._r.random()

    def int(self, lo, hi):
        return min(hi, lo + int(self._r.random() * (hi - lo + 1)))

    def pick(self, seq):
        return seq[self.int(0, len(seq) - 1)]

    def chance(self, p):
        return self._r.random() < p


def _norm(v):
    length = math.sqrt(dot(v, v))
    return (v[0] / length, v[1] / length, v[2] / length)


def _add(a, b, s=1.0):
    return (a[0] + b[0] * s, a[1] + b[1] * s, a[2] + b[2] * s)


def _r6(v):
    return round(v, 6)


def _circle(segments):
    """(cos, sin) at segments + 1 angles (the seam repeated for texture coordinates), rounded."""
    return [(_r6(math.cos(2 * math.pi * k / segments)), _r6(math.sin(2 * math.pi * k / segments)))
            for k in range(segments + 1)]


def add_oriented_triangle(mesh, material, verts):
    """verts = [(pos, st, normal)]; winding fixed so the face is clockwise seen from the normal side."""
    face = cross(sub(verts[1][0], verts[0][0]), sub(verts[2][0], verts[0][0]))
    n = (verts[0][2][0] + verts[1][2][0] + verts[2][2][0], verts[0][2][1] + verts[1][2][1] + verts[2][2][1],
         verts[0][2][2] + verts[1][2][2] + verts[2][2][2])
    if dot(face, face) < 1e-10:
        return
    if dot(face, n) > 0:
        verts = [verts[0], verts[2], verts[1]]
    mesh.add_triangle(material, verts)


def add_grid_surface(mesh, material, rows):
    """rows[i][j] = (pos, st, normal); two triangles per grid cell."""
    for i in range(len(rows) - 1):
        for j in range(len(rows[i]) - 1):
            a, b, c, d = rows[i][j], rows[i + 1][j], rows[i + 1][j + 1], rows[i][j + 1]
            add_oriented_triangle(mesh, material, [a, b, c])
            add_oriented_triangle(mesh, material, [a, c, d])


def add_tube(mesh, material, centres, radius, segments, texel=64.0):
    """Circle of `radius` swept along a path of centre points (pipes, rails, ribs); smooth normals."""
    ring = _circle(segments)
    rows = []
    length = 0.0
    count = len(centres)
    for i, c in enumerate(centres):
        if i > 0:
            d = sub(c, centres[i - 1])
            length += math.sqrt(dot(d, d))
        t = _norm(sub(centres[min(i + 1, count - 1)], centres[max(i - 1, 0)]))
        helper = (0.0, 0.0, 1.0) if abs(t[2]) < 0.9 else (1.0, 0.0, 0.0)
        n = _norm(cross(t, helper))
        b = cross(t, n)
        row = []
        for k, (cs, sn) in enumerate(ring):
            normal = (_r6(cs * n[0] + sn * b[0]), _r6(cs * n[1] + sn * b[1]), _r6(cs * n[2] + sn * b[2]))
            row.append((_add(c, normal, radius), (k / float(segments), length / texel), normal))
        rows.append(row)
    add_grid_surface(mesh, material, rows)


def add_cylinder(mesh, material, x, y, z0, z1, radius, segments, slices, caps=False):
    ring = _circle(segments)
    rows = []
    for k, (cs, sn) in enumerate(ring):
        normal = (cs, sn, 0.0)
        column = []
        for j in range(slices + 1):
            z = z0 + (z1 - z0) * j / float(slices)
            column.append(((x + radius * cs, y + radius * sn, z), (k / float(segments) * 2.0, -z / 64.0), normal))
        rows.append(column)
    add_grid_surface(mesh, material, rows)
    if caps:
        for z, up in ((z0, -1.0), (z1, 1.0)):
            centre = ((x, y, z), (0.5, 0.5), (0.0, 0.0, up))
            for k in range(segments):
                p = [((x + radius * cs, y + radius * sn, z), (0.5 + 0.5 * cs, 0.5 + 0.5 * sn), (0.0, 0.0, up))
                     for cs, sn in (ring[k], ring[k + 1])]
                add_oriented_triangle(mesh, material, [centre, p[0], p[1]])


def bezier(p0, p1, p2, t):
    a, b, c = (1 - t) * (1 - t), 2 * (1 - t) * t, t * t
    return tuple(a * p0[m] + b * p1[m] + c * p2[m] for m in range(len(p0)))


def add_patch(mesh, material, control, nu, nv, inside):
    """Biquadratic bezier patch (control[u][v], 3x3 of xyz), tessellated nu x nv; normals point toward
    `inside` (a point the surface faces)."""
    def point(u, v):
        return bezier(bezier(*control[0], v), bezier(*control[1], v), bezier(*control[2], v), u)

    rows = []
    for i in range(nu + 1):
        u = i / float(nu)
        row = []
        for j in range(nv + 1):
            v = j / float(nv)
            p = point(u, v)
            du = sub(point(min(u + 1e-3, 1.0), v), point(max(u - 1e-3, 0.0), v))
            dv = sub(point(u, min(v + 1e-3, 1.0)), point(u, max(v - 1e-3, 0.0)))
            n = _norm(cross(du, dv))
            if dot(n, sub(inside, p)) < 0:
                n = (-n[0], -n[1], -n[2])
            n = (_r6(n[0]), _r6(n[1]), _r6(n[2]))
            row.append((p, (u * nu / 4.0, v), n))
        rows.append(row)
    add_grid_surface(mesh, material, rows)


def add_panel(mesh, material, points, normal):
    st = [(0.0, 1.0), (1.0, 1.0), (1.0, 0.0), (0.0, 0.0)]
    mesh.add_polygon(material, points, normal, st=st)


# --- layout ----------------------------------------------------------------------------------------

class Room:
    def __init__(self, index, col, row, lo, hi, theme):
        self.index = index
        self.col, self.row = col, row
        self.lo, self.hi = lo, hi
        self.theme = theme
        self.centre = ((lo[0] + hi[0]) * 0.5, (lo[1] + hi[1]) * 0.5)
        self.shaft = None


class Layout:
    def __init__(self, seed, cols, rows):
        rng = Rng(seed)
        self.rng = rng
        widths = [rng.pick((512, 576, 640, 704, 768)) for _ in range(cols)]
        depths = [rng.pick((512, 576, 640, 704)) for _ in range(rows)]
        xs, ys = [0], [0]
        for w in widths:
            xs.append(xs[-1] + w + GAP)
        for d in depths:
            ys.append(ys[-1] + d + GAP)
        floors = ((M + "floor_tiles", M + "wall_bricks", M + "ceiling"),
                  (M + "metalfloor", M + "concrete", M + "concrete"),
                  (M + "wood_floor", M + "wall_bricks", M + "ceiling"),
                  (M + "floor_tiles", M + "concrete", M + "ceiling"))
        self.rooms = []
        for r in range(rows):
            for c in range(cols):
                level = UPPER if rng.chance(0.35) else 0
                height = rng.pick((192, 256, 256, 320))
                lo = (xs[c], ys[r], level)
                hi = (xs[c] + widths[c], ys[r] + depths[r], level + height)
                self.rooms.append(Room(len(self.rooms), c, r, lo, hi, rng.pick(floors)))
        self.cols, self.rows_n = cols, rows

        # Links: a random spanning tree over the lattice plus about half of the remaining neighbours.
        def at(c, r):
            return self.rooms[r * cols + c]

        pairs = []
        for r in range(rows):
            for c in range(cols):
                if c + 1 < cols:
                    pairs.append((at(c, r), at(c + 1, r), 0))
                if r + 1 < rows:
                    pairs.append((at(c, r), at(c, r + 1), 1))
        order = sorted(pairs, key=lambda p: rng.real(0, 1))
        parent = list(range(len(self.rooms)))

        def find(i):
            while parent[i] != i:
                parent[i] = parent[parent[i]]
                i = parent[i]
            return i

        self.links = []
        for a, b, axis in order:
            ra, rb = find(a.index), find(b.index)
            if ra != rb:
                parent[ra] = rb
                self.links.append((a, b, axis))
            elif rng.chance(0.5):
                self.links.append((a, b, axis))
        self.links.sort(key=lambda link: (link[0].index, link[1].index))

        for room in self.rooms:
            if rng.chance(0.22) or room.index == 0:
                cx, cy = room.centre
                room.shaft = ((cx - HALF_CORRIDOR, cy - HALF_CORRIDOR, room.hi[2]),
                              (cx + HALF_CORRIDOR, cy + HALF_CORRIDOR, room.hi[2] + SHAFT_HEIGHT))

        # Areas: rooms first (area index = room index), then corridors, then shafts.
        self.areas = []
        for room in self.rooms:
            floor, wall, ceiling = room.theme
            self.areas.append(Box("room_%d_%d" % (room.col, room.row), room.lo, room.hi, floor=floor, wall=wall,
                                  ceiling=ceiling, kind="room", room=room))
        self.solids = []
        self.corridors = []
        for a, b, axis in self.links:
            other = 1 - axis
            start, end = a.hi[axis], b.lo[axis]
            mid = (a.lo[other] + a.hi[other]) * 0.5
            z0 = min(a.lo[2], b.lo[2])
            z1 = max(a.lo[2], b.lo[2]) + CORRIDOR_HEIGHT
            lo, hi = [0, 0, z0], [0, 0, z1]
            lo[axis], hi[axis] = start, end
            lo[other], hi[other] = mid - HALF_CORRIDOR, mid + HALF_CORRIDOR
            stairs = a.lo[2] != b.lo[2]
            index = len(self.areas)
            corridor = {"index": index, "a": a, "b": b, "axis": axis, "lo": tuple(lo), "hi": tuple(hi),
                        "stairs": stairs, "rising": (1 if b.lo[2] > a.lo[2] else -1) if stairs else 0}
            self.corridors.append(corridor)
            self.areas.append(Box("%s_%d_%d" % ("stairs" if stairs else "corridor", a.index, b.index), lo, hi,
                                  floor=M + "metalfloor", wall=M + "concrete", ceiling=M + "concrete",
                                  kind="corridor", corridor=corridor))
            if stairs:
                for k in range(STEPS):
                    slo, shi = list(lo), list(hi)
                    shi[2] = RISE * (k + 1)
                    if corridor["rising"] > 0:
                        slo[axis] = start + RUN * k
                    else:
                        shi[axis] = end - RUN * k
                    self.solids.append(Box("stairs", tuple(slo), tuple(shi)))
        for room in self.rooms:
            if room.shaft:
                room.shaft_area = len(self.areas)
                self.areas.append(Box("shaft_%d_%d" % (room.col, room.row), room.shaft[0], room.shaft[1],
                                      floor=M + "concrete", wall=M + "concrete", ceiling=M + "sky", kind="shaft",
                                      room=room))

    def material_for(self, area_index, inward_normal, neighbour):
        area = self.areas[area_index]
        if neighbour == "stairs":
            return M + "metalfloor" if inward_normal[2] > 0 else M + "concrete"
        if inward_normal[2] > 0:
            return area.props["floor"]
        if inward_normal[2] < 0:
            return area.props["ceiling"]
        return area.props["wall"]


# --- detail ----------------------------------------------------------------------------------------

def _room_detail(mesh, room, layout, patches):
    rng = layout.rng
    (x0, y0, z0), (x1, y1, z1) = room.lo, room.hi
    cx, cy = room.centre
    height = z1 - z0

    # Cove patches where the walls meet the ceiling: quadratic in the cross-section, linear along the wall.
    cove = 40.0
    for wall in range(4):
        if wall == 0:    # -y wall
            a, b, inward = (x0, y0), (x1, y0), (0, 1)
        elif wall == 1:  # +y wall
            a, b, inward = (x1, y1), (x0, y1), (0, -1)
        elif wall == 2:  # -x wall
            a, b, inward = (x0, y1), (x0, y0), (1, 0)
        else:            # +x wall
            a, b, inward = (x1, y0), (x1, y1), (-1, 0)
        control = []
        for f in (0.0, 0.5, 1.0):
            px, py = a[0] + (b[0] - a[0]) * f, a[1] + (b[1] - a[1]) * f
            control.append([(px + inward[0] * 0.5, py + inward[1] * 0.5, z1 - cove),
                            (px + inward[0] * 0.5, py + inward[1] * 0.5, z1 - 0.5),
                            (px + inward[0] * cove, py + inward[1] * cove, z1 - 0.5)])
        length = abs(b[0] - a[0]) + abs(b[1] - a[1])
        add_patch(mesh, M + "metal", control, int(length // 32), 6, (cx, cy, z0 + height * 0.5))
        patches.append((M + "metal", [[p + (u * 0.5, v * 0.5) for v, p in enumerate(column)]
                                      for u, column in enumerate(control)]))

    # Arch ribs across the short side, swept along quadratic beziers, on pilasters.
    along = 0 if (x1 - x0) >= (y1 - y0) else 1
    span_lo, span_hi = (room.lo[along], room.hi[along])
    spring = z0 + height * 0.55
    ribs = 3 if span_hi - span_lo < 640 else 4
    for k in range(ribs):
        s = span_lo + (span_hi - span_lo) * (k + 0.5) / ribs
        if along == 0:
            p0, p2 = (s, y0 + 8, spring), (s, y1 - 8, spring)
        else:
            p0, p2 = (x0 + 8, s, spring), (x1 - 8, s, spring)
        peak = z1 - 48
        p1 = ((p0[0] + p2[0]) * 0.5, (p0[1] + p2[1]) * 0.5, 2 * peak - spring)
        add_tube(mesh, M + "pillar", [bezier(p0, p1, p2, i / 32.0) for i in range(33)], 7.0, 10)
        for foot in (p0, p2):
            add_cylinder(mesh, M + "pillar", foot[0], foot[1], z0, spring, 9.0, 10, 4)

    # Round pillars with base and capital.
    inset = 128
    pillars = [(x0 + inset, y0 + inset), (x1 - inset, y0 + inset), (x0 + inset, y1 - inset),
               (x1 - inset, y1 - inset)]
    if x1 - x0 >= 704:
        pillars += [(cx, y0 + inset), (cx, y1 - inset)]
    for px, py in pillars:
        add_cylinder(mesh, M + "pillar", px, py, z0 + 16, z1 - 24, 14.0, 16, 8)
        add_cylinder(mesh, M + "metal", px, py, z0, z0 + 16, 20.0, 16, 1, caps=True)
        add_cylinder(mesh, M + "metal", px, py, z1 - 24, z1, 20.0, 16, 1, caps=True)

    # Pipe runs round the room with rounded corners, two heights; drop pipes to the floor.
    for level, (offset, radius) in enumerate(((14.0, 5.0), (30.0, 3.0))):
        z = z1 - cove - 24 - 14 * level
        bend = 24.0
        lo_x, hi_x, lo_y, hi_y = x0 + offset, x1 - offset, y0 + offset, y1 - offset
        path = []
        corners = [((hi_x - bend, lo_y), (hi_x - bend, lo_y + bend), -90),
                   ((hi_x, hi_y - bend), (hi_x - bend, hi_y - bend), 0),
                   ((lo_x + bend, hi_y), (lo_x + bend, hi_y - bend), 90),
                   ((lo_x, lo_y + bend), (lo_x + bend, lo_y + bend), 180)]
        start = (lo_x + bend, lo_y)
        for (end, centre, angle0) in corners:
            # straight run from `start` to `end`, then a quarter bend round `centre`
            d = (end[0] - start[0], end[1] - start[1])
            steps = max(1, int((abs(d[0]) + abs(d[1])) // 32))
            for i in range(steps):
                path.append((start[0] + d[0] * i / steps, start[1] + d[1] * i / steps, z))
            for i in range(6):
                angle = math.radians(angle0 + 90.0 * i / 6.0)
                path.append((centre[0] + bend * _r6(math.cos(angle)), centre[1] + bend * _r6(math.sin(angle)), z))
            start = (centre[0] + bend * _r6(math.cos(math.radians(angle0 + 90))),
                     centre[1] + bend * _r6(math.sin(math.radians(angle0 + 90))))
        path.append(path[0])
        add_tube(mesh, M + "metal", path, radius, 8)
    for k in range(rng.int(2, 4)):
        px = x0 + 14 + rng.int(2, int((x1 - x0 - 28) // 32) - 2) * 32
        add_cylinder(mesh, M + "metal", px, y0 + 14, z0, z1 - cove - 24, 4.0, 10, 8)

    # Baseboard trim and wall panels.
    for lo, hi in (((x0, y0, z0), (x1, y0 + 4, z0 + 8)), ((x0, y1 - 4, z0), (x1, y1, z0 + 8)),
                   ((x0, y0 + 4, z0), (x0 + 4, y1 - 4, z0 + 8)), ((x1 - 4, y0 + 4, z0), (x1, y1 - 4, z0 + 8))):
        add_box(mesh, M + "metal", lo, hi, texel_scale=32.0)
    for k in range(int((x1 - x0) // 128) - 1):
        px = x0 + 96 + 128 * k
        add_box(mesh, M + "door", (px, y1 - 6, z0 + 24), (px + 48, y1 - 0.25, z0 + 88), texel_scale=64.0)

    # Ceiling light panels (emitters) over the four ceiling lights, and a grate under the shaft.
    for sx in (-1, 1):
        for sy in (-1, 1):
            lx, ly = cx + sx * (x1 - x0) * 0.25, cy + sy * (y1 - y0) * 0.25
            z = z1 - 0.25
            add_panel(mesh, M + "lightpanel", [(lx - 24, ly - 12, z), (lx + 24, ly - 12, z), (lx + 24, ly + 12, z),
                                               (lx - 24, ly + 12, z)], (0, 0, -1))
    if room.shaft:
        z = z1 - 0.5
        add_panel(mesh, M + "grate", [(cx - 64, cy - 64, z), (cx + 64, cy - 64, z), (cx + 64, cy + 64, z),
                                      (cx - 64, cy + 64, z)], (0, 0, -1))
    # Floor decal and a glass screen in some rooms.
    add_panel(mesh, M + "decal_blood", [(cx - 96, cy - 32, z0 + 0.25), (cx - 32, cy - 32, z0 + 0.25),
                                        (cx - 32, cy + 32, z0 + 0.25), (cx - 96, cy + 32, z0 + 0.25)], (0, 0, 1))
    if rng.chance(0.3):
        add_box(mesh, M + "glass", (cx + 48, cy - 64, z0 + 0.5), (cx + 50, cy + 64, z0 + 96), texel_scale=64.0)


def _corridor_detail(mesh, corridor):
    axis, other = corridor["axis"], 1 - corridor["axis"]
    lo, hi = corridor["lo"], corridor["hi"]

    def point(a, o, z):
        p = [0.0, 0.0, z]
        p[axis], p[other] = a, o
        return tuple(p)

    z1 = hi[2]
    # Two pipes along the ceiling, an arch rib at each third.
    for o, radius in ((lo[other] + 14, 5.0), (hi[other] - 22, 3.5)):
        add_tube(mesh, M + "metal", [point(lo[axis] + (hi[axis] - lo[axis]) * i / 16.0, o, z1 - 12)
                                     for i in range(17)], radius, 12)
    floor_at = (lambda a: lo[2])
    if corridor["stairs"]:
        def floor_at(a):
            t = (a - lo[axis]) / float(hi[axis] - lo[axis])
            if corridor["rising"] < 0:
                t = 1.0 - t
            return lo[2] + min(UPPER, RISE * (1 + int(t * STEPS)))
        # Handrails on both walls following the steps, on posts.
        for o in (lo[other] + 6, hi[other] - 6):
            rail = []
            for i in range(25):
                a = lo[axis] + (hi[axis] - lo[axis]) * i / 24.0
                t = (a - lo[axis]) / float(hi[axis] - lo[axis])
                z = lo[2] + 36 + UPPER * (t if corridor["rising"] > 0 else 1 - t)
                rail.append(point(a, o, z))
            add_tube(mesh, M + "metal", rail, 2.0, 10)
            for i in (3, 9, 15, 21):
                p = rail[i]
                base = floor_at(p[axis])
                add_cylinder(mesh, M + "metal", p[0], p[1], base, p[2], 1.5, 8, 2)
    for k in range(3):
        a = lo[axis] + (hi[axis] - lo[axis]) * (k + 1) / 4.0
        base = floor_at(a)
        p0, p2 = point(a, lo[other] + 6, base + 72), point(a, hi[other] - 6, base + 72)
        top = min(z1 - 8, base + 120)
        p1 = ((p0[0] + p2[0]) * 0.5, (p0[1] + p2[1]) * 0.5, 2 * top - (base + 72))
        add_tube(mesh, M + "pillar", [bezier(p0, p1, p2, i / 16.0) for i in range(17)], 5.0, 8)
    # Light strip along the ceiling.
    a0, a1 = lo[axis] + 48, hi[axis] - 48
    m = (lo[other] + hi[other]) * 0.5
    add_panel(mesh, M + "lightpanel_blue", [point(a0, m - 8, z1 - 0.25), point(a1, m - 8, z1 - 0.25),
                                            point(a1, m + 8, z1 - 0.25), point(a0, m + 8, z1 - 0.25)], (0, 0, -1))


# --- props -----------------------------------------------------------------------------------------

def prop_models():
    crate, table = [m for m in testmap_models() if m.name in ("testmap_crate", "testmap_table")]
    barrel = Mesh("largemap_barrel")
    add_cylinder(barrel, M + "metal", 0, 0, 0, 44, 16.0, 16, 4, caps=True)
    console = Mesh("largemap_console")
    add_box(console, M + "metal", (-24, -16, 0), (24, 16, 32), texel_scale=32.0)
    add_box(console, M + "door", (-20, -12, 32), (20, 12, 56), texel_scale=32.0)
    add_box(console, M + "metal", (-4, -4, 56), (4, 4, 72), texel_scale=16.0)
    return [crate, table, barrel, console]


# --- entities --------------------------------------------------------------------------------------

def _light_keys(rng, kind, origin, radius, colour):
    keys = [("origin", origin)]
    if kind == "round":        # point light with a light image and a falloff image, offset centre
        keys += [("light_radius", radius), ("light_center", (0, 0, -16)), ("texture", "lights/testmap_round")]
    elif kind == "plain":      # renderer's default point light
        keys += [("light_radius", radius)]
    elif kind == "scalar":     # old-style `light` key: one radius for all axes
        keys += [("light", max(radius))]
    elif kind == "fill":       # no shadows, wide and dim
        keys += [("light_radius", tuple(r * 1.5 for r in radius)), ("noshadows", 1)]
        colour = tuple(c * 0.4 for c in colour)
    elif kind == "nospec":
        keys += [("light_radius", radius), ("nospecular", 1)]
    elif kind == "rotated":    # anisotropic box turned by light_rotation
        keys += [("light_radius", (radius[0], radius[1] * 0.5, radius[2])),
                 ("light_rotation", yaw_rotation(rng.pick((30, 45, 60, 120))))]
    elif kind == "angle":      # turned by `angle`, shader parm for the time offset
        keys += [("light_radius", (radius[0] * 0.6, radius[1], radius[2])), ("angle", rng.pick((90, 45, 135))),
                 ("shaderParm4", rng.int(0, 3))]
    keys.append(("_color", colour))
    return keys


def _colour(rng):
    return (round(rng.real(0.7, 1.0), 2), round(rng.real(0.65, 0.95), 2), round(rng.real(0.5, 0.9), 2))


def entities(layout, models):
    rng = layout.rng
    ents = []
    expected = {}

    def add(classname, name, area, keys):
        ents.append((classname, [("name", name)] + keys))
        expected[name] = area

    first = layout.rooms[0]
    add("info_player_start", "info_player_start_1", 0,
        [("origin", (first.lo[0] + 64, first.centre[1], first.lo[2] + 1)), ("angle", 0)])

    point_kinds = ("round", "plain", "fill", "nospec", "scalar", "rotated", "angle")
    prop_names = [m.name for m in models]
    props = 0
    for room in layout.rooms:
        (x0, y0, z0), (x1, y1, z1) = room.lo, room.hi
        cx, cy = room.centre
        tag = "%d_%d" % (room.col, room.row)
        w, d = x1 - x0, y1 - y0
        for n, (sx, sy) in enumerate(((-1, -1), (1, -1), (-1, 1), (1, 1))):
            kind = point_kinds[(room.index + n) % len(point_kinds)]
            origin = (cx + sx * w * 0.25, cy + sy * d * 0.25, z1 - 20)
            add("light", "light_%s_%d" % (tag, n), room.index,
                _light_keys(rng, kind, origin, (w * 0.5, d * 0.5, z1 - z0), _colour(rng)))
        # Projected spots from under the ceiling at the -y wall toward the floor centre: one textured
        # (gel or round image + falloff, with start/end), one with the default projected light.
        origin = (cx - w * 0.25, y0 + 32, z1 - 24)
        target = (0, d * 0.5 - 32, -(z1 - z0 - 24))
        add("light", "light_%s_spot" % tag, room.index,
            [("origin", origin), ("light_target", target), ("light_right", (96, 0, 0)),
             ("light_up", (0, 48, 48)), ("light_start", (0, 8, -8)),
             ("light_end", (0, d * 0.5, -(z1 - z0 - 24))),
             ("texture", rng.pick(("lights/testmap_gel", "lights/testmap_round"))), ("_color", _colour(rng))])
        origin = (cx + w * 0.25, y1 - 32, z1 - 24)
        add("light", "light_%s_beam" % tag, room.index,
            [("origin", origin), ("light_target", (0, -(d * 0.5 - 32), -(z1 - z0 - 24))),
             ("light_right", (-64, 0, 0)), ("light_up", (0, 40, -40)), ("_color", _colour(rng))])
        add("light", "light_%s_low" % tag, room.index,
            _light_keys(rng, point_kinds[(room.index + 4) % len(point_kinds)], (cx, cy, z0 + 48),
                        (160, 160, 96), (0.6, 0.75, 1.0)))
        if room.shaft:
            lo, hi = room.shaft
            add("light", "light_%s_sun" % tag, room.shaft_area,
                [("origin", (cx, cy, hi[2] - 16)), ("light_radius", (w * 0.6, d * 0.6, z1 - z0 + SHAFT_HEIGHT)),
                 ("parallel", 1), ("light_center", (rng.int(-160, 160), rng.int(-160, 160), 480)),
                 ("_color", (1, 0.95, 0.85))])

        # Props: a stack in two corners, barrels and a console along walls, a table in the middle.
        spots = [((x0 + 56, y0 + 56, z0), "testmap_crate"), ((x1 - 56, y1 - 56, z0), "testmap_crate"),
                 ((x1 - 40, y0 + 40, z0), "largemap_barrel"), ((x0 + 40, y1 - 40, z0), "largemap_barrel"),
                 ((cx - 160 if w >= 640 else cx - 120, cy + 96, z0), "largemap_console")]
        if not room.shaft:
            spots.append(((cx, cy - 96, z0), "testmap_table"))
        for n, (origin, model) in enumerate(spots):
            assert model in prop_names
            add("func_static", "prop_%s_%d" % (tag, n), room.index,
                [("model", model), ("origin", origin), ("rotation", yaw_rotation(rng.int(0, 7) * 15))])
            props += 1
        add("func_static", "prop_%s_stack" % tag, room.index,
            [("model", "testmap_crate"), ("origin", (x0 + 56, y0 + 56, z0 + 48)),
             ("rotation", yaw_rotation(rng.int(1, 5) * 10))])
        props += 1

    for corridor in layout.corridors:
        lo, hi = corridor["lo"], corridor["hi"]
        axis = corridor["axis"]
        mid = [(lo[m] + hi[m]) * 0.5 for m in range(3)]
        tag = "%d_%d" % (corridor["a"].index, corridor["b"].index)
        radius = [0.0, 0.0, hi[2] - lo[2]]
        radius[axis] = (hi[axis] - lo[axis]) * 0.75
        radius[1 - axis] = 96
        colour = (1.0, 0.6, 0.3) if corridor["stairs"] else (0.7, 0.85, 1.0)
        for n, f in enumerate((0.3, 0.7)):
            origin = list(mid)
            origin[axis] = lo[axis] + (hi[axis] - lo[axis]) * f
            origin[2] = hi[2] - 16
            kind = ("plain", "nospec", "round", "scalar")[(corridor["index"] + n) % 4]
            add("light", "light_c%s_%d" % (tag, n), corridor["index"],
                _light_keys(rng, kind, tuple(origin), tuple(radius), colour))
    return ents, expected, props


# --- build -----------------------------------------------------------------------------------------

def build_large(seed=1, cols=6, rows=5, check_targets=True):
    from .textures import build_images
    layout = Layout(seed, cols, rows)
    grid = Grid(layout.areas, layout.solids)
    area_meshes, portal_faces = build_shell(grid, layout.material_for, texel_scale_for)
    portals = merge_portals(portal_faces)
    patches = []
    for room in layout.rooms:
        _room_detail(area_meshes[room.index], room, layout, patches)
    for corridor in layout.corridors:
        _corridor_detail(area_meshes[corridor["index"]], corridor)
    models = prop_models()
    nodes = build_nodes(grid)
    ents, expected, props = entities(layout, models)
    images = build_images()

    for mesh in area_meshes:
        for material, tags in mesh.tags.items():
            if len(tags) > 1:  # the checks tell shell from detail by material
                raise checks.CheckError("%s: material %s is used by shell and detail" % (mesh.name, material))
    entity_points = []
    for classname, keys in ents:
        values = dict(keys)
        o = values["origin"]
        entity_points.append((values["name"], (o[0], o[1], o[2] + 1), expected[values["name"]]))
    stats = checks.check_level(area_meshes, models, portals, nodes, grid, entity_points, images.keys())
    connected = {0}
    links = [(c["a"].index, c["b"].index) for c in layout.corridors]
    grew = True
    while grew:
        grew = False
        for a, b in links:
            if (a in connected) != (b in connected):
                connected |= {a, b}
                grew = True
    if len(connected) != len(layout.rooms):
        raise checks.CheckError("rooms not all connected: %d of %d" % (len(connected), len(layout.rooms)))

    def worldspawn(out):
        number = 0
        for room in layout.rooms:
            brush_text(out, number, (room.lo[0], room.lo[1], room.lo[2] - 16), (room.hi[0], room.hi[1], room.lo[2]),
                       room.theme[0])
            number += 1
        for material, control in patches:
            patch_text(out, number, material, control)
            number += 1

    files = {}
    name = MAP_NAME
    files["maps/%s.proc" % name] = proc_text(area_meshes, models, ((40, 40, 0), (88, 88, 48)), portals,
                                             nodes).encode("ascii")
    files["maps/%s.map" % name] = map_text(ents, worldspawn).encode("ascii")
    files["materials/testmap.mtr"] = materials.MTR.encode("ascii")
    for path, (image_rows, channels, rle) in images.items():
        files[path] = encode_tga(image_rows, channels, rle)

    lights = [dict(keys) for classname, keys in ents if classname == "light"]
    stats.update({
        "areas": len(area_meshes),
        "rooms": len(layout.rooms),
        "corridors": sum(1 for c in layout.corridors if not c["stairs"]),
        "stairwells": sum(1 for c in layout.corridors if c["stairs"]),
        "shafts": sum(1 for r in layout.rooms if r.shaft),
        "portals": len(portals),
        "nodes": len(nodes),
        "shell_triangles": sum(len(checks.shell_triangles(m)) for m in area_meshes),
        "area_triangles": sum(m.triangle_count() for m in area_meshes),
        "model_triangles": sum(m.triangle_count() for m in models),
        "inline_models": [m.name for m in models],
        "materials": materials.material_names(),
        "images": len(images),
        "lights": len(lights),
        "lights_point": sum(1 for l in lights if "light_target" not in l and "parallel" not in l),
        "lights_projected": sum(1 for l in lights if "light_target" in l),
        "lights_parallel": sum(1 for l in lights if "parallel" in l),
        "props": props,
        "entities": [(classname, dict(keys)["name"]) for classname, keys in ents],
        "patches": len(patches),
        "seed": seed,
        "size": (cols, rows),
    })
    if check_targets:
        for key, minimum in TARGETS.items():
            if stats[key] < minimum:
                raise checks.CheckError("large map has %d %s, the target is at least %d" % (stats[key], key, minimum))
    files["README.md"] = _readme(stats, layout, files).encode("utf-8")
    stats["bytes"] = sum(len(b) for b in files.values())
    return files, stats


def _readme(stats, layout, files):
    room = layout.rooms[0]
    lines = [
        "# Cohort large map (generated, not committed)",
        "",
        "Generated by `python3 tools/gen_testmap.py --large --seed %d --size %dx%d`; the same seed gives the"
        % (stats["seed"], stats["size"][0], stats["size"][1]),
        "same bytes. Laid out like a Doom 3 base folder; materials and textures are the test map's.",
        "",
        "- areas: %d (%d rooms, %d corridors, %d stairwells, %d skylight shafts), %d portals, %d nodes"
        % (stats["areas"], stats["rooms"], stats["corridors"], stats["stairwells"], stats["shafts"],
           stats["portals"], stats["nodes"]),
        "- world triangles: %d (%d of them the watertight shell), %d bezier patches"
        % (stats["area_triangles"], stats["shell_triangles"], stats["patches"]),
        "- lights: %d (%d point, %d projected, %d parallel)" % (stats["lights"], stats["lights_point"],
                                                                 stats["lights_projected"], stats["lights_parallel"]),
        "- props: %d func_static entities instancing %s" % (stats["props"],
                                                            ", ".join("`%s`" % m for m in stats["inline_models"])),
        "- player start in `room_0_0` at (%s)" % fmt_vec((room.lo[0] + 64, room.centre[1], room.lo[2] + 1)),
        "",
        "## Files",
        "",
    ]
    for path in sorted(files):
        lines.append("- `%s` (%d bytes)" % (path, len(files[path])))
    lines.append("")
    return "\n".join(lines)
