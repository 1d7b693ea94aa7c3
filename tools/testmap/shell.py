"""World shell from boxes on one shared grid.

Areas are axis-aligned air boxes; solids (pillars, stairs, plinths) are boxes carved out of them.
Every coordinate of every box becomes a grid line on its axis, space is cut into cells, and the shell
is every cell face between air and non-air. Because all faces use the same grid, neighbouring quads
share their edges and vertices exactly: no cracks, no T-junctions, and openings between areas
(portals) line up vertex for vertex on both sides.
"""
from .mesh import Mesh

AXES = ("x", "y", "z")


class Box:
    def __init__(self, name, lo, hi, **props):
        self.name = name
        self.lo = tuple(float(v) for v in lo)
        self.hi = tuple(float(v) for v in hi)
        self.props = props

    def contains(self, p):
        return all(self.lo[i] < p[i] < self.hi[i] for i in range(3))


class Grid:
    def __init__(self, areas, solids):
        self.areas = areas
        self.solids = solids
        self.lines = []
        for axis in range(3):
            values = set()
            for box in list(areas) + list(solids):
                values.add(box.lo[axis])
                values.add(box.hi[axis])
            self.lines.append(sorted(values))
        self.shape = tuple(len(lines) - 1 for lines in self.lines)
        # Rasterise boxes onto the cells (every box edge is a grid line, so a box covers whole cells):
        # solids first, then areas in index order, first writer wins; the same answer as _classify
        # at every cell centre, but linear in the boxes' cell counts (the large map has ~10^5 cells).
        index = [{value: i for i, value in enumerate(lines)} for lines in self.lines]
        labels = {}
        for box, label in ([(s, ("solid", s.name)) for s in solids] +
                           [(a, ("air", i)) for i, a in enumerate(areas)]):
            ranges = [range(index[a][box.lo[a]], index[a][box.hi[a]]) for a in range(3)]
            for i in ranges[0]:
                for j in ranges[1]:
                    for k in ranges[2]:
                        labels.setdefault((i, j, k), label)
        self.labels = {}
        for i in range(self.shape[0]):
            for j in range(self.shape[1]):
                for k in range(self.shape[2]):
                    self.labels[(i, j, k)] = labels.get((i, j, k), ("solid", "void"))

    def center(self, cell):
        return tuple((self.lines[a][cell[a]] + self.lines[a][cell[a] + 1]) * 0.5 for a in range(3))

    def _classify(self, p):
        """('air', area index) or ('solid', solid name or 'void')."""
        for solid in self.solids:
            if solid.contains(p):
                return ("solid", solid.name)
        for index, area in enumerate(self.areas):
            if area.contains(p):
                return ("air", index)
        return ("solid", "void")

    def label(self, cell):
        if any(c < 0 or c >= self.shape[a] for a, c in enumerate(cell)):
            return ("solid", "void")
        return self.labels[cell]


def face_corners(grid, cell, axis, positive):
    """The four corners of a cell's face on `axis` (plane at the cell's upper side if `positive`)."""
    u, v = [a for a in range(3) if a != axis]
    plane = grid.lines[axis][cell[axis] + (1 if positive else 0)]
    corners = []
    for du, dv in ((0, 0), (1, 0), (1, 1), (0, 1)):
        p = [0.0, 0.0, 0.0]
        p[axis] = plane
        p[u] = grid.lines[u][cell[u] + du]
        p[v] = grid.lines[v][cell[v] + dv]
        corners.append(tuple(p))
    return corners


def build_shell(grid, material_for, texel_scale_for=lambda material: 128.0):
    """Returns (area meshes, portal faces).

    material_for(area_index, inward_normal, solid_name) -> material name; texel_scale_for(material) ->
    world units per texture repeat.
    Portal faces: {(area_a, area_b, axis, plane): {"faces": [corner lists], "a_below": bool}} with
    area_a < area_b; a_below says area_a lies on the lower-coordinate side of the plane.
    """
    meshes = [Mesh("_area%d" % i) for i in range(len(grid.areas))]
    portals = {}
    for cell, (kind, area) in sorted(grid.labels.items()):
        if kind != "air":
            continue
        for axis in range(3):
            for positive in (False, True):
                neighbour = list(cell)
                neighbour[axis] += 1 if positive else -1
                other_kind, other = grid.label(tuple(neighbour))
                corners = face_corners(grid, cell, axis, positive)
                if other_kind == "air":
                    if other != area:
                        key = (min(area, other), max(area, other), axis, corners[0][axis])
                        if area < other:
                            entry = portals.setdefault(key, {"faces": [], "a_below": positive})
                            entry["faces"].append(corners)
                    continue
                normal = [0.0, 0.0, 0.0]
                normal[axis] = -1.0 if positive else 1.0
                normal = tuple(normal)
                material = material_for(area, normal, other)
                meshes[area].add_polygon(material, corners, normal, texel_scale=texel_scale_for(material),
                                         tag="shell")
    return meshes, portals
