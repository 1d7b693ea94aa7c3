"""Triangle meshes grouped by material, with Doom 3's winding: clockwise seen from the front, i.e.
(v1 - v0) x (v2 - v0) points against the stored normal."""


def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def planar_st(point, normal, texel_scale):
    """World-aligned projection so neighbouring faces of one wall continue the same texture."""
    x, y, z = point
    ax = max(range(3), key=lambda i: abs(normal[i]))
    if ax == 2:
        s, t = x, -y
    elif ax == 0:
        s, t = y, -z
    else:
        s, t = x, -z
    return (s / texel_scale, t / texel_scale)


class Mesh:
    """Surfaces keyed by material in insertion order; each a list of triangles of (pos, st, normal)."""

    def __init__(self, name):
        self.name = name
        self.surfaces = {}
        self.tags = {}  # material -> set of tags ("shell", "detail") for the checks

    def add_triangle(self, material, verts, tag="detail"):
        self.surfaces.setdefault(material, []).append(verts)
        self.tags.setdefault(material, set()).add(tag)

    def add_polygon(self, material, points, normal, st=None, texel_scale=128.0, tag="detail"):
        """Convex polygon, fanned from point 0; winding fixed up to face `normal`."""
        if st is None:
            st = [planar_st(p, normal, texel_scale) for p in points]
        for i in range(1, len(points) - 1):
            tri = [0, i, i + 1]
            face = cross(sub(points[tri[1]], points[tri[0]]), sub(points[tri[2]], points[tri[0]]))
            if dot(face, normal) > 0:
                tri = [0, i + 1, i]
            self.add_triangle(material, [(points[k], st[k], normal) for k in tri], tag)

    def triangle_count(self):
        return sum(len(tris) for tris in self.surfaces.values())

    def translated(self, offset):
        out = Mesh(self.name)
        for material, tris in self.surfaces.items():
            for tri in tris:
                moved = [((p[0] + offset[0], p[1] + offset[1], p[2] + offset[2]), st, n) for p, st, n in tri]
                out.add_triangle(material, moved)
        return out


def add_box(mesh, material, lo, hi, texel_scale=64.0, inward=False, faces=None, tag="detail"):
    """Closed axis-aligned box (normals outward unless `inward`); `faces` limits to e.g. {"+z", "-x"}."""
    x0, y0, z0 = lo
    x1, y1, z1 = hi
    quads = {
        "-x": ([(x0, y0, z0), (x0, y1, z0), (x0, y1, z1), (x0, y0, z1)], (-1, 0, 0)),
        "+x": ([(x1, y0, z0), (x1, y1, z0), (x1, y1, z1), (x1, y0, z1)], (1, 0, 0)),
        "-y": ([(x0, y0, z0), (x1, y0, z0), (x1, y0, z1), (x0, y0, z1)], (0, -1, 0)),
        "+y": ([(x0, y1, z0), (x1, y1, z0), (x1, y1, z1), (x0, y1, z1)], (0, 1, 0)),
        "-z": ([(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0)], (0, 0, -1)),
        "+z": ([(x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)], (0, 0, 1)),
    }
    for key in ("-x", "+x", "-y", "+y", "-z", "+z"):
        if faces is not None and key not in faces:
            continue
        points, normal = quads[key]
        if inward:
            normal = (-normal[0], -normal[1], -normal[2])
        mesh.add_polygon(material, points, normal, texel_scale=texel_scale, tag=tag)
