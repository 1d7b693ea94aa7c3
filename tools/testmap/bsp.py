"""Area node tree for the .proc `nodes` block.

Built over the labelled boxes (area air boxes, solids carved out of them) rather than single cells:
each node splits on a face of some box, preferring planes that cut the fewest boxes, until a region is
one area box with nothing carved from it (area leaf) or holds no air (solid leaf).
Node plane (a b c d) classifies point p by a*x + b*y + c*z + d > 0 -> child 0 (positive), else child 1.
Child 0 means solid, a negative child n means area -1-n, a positive child is a node index.
"""


def _clip(box_lo, box_hi, lo, hi):
    clo = tuple(max(box_lo[a], lo[a]) for a in range(3))
    chi = tuple(min(box_hi[a], hi[a]) for a in range(3))
    if all(clo[a] < chi[a] for a in range(3)):
        return clo, chi
    return None


def build_nodes(grid):
    areas = [(index, box.lo, box.hi) for index, box in enumerate(grid.areas)]
    solids = [(box.lo, box.hi) for box in grid.solids]
    world_lo = tuple(grid.lines[a][0] - 64.0 for a in range(3))
    world_hi = tuple(grid.lines[a][-1] + 64.0 for a in range(3))
    nodes = []

    def build(lo, hi):
        in_areas = [(i, c) for i, blo, bhi in areas for c in [_clip(blo, bhi, lo, hi)] if c]
        if not in_areas:
            return 0
        in_solids = [c for slo, shi in solids for c in [_clip(slo, shi, lo, hi)] if c]
        if len(in_areas) == 1 and not in_solids and in_areas[0][1] == (lo, hi):
            return -1 - in_areas[0][0]
        boxes = [c for _, c in in_areas] + in_solids
        best = None
        for axis in range(3):
            planes = sorted({b[0][axis] for b in boxes} | {b[1][axis] for b in boxes})
            for plane in planes:
                if not lo[axis] < plane < hi[axis]:
                    continue
                cut = sum(1 for b in boxes if b[0][axis] < plane < b[1][axis])
                below = sum(1 for b in boxes if b[1][axis] <= plane)
                above = sum(1 for b in boxes if b[0][axis] >= plane)
                score = (cut, abs(above - below), axis, plane)
                if best is None or score < best:
                    best = score
        if best is None:
            # Every box spans the whole region: a solid carved over it wins (solids beat air).
            return 0 if in_solids else -1 - in_areas[0][0]
        _, _, axis, plane = best
        index = len(nodes)
        normal = [0.0, 0.0, 0.0, -plane]
        normal[axis] = 1.0
        nodes.append([tuple(normal), None, None])
        upper_lo = list(lo)
        upper_lo[axis] = plane
        lower_hi = list(hi)
        lower_hi[axis] = plane
        nodes[index][1] = build(tuple(upper_lo), hi)
        nodes[index][2] = build(lo, tuple(lower_hi))
        return index

    build(world_lo, world_hi)
    return [(plane, pos, neg) for plane, pos, neg in nodes]


def point_area(nodes, point):
    """Area index of `point`, or -1 in solid (the engine's PointInArea)."""
    index = 0
    while True:
        plane, pos, neg = nodes[index]
        d = plane[0] * point[0] + plane[1] * point[1] + plane[2] * point[2] + plane[3]
        child = pos if d > 0 else neg
        if child == 0:
            return -1
        if child < 0:
            return -1 - child
        index = child
