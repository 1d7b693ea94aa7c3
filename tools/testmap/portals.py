"""Merges the grid's portal faces into one convex rectangle per pair of touching areas."""


def merge_portals(portal_faces):
    portals = []
    for (area_a, area_b, axis, plane), entry in sorted(portal_faces.items()):
        faces = entry["faces"]
        u, v = [a for a in range(3) if a != axis]
        lo_u = min(c[u] for f in faces for c in f)
        hi_u = max(c[u] for f in faces for c in f)
        lo_v = min(c[v] for f in faces for c in f)
        hi_v = max(c[v] for f in faces for c in f)
        covered = 0.0
        for f in faces:
            covered += (max(c[u] for c in f) - min(c[u] for c in f)) * (max(c[v] for c in f) - min(c[v] for c in f))
        if abs(covered - (hi_u - lo_u) * (hi_v - lo_v)) > 1e-6:
            raise ValueError("portal between areas %d and %d is not one rectangle" % (area_a, area_b))

        def point(pu, pv):
            p = [0.0, 0.0, 0.0]
            p[axis] = plane
            p[u] = pu
            p[v] = pv
            return tuple(p)

        corners = [point(lo_u, lo_v), point(hi_u, lo_v), point(hi_u, hi_v), point(lo_u, hi_v)]
        # The positive area is area_a. The engine's plane of a winding is (p1-c) x (p0-c) and a viewer in
        # the positive area must be on its front, so the winding runs clockwise seen from area_a.
        pos_side = -1.0 if entry["a_below"] else 1.0
        normal = _winding_plane_normal(corners)
        if normal[axis] * pos_side < 0:
            corners.reverse()
        portals.append({"pos": area_a, "neg": area_b, "points": corners, "axis": axis, "plane": plane,
                        "rect": (lo_u, hi_u, lo_v, hi_v)})
    return portals



def _winding_plane_normal(points):
    cx = sum(p[0] for p in points) / len(points)
    cy = sum(p[1] for p in points) / len(points)
    cz = sum(p[2] for p in points) / len(points)
    v1 = (points[0][0] - cx, points[0][1] - cy, points[0][2] - cz)
    v2 = (points[1][0] - cx, points[1][1] - cy, points[1][2] - cz)
    return (v2[1] * v1[2] - v2[2] * v1[1], v2[2] * v1[0] - v2[0] * v1[2], v2[0] * v1[1] - v2[1] * v1[0])
