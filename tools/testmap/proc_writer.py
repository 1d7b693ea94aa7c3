"""Writes the .proc (mapProcFile003) text: models, one shadowModel, interAreaPortals, nodes."""
from .numbers import fmt, fmt_vec


def surface_arrays(triangles):
    """Dedupe vertices of one surface; returns (vertices, indices) in first-use order."""
    index_of = {}
    vertices = []
    indices = []
    for tri in triangles:
        for pos, st, normal in tri:
            key = (fmt_vec(pos), fmt_vec(st), fmt_vec(normal))
            if key not in index_of:
                index_of[key] = len(vertices)
                vertices.append(key)
            indices.append(index_of[key])
    return vertices, indices


def write_model(out, mesh):
    out.append('model { /* name = */ "%s" /* numSurfaces = */ %d\n' % (mesh.name, len(mesh.surfaces)))
    for number, (material, triangles) in enumerate(mesh.surfaces.items()):
        vertices, indices = surface_arrays(triangles)
        out.append('/* surface %d */ { "%s" /* numVerts = */ %d /* numIndexes = */ %d\n'
                   % (number, material, len(vertices), len(indices)))
        for k in range(0, len(vertices), 3):
            out.append(" ".join("( %s %s %s )" % v for v in vertices[k:k + 3]) + "\n")
        for k in range(0, len(indices), 12):
            out.append(" ".join(str(i) for i in indices[k:k + 12]) + "\n")
        out.append("}\n")
    out.append("}\n\n")


def write_shadow_model(out, name, lo, hi):
    """A closed box as a shadow volume; renderers that trace rays skip these blocks."""
    x0, y0, z0 = lo
    x1, y1, z1 = hi
    corners = [(x, y, z) for z in (z0, z1) for y in (y0, y1) for x in (x0, x1)]
    quads = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    indices = []
    for a, b, c, d in quads:
        indices += [a, b, c, a, c, d]
    out.append('shadowModel { /* name = */ "%s"\n\n' % name)
    out.append("/* numVerts = */ %d /* noCaps = */ %d /* noFrontCaps = */ %d /* numIndexes = */ %d "
               "/* planeBits = */ %d\n" % (len(corners), 0, 0, len(indices), 0))
    for k in range(0, len(corners), 4):
        out.append(" ".join("( %s )" % fmt_vec(c) for c in corners[k:k + 4]) + "\n")
    out.append(" ".join(str(i) for i in indices) + "\n")
    out.append("}\n\n")


def write_portals(out, num_areas, portals):
    out.append("interAreaPortals { /* numAreas = */ %d /* numIAP = */ %d\n\n" % (num_areas, len(portals)))
    out.append("/* interAreaPortal format is: numPoints positiveSideArea negativeSideArea ( point) ... */\n")
    for number, portal in enumerate(portals):
        out.append("/* iap %d */ %d %d %d %s\n" % (
            number, len(portal["points"]), portal["pos"], portal["neg"],
            " ".join("( %s )" % fmt_vec(p) for p in portal["points"])))
    out.append("}\n\n")


def write_nodes(out, nodes):
    out.append("nodes { /* numNodes = */ %d\n\n" % len(nodes))
    out.append("/* node format is: ( planeVector ) positiveChild negativeChild */\n")
    out.append("/* a child number of 0 is an opaque, solid area */\n")
    out.append("/* negative child numbers are areas: (-1-child) */\n")
    for number, (plane, pos, neg) in enumerate(nodes):
        out.append("/* node %d */ ( %s ) %d %d\n" % (number, fmt_vec(plane), pos, neg))
    out.append("}\n\n")


def proc_text(area_meshes, inline_meshes, shadow_box, portals, nodes):
    out = ["mapProcFile003\n\n"]
    for mesh in list(area_meshes) + list(inline_meshes):
        write_model(out, mesh)
    write_shadow_model(out, "_prelight_light_hall_crate_1", *shadow_box)
    write_portals(out, len(area_meshes), portals)
    write_nodes(out, nodes)
    return "".join(out)
