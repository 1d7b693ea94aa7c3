"""Writes the .map (Version 2). Worldspawn carries a few brushDef3 brushes and a patchDef2 so parsers
must cope with primitives; the rendered geometry comes from the .proc."""
from .numbers import fmt, fmt_vec

TEXMAT = "( ( 0.0078125 0 0 ) ( 0 0.0078125 0 ) )"


def _value(value):
    if isinstance(value, str):
        return value
    if isinstance(value, (tuple, list)):
        return fmt_vec(value)
    return fmt(value)


def _brush(out, number, lo, hi, material):
    """Box brush: six outward planes (a b c d) with a*x + b*y + c*z + d = 0."""
    out.append("// primitive %d\n{\n brushDef3\n {\n" % number)
    planes = [((0, 0, -1), lo[2]), ((0, 0, 1), -hi[2]), ((0, -1, 0), lo[1]), ((1, 0, 0), -hi[0]),
              ((0, 1, 0), -hi[1]), ((-1, 0, 0), lo[0])]
    for normal, d in planes:
        out.append('  ( %s %s ) %s "%s" 0 0 0\n' % (fmt_vec(normal), fmt(d), TEXMAT, material))
    out.append(" }\n}\n")


def _patch(out, number, material):
    """A 3x3 bezier patch (an arch over the hall's west door frame)."""
    out.append("// primitive %d\n{\n patchDef2\n {\n  \"%s\"\n  ( 3 3 0 0 0 )\n  (\n" % (number, material))
    for column, x in enumerate((8, 8, 8)):
        row = []
        for k, (y, z) in enumerate(((160, 96), (192, 128), (224, 96))):
            zz = z + 8 * column
            row.append("( %s %s %s %s %s )" % (fmt(x + 4 * column), fmt(y), fmt(zz), fmt(k * 0.5), fmt(column * 0.5)))
        out.append("   ( %s )\n" % " ".join(row))
    out.append("  )\n }\n}\n")


def _testmap_worldspawn(out):
    # Brushes outlining the hall's floor and west wall, and the atrium floor (editor data only).
    _brush(out, 0, (0, 0, -16), (512, 384, 0), "textures/testmap/floor_tiles")
    _brush(out, 1, (-16, 0, 0), (0, 384, 160), "textures/testmap/wall_bricks")
    _brush(out, 2, (768, 0, -16), (1152, 384, 0), "textures/testmap/floor_tiles")
    _patch(out, 3, "textures/testmap/metal")


def patch_text(out, number, material, control):
    """patchDef2 of a control grid: control[column][row] = (x, y, z, s, t)."""
    out.append("// primitive %d\n{\n patchDef2\n {\n  \"%s\"\n  ( %d %d 0 0 0 )\n  (\n"
               % (number, material, len(control), len(control[0])))
    for column in control:
        out.append("   ( %s )\n" % " ".join("( %s )" % fmt_vec(point) for point in column))
    out.append("  )\n }\n}\n")


def brush_text(out, number, lo, hi, material):
    _brush(out, number, lo, hi, material)


def map_text(entities, worldspawn=_testmap_worldspawn):
    """`worldspawn(out)` appends the world entity's primitives (editor data: the .proc has the geometry)."""
    out = ["Version 2\n"]
    out.append("// entity 0\n{\n\"classname\" \"worldspawn\"\n\"name\" \"world\"\n")
    worldspawn(out)
    out.append("}\n")
    for number, (classname, keys) in enumerate(entities, start=1):
        out.append("// entity %d\n{\n\"classname\" \"%s\"\n" % (number, classname))
        for key, value in keys:
            out.append('"%s" "%s"\n' % (key, _value(value)))
        out.append("}\n")
    return "".join(out)
