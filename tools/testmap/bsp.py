"""Area node tree for the .proc `nodes` block, built over the shell grid.

Splits on grid lines until a block of cells is uniformly one area or solid. Node plane (a b c d)
classifies point p by a*x + b*y + c*z + d > 0 -> child 0 (positive), else child 1. Child 0 means solid,
a negative child n means area -1-n, a positive child is a node index.
"""


def _uniform(grid, lo, hi):
    first = None
    for i in range(lo[0], hi[0]):
        for j in range(lo[1], hi[1]):
            for k in range(lo[2], hi[2]):
                kind, value = grid.labels[(i, j, k)]
                label = -1 - value if kind == "air" else 0
                if first is None:
                    first = label
                elif label != first:
                    return None
    return first


def build_nodes(grid):
    nodes = []  # each: [plane tuple, positive child, negative child]

    def build(lo, hi):
        label = _uniform(grid, lo, hi)
        if label is not None:
            return label
        axis = max(range(3), key=lambda a: hi[a] - lo[a])
        mid = (lo[axis] + hi[axis]) // 2
        index = len(nodes)
        plane = [0.0, 0.0, 0.0, 0.0]
        plane[axis] = 1.0
        plane[3] = -grid.lines[axis][mid]
        nodes.append([tuple(plane), None, None])
        upper_lo = list(lo)
        upper_lo[axis] = mid
        lower_hi = list(hi)
        lower_hi[axis] = mid
        nodes[index][1] = build(tuple(upper_lo), hi)
        nodes[index][2] = build(lo, tuple(lower_hi))
        return index

    root = build((0, 0, 0), grid.shape)
    if root <= 0 and not nodes:
        raise ValueError("world is a single leaf; need at least one split")
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
