"""Self-checks run on every generation; any failure aborts with a message naming the problem."""
from collections import Counter

from . import materials
from .bsp import point_area
from .mesh import cross, dot, sub
from .numbers import fmt_vec


class CheckError(Exception):
    pass


def _key(p):
    return fmt_vec(p)


def _directed_edges(triangles):
    edges = Counter()
    for tri in triangles:
        keys = [_key(v[0]) for v in tri]
        for i in range(3):
            edges[(keys[i], keys[(i + 1) % 3])] += 1
    return edges


def shell_triangles(mesh):
    return [tri for material, tris in mesh.surfaces.items() if "shell" in mesh.tags[material] for tri in tris]


def check_winding(meshes):
    """Every triangle's (v1-v0)x(v2-v0) points against its stored normal (Doom 3: clockwise = front)."""
    for mesh in meshes:
        for material, tris in mesh.surfaces.items():
            for tri in tris:
                face = cross(sub(tri[1][0], tri[0][0]), sub(tri[2][0], tri[0][0]))
                if dot(face, tri[0][2]) >= 0:
                    raise CheckError("%s/%s: triangle %s is not clockwise from its front" % (mesh.name, material, tri))


def check_world_closed(area_meshes):
    """All areas' shells together form one closed, consistently wound surface: every directed edge
    appears once and its reverse once. This is what 'no cracks, no T-junctions' means here."""
    edges = _directed_edges([t for m in area_meshes for t in shell_triangles(m)])
    for (a, b), count in edges.items():
        if count != 1 or edges.get((b, a), 0) != 1:
            raise CheckError("world shell edge %s -> %s used %d times, reverse %d times"
                             % (a, b, count, edges.get((b, a), 0)))
    return len(edges) // 2


def _on_portal_boundary(p, q, portal):
    axis = portal["axis"]
    if abs(p[axis] - portal["plane"]) > 1e-6 or abs(q[axis] - portal["plane"]) > 1e-6:
        return False
    u, v = [a for a in range(3) if a != axis]
    lo_u, hi_u, lo_v, hi_v = portal["rect"]
    for coord, values in ((u, (lo_u, hi_u)), (v, (lo_v, hi_v))):
        for value in values:
            if abs(p[coord] - value) < 1e-6 and abs(q[coord] - value) < 1e-6:
                other = v if coord == u else u
                lo, hi = (lo_v, hi_v) if coord == u else (lo_u, hi_u)
                if lo - 1e-6 <= p[other] <= hi + 1e-6 and lo - 1e-6 <= q[other] <= hi + 1e-6:
                    return True
    return False


def check_area_shells(area_meshes, portals):
    """Within each area every shell edge is shared by exactly two triangles, except edges on the rim
    of one of that area's portal openings, which have one."""
    rim_edges = 0
    for index, mesh in enumerate(area_meshes):
        area_portals = [p for p in portals if index in (p["pos"], p["neg"])]
        undirected = Counter()
        positions = {}
        for tri in shell_triangles(mesh):
            for i in range(3):
                a, b = tri[i][0], tri[(i + 1) % 3][0]
                key = tuple(sorted((_key(a), _key(b))))
                undirected[key] += 1
                positions[key] = (a, b)
        for key, count in undirected.items():
            if count == 2:
                continue
            a, b = positions[key]
            if count == 1 and any(_on_portal_boundary(a, b, p) for p in area_portals):
                rim_edges += 1
                continue
            raise CheckError("%s: edge %s used by %d triangles and not on a portal rim" % (mesh.name, key, count))
    return rim_edges


def check_closed_models(meshes):
    """Props, door and fan are unions of closed boxes: each directed edge has as many reverse uses."""
    for mesh in meshes:
        edges = _directed_edges([t for tris in mesh.surfaces.values() for t in tris])
        for (a, b), count in edges.items():
            if edges.get((b, a), 0) != count:
                raise CheckError("%s: open edge %s -> %s" % (mesh.name, a, b))


def check_nodes(nodes, grid, entity_points):
    for cell, (kind, value) in grid.labels.items():
        expected = value if kind == "air" else -1
        got = point_area(nodes, grid.center(cell))
        if got != expected:
            raise CheckError("node tree puts cell %s (%s) in area %d" % (cell, kind, got))
    for name, point, expected in entity_points:
        got = point_area(nodes, point)
        if got != expected:
            raise CheckError("%s at %s falls in area %d, expected %d" % (name, point, got, expected))


def check_materials(meshes, material_names, image_paths, written_images):
    defined = set(material_names)
    for mesh in meshes:
        for material in mesh.surfaces:
            if material not in defined:
                raise CheckError("%s uses undefined material %s" % (mesh.name, material))
    missing = sorted(set(image_paths) - set(written_images))
    if missing:
        raise CheckError("materials reference images that are not generated: %s" % ", ".join(missing))


def check_shell_faces_air(area_meshes, nodes):
    """Each shell triangle's front (its normal side) looks into its own area's air, as the node tree
    sees it; its back is solid or another area. Catches inside-out walls."""
    for index, mesh in enumerate(area_meshes):
        for tri in shell_triangles(mesh):
            centre = [sum(v[0][m] for v in tri) / 3.0 for m in range(3)]
            normal = tri[0][2]
            front = tuple(centre[m] + 0.5 * normal[m] for m in range(3))
            back = tuple(centre[m] - 0.5 * normal[m] for m in range(3))
            if point_area(nodes, front) != index or point_area(nodes, back) == index:
                raise CheckError("%s: triangle at %s does not face into its area" % (mesh.name, front))


def check_level(area_meshes, models, portals, nodes, grid, entity_points, images):
    """Every check a generated level passes before it is written; returns the edge counts for its stats.

    entity_points: (name, point, expected area) per entity; images: the image paths being written.
    """
    stats = {}
    check_winding(area_meshes + models)
    stats["shell_edges"] = check_world_closed(area_meshes)
    stats["portal_rim_edges"] = check_area_shells(area_meshes, portals)
    check_closed_models(models)
    check_nodes(nodes, grid, entity_points)
    check_shell_faces_air(area_meshes, nodes)
    check_materials(area_meshes + models, materials.material_names(), materials.referenced_images(), images)
    return stats
