"""The test map's model files, generated: an ASE prop (two objects, a sub-material list, normals, vertex
colours), an LWO2 prop (two surfaces, a TXUV map with a per-polygon VMAD override, an RGBA colour map, smoothing angle) and an
MD5 character (a boxy walker: md5mesh plus a looping walk md5anim). Everything is exact small numbers,
so the bytes are the same on every run. Formats as the engine reads them (doom3-content.md section 4-5).
"""
import math
import struct

from .numbers import fmt

ASE_PATH = "models/testmap/lamp.ase"
LWO_PATH = "models/testmap/wedge.lwo"
MD5MESH_PATH = "models/testmap/walker.md5mesh"
MD5ANIM_PATH = "models/testmap/walker_walk.md5anim"
WALKER_MATERIAL = "models/testmap/walker"


def _f(value):
    return "%.4f" % round(float(value), 4)


# --- ASE ------------------------------------------------------------------------------------------------

def _prism(sides, radius, z0, z1):
    """Vertices and faces (Max order: counter-clockwise seen from outside) of a closed n-gon prism."""
    verts = []
    for z in (z0, z1):
        for k in range(sides):
            a = 2 * math.pi * k / sides
            verts.append((round(radius * math.cos(a), 4), round(radius * math.sin(a), 4), z))
    faces = []
    for k in range(sides):
        b0, b1, t0, t1 = k, (k + 1) % sides, sides + k, sides + (k + 1) % sides
        faces.append((b0, b1, t1))
        faces.append((b0, t1, t0))
    for k in range(1, sides - 1):
        faces.append((0, k + 1, k))                        # bottom, facing -z
        faces.append((sides, sides + k, sides + k + 1))    # top, facing +z
    return verts, faces


def _ase_object(out, name, verts, faces, material_ref, colors):
    out.append('*GEOMOBJECT {\n\t*NODE_NAME "%s"\n\t*NODE_TM {\n\t\t*NODE_NAME "%s"\n' % (name, name))
    for r, row in enumerate(((1, 0, 0), (0, 1, 0), (0, 0, 1), (0, 0, 0))):
        out.append("\t\t*TM_ROW%d %s\n" % (r, "\t".join(_f(v) for v in row)))
    out.append("\t}\n\t*MESH {\n\t\t*TIMEVALUE 0\n")
    out.append("\t\t*MESH_NUMVERTEX %d\n\t\t*MESH_NUMFACES %d\n\t\t*MESH_VERTEX_LIST {\n" % (len(verts), len(faces)))
    for i, v in enumerate(verts):
        out.append("\t\t\t*MESH_VERTEX %5d\t%s\n" % (i, "\t".join(_f(c) for c in v)))
    out.append("\t\t}\n\t\t*MESH_FACE_LIST {\n")
    for i, (a, b, c) in enumerate(faces):
        out.append("\t\t\t*MESH_FACE %5d:    A: %5d B: %5d C: %5d AB:    1 BC:    1 CA:    1\t *MESH_SMOOTHING 1 \t"
                   "*MESH_MTLID 0\n" % (i, a, b, c))
    out.append("\t\t}\n")
    # Texture vertices: cylindrical u from the angle, v from height (one per vertex, shared by faces).
    out.append("\t\t*MESH_NUMTVERTEX %d\n\t\t*MESH_TVERTLIST {\n" % len(verts))
    zmin = min(v[2] for v in verts)
    zmax = max(v[2] for v in verts)
    for i, (x, y, z) in enumerate(verts):
        u = (math.atan2(y, x) / (2 * math.pi)) % 1.0
        out.append("\t\t\t*MESH_TVERT %d\t%s\t%s\t0.0000\n" % (i, _f(u), _f((z - zmin) / (zmax - zmin))))
    out.append("\t\t}\n\t\t*MESH_NUMTVFACES %d\n\t\t*MESH_TFACELIST {\n" % len(faces))
    for i, (a, b, c) in enumerate(faces):
        out.append("\t\t\t*MESH_TFACE %d\t%d\t%d\t%d\n" % (i, a, b, c))
    out.append("\t\t}\n")
    if colors:
        out.append("\t\t*MESH_NUMCVERTEX %d\n\t\t*MESH_CVERTLIST {\n" % len(verts))
        for i, v in enumerate(verts):
            shade = 0.5 + 0.5 * (v[2] - zmin) / (zmax - zmin)
            out.append("\t\t\t*MESH_VERTCOL %d\t%s\t%s\t%s\n" % (i, _f(shade), _f(shade * 0.9), _f(shade * 0.7)))
        out.append("\t\t}\n\t\t*MESH_NUMCVFACES %d\n\t\t*MESH_CFACELIST {\n" % len(faces))
        for i, (a, b, c) in enumerate(faces):
            out.append("\t\t\t*MESH_CFACE %d\t%d\t%d\t%d\n" % (i, a, b, c))
        out.append("\t\t}\n")
    # Normals: flat face normals, and per corner the face normal too (a faceted look, as exported).
    out.append("\t\t*MESH_NORMALS {\n")
    for i, (a, b, c) in enumerate(faces):
        p0, p1, p2 = verts[a], verts[b], verts[c]
        e1 = [p1[k] - p0[k] for k in range(3)]
        e2 = [p2[k] - p0[k] for k in range(3)]
        n = (e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0])
        length = math.sqrt(sum(x * x for x in n))
        n = tuple(x / length for x in n)
        out.append("\t\t\t*MESH_FACENORMAL %d\t%s\n" % (i, "\t".join(_f(x) for x in n)))
        for v in (a, b, c):
            out.append("\t\t\t\t*MESH_VERTEXNORMAL %d\t%s\n" % (v, "\t".join(_f(x) for x in n)))
    out.append("\t\t}\n\t}\n\t*PROP_MOTIONBLUR 0\n\t*PROP_CASTSHADOW 1\n\t*PROP_RECVSHADOW 1\n")
    out.append("\t*MATERIAL_REF %d\n}\n" % material_ref)


def _ase_material(out, number, name, bitmaps):
    out.append('\t*MATERIAL %d {\n\t\t*MATERIAL_NAME "%s"\n\t\t*MATERIAL_CLASS "Standard"\n' % (number, name))
    if len(bitmaps) == 1:
        bitmap_blocks = [("\t\t", bitmaps[0])]
    else:
        out.append("\t\t*NUMSUBMTLS %d\n" % len(bitmaps))
        bitmap_blocks = []
    for index, bitmap in enumerate(bitmaps if len(bitmaps) > 1 else []):
        out.append('\t\t*SUBMATERIAL %d {\n\t\t\t*MATERIAL_NAME "%s_sub%d"\n' % (index, name, index))
        _ase_diffuse(out, "\t\t\t", bitmap)
        out.append("\t\t}\n")
    for indent, bitmap in bitmap_blocks:
        _ase_diffuse(out, indent, bitmap)
    out.append("\t}\n")


def _ase_diffuse(out, indent, bitmap):
    out.append('%s*MAP_DIFFUSE {\n%s\t*MAP_NAME "diffuse"\n%s\t*BITMAP "%s"\n' % (indent, indent, indent, bitmap))
    for key, value in (("UVW_U_OFFSET", 0), ("UVW_V_OFFSET", 0), ("UVW_U_TILING", 1), ("UVW_V_TILING", 2),
                       ("UVW_ANGLE", 0)):
        out.append("%s\t*%s %s\n" % (indent, key, _f(value)))
    out.append("%s}\n" % indent)


def ase_text():
    """A standing lamp: a metal octagonal post with vertex colours (its material `vertexColor`), and a wooden cap whose material is a
    multi/sub-object list (the engine takes the last sub-material's bitmap: wood)."""
    out = ["*3DSMAX_ASCIIEXPORT\t200\n", '*COMMENT "Cohort test map prop, generated by tools/gen_testmap.py"\n']
    out.append('*SCENE {\n\t*SCENE_FILENAME "lamp.max"\n\t*SCENE_FIRSTFRAME 0\n\t*SCENE_LASTFRAME 100\n}\n')
    out.append("*MATERIAL_LIST {\n\t*MATERIAL_COUNT 2\n")
    _ase_material(out, 0, "post", ["C:\\doom3\\base\\textures\\testmap\\lamppost.tga"])
    _ase_material(out, 1, "cap", ["C:\\doom3\\base\\textures\\testmap\\crate.tga",
                                  "C:\\doom3\\base\\textures\\testmap\\wood.tga"])
    out.append("}\n")
    verts, faces = _prism(8, 4, 0, 56)
    _ase_object(out, "post", verts, faces, 0, colors=True)
    verts, faces = _prism(8, 14, 56, 64)
    _ase_object(out, "cap", verts, faces, 1, colors=False)
    return "".join(out)


# --- LWO2 -----------------------------------------------------------------------------------------------

def _chunk(tag, payload):
    data = tag.encode("ascii") + struct.pack(">I", len(payload)) + payload
    return data + (b"\0" if len(payload) % 2 else b"")


def _s0(text):
    data = text.encode("ascii") + b"\0"
    return data + (b"\0" if len(data) % 2 else b"")


def _subchunk(tag, payload):
    return tag.encode("ascii") + struct.pack(">H", len(payload)) + payload


def lwo_bytes():
    """A wedge (triangular prism lying on its side), in LightWave axes (y up): crate sides, metal ends.
    Two layers: the second (a stray triangle far away) must be ignored as the engine does."""
    # LightWave (x, y, z) = idTech (x, z, y): height along LW y.
    points = [(-16, 0, -12), (16, 0, -12), (16, 0, 12), (-16, 0, 12), (-16, 24, 0), (16, 24, 0)]
    # Triangles in LightWave order (the engine keeps it; the y/z swap makes it idTech clockwise-front).
    crate_tris = [(0, 1, 2), (0, 2, 3), (0, 4, 5), (0, 5, 1), (3, 2, 5), (3, 5, 4)]
    metal_tris = [(0, 3, 4), (1, 5, 2)]
    tags = ["textures/testmap/crate", "textures/testmap/metal"]
    pols = b"FACE"
    ptag = b"SURF"
    polygons = [(t, 0) for t in crate_tris] + [(t, 1) for t in metal_tris]
    for index, (tri, tag) in enumerate(polygons):
        pols += struct.pack(">H", 3) + b"".join(struct.pack(">H", p) for p in tri)
        ptag += struct.pack(">HH", index, tag)
    uv = b"TXUV" + struct.pack(">H", 2) + _s0("txuv01")
    for index, (x, y, z) in enumerate(points):
        uv += struct.pack(">Hff", index, (x + 16) / 32.0, y / 24.0)
    # Vertex colours (an RGBA map): darker at the foot, as a baked ambient occlusion would be. The wedge's
    # materials do not say vertexColor, so they do not show; the map exercises the reader on a real file.
    rgba = b"RGBA" + struct.pack(">H", 4) + _s0("shade")
    for index, (x, y, z) in enumerate(points):
        shade = 0.5 + 0.5 * y / 24.0
        rgba += struct.pack(">Hffff", index, shade, shade, shade * 0.9, 1.0)
    vmad = b"TXUV" + struct.pack(">H", 2) + _s0("txuv01")
    # The end caps get their own mapping on the polygon corners (VMAD overrides VMAP).
    for poly_index in (6, 7):
        for corner, point in enumerate(polygons[poly_index][0]):
            vmad += struct.pack(">HHff", point, poly_index, (0.0, 1.0, 0.5)[corner], (0.0, 0.0, 1.0)[corner])
    surfs = b""
    for name, color, sman in ((tags[0], (0.9, 0.8, 0.7), 0.0), (tags[1], (0.78431, 0.78431, 0.78431), 1.0)):
        body = _s0(name) + _s0("")
        body += _subchunk("COLR", struct.pack(">fffH", color[0], color[1], color[2], 0))
        body += _subchunk("SMAN", struct.pack(">f", sman))
        body += _subchunk("SIDE", struct.pack(">H", 1))
        surfs += _chunk("SURF", body)
    body = b"LWO2"
    body += _chunk("TAGS", b"".join(_s0(t) for t in tags))
    body += _chunk("LAYR", struct.pack(">HH", 0, 0) + struct.pack(">fff", 0, 0, 0) + _s0("wedge"))
    body += _chunk("PNTS", b"".join(struct.pack(">fff", *p) for p in points))
    body += _chunk("BBOX", struct.pack(">ffffff", -16, 0, -12, 16, 24, 12))
    body += _chunk("VMAP", uv)
    body += _chunk("VMAP", rgba)
    body += _chunk("POLS", pols)
    body += _chunk("PTAG", ptag)
    body += _chunk("VMAD", vmad)
    body += _chunk("LAYR", struct.pack(">HH", 1, 0) + struct.pack(">fff", 0, 0, 0) + _s0("ignored"))
    body += _chunk("PNTS", struct.pack(">fffffffff", 500, 0, 0, 501, 0, 0, 500, 1, 0))
    body += _chunk("POLS", b"FACE" + struct.pack(">HHHH", 3, 0, 1, 2))
    body += surfs
    return b"FORM" + struct.pack(">I", len(body)) + body


# --- MD5 ------------------------------------------------------------------------------------------------
# Joints (model space, bind pose = identity rotations): origin, pelvis, torso, head, thighs, shins.
WALKER_JOINTS = [
    ("origin", -1, (0, 0, 0)),
    ("pelvis", 0, (0, 0, 36)),
    ("torso", 1, (0, 0, 44)),
    ("head", 2, (0, 0, 64)),
    ("thigh_l", 1, (0, 6, 36)),
    ("shin_l", 4, (0, 6, 18)),
    ("thigh_r", 1, (0, -6, 36)),
    ("shin_r", 6, (0, -6, 18)),
]

# Boxes (joint, lo, hi) in model space; each box's vertices hang on its joint.
WALKER_BOXES = [
    (2, (-6, -10, 38), (6, 10, 62)),     # torso, bottom corners shared with the pelvis
    (3, (-5, -5, 62), (5, 5, 72)),       # head
    (4, (-3, 3, 18), (3, 9, 36)),        # thighs
    (5, (-3, 3, 0), (4, 9, 18)),         # shins (a toe: 1 unit forward)
    (6, (-3, -9, 18), (3, -3, 36)),
    (7, (-3, -9, 0), (4, -3, 18)),
]


def _box_triangles():
    """Index triples into a box's 8 corners (bit 0 x, bit 1 y, bit 2 z), clockwise seen from outside."""
    quads = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    tris = []
    for a, b, c, d in quads:     # each quad listed counter-clockwise from outside: reverse for clockwise
        tris.append((a, c, b))
        tris.append((a, d, c))
    return tris


def md5mesh_text():
    out = ["MD5Version 10\n", 'commandline "generated by tools/gen_testmap.py"\n\n',
           "numJoints %d\nnumMeshes 1\n\njoints {\n" % len(WALKER_JOINTS)]
    for name, parent, pos in WALKER_JOINTS:
        out.append('\t"%s"\t%d ( %s ) ( 0 0 0 )\n' % (name, parent, " ".join(fmt(v) for v in pos)))
    out.append("}\n\nmesh {\n\tshader \"%s\"\n" % WALKER_MATERIAL)
    verts, tris, weights = [], [], []
    for joint, lo, hi in WALKER_BOXES:
        base = len(verts)
        jpos = WALKER_JOINTS[joint][2]
        for corner in range(8):
            p = (hi[0] if corner & 1 else lo[0], hi[1] if corner & 2 else lo[1], hi[2] if corner & 4 else lo[2])
            st = ((corner & 1) * 0.5 + (corner >> 2) * 0.5, 1.0 - ((corner >> 1) & 1))
            influences = [(joint, 1.0)]
            if joint == 2 and not corner & 4:        # torso bottom: half pelvis, half torso
                influences = [(1, 0.5), (2, 0.5)]
            verts.append((st, len(weights), len(influences)))
            for j, bias in influences:
                jp = WALKER_JOINTS[j][2]
                weights.append((j, bias, tuple(p[k] - jp[k] for k in range(3))))
        for a, b, c in _box_triangles():
            tris.append((base + a, base + b, base + c))
        del jpos
    out.append("\n\tnumverts %d\n" % len(verts))
    for i, (st, first, count) in enumerate(verts):
        out.append("\tvert %d ( %s %s ) %d %d\n" % (i, fmt(st[0]), fmt(st[1]), first, count))
    out.append("\n\tnumtris %d\n" % len(tris))
    for i, t in enumerate(tris):
        out.append("\ttri %d %d %d %d\n" % (i, t[0], t[1], t[2]))
    out.append("\n\tnumweights %d\n" % len(weights))
    for i, (j, bias, offset) in enumerate(weights):
        out.append("\tweight %d %d %s ( %s )\n" % (i, j, fmt(bias), " ".join(fmt(v) for v in offset)))
    out.append("}\n")
    return "".join(out)


WALK_FRAMES = 25          # frame 24 repeats frame 0: a seamless loop of one second
WALK_RATE = 24


def _walk_values(frame, flags):
    """The animated components of one frame, in joint order (file quaternion components are the
    sines of half the angle about the side axis)."""
    phase = 2 * math.pi * (frame % (WALK_FRAMES - 1)) / (WALK_FRAMES - 1)
    swing = math.radians(30) * math.sin(phase)
    values = []
    for j in sorted(flags):
        if j == 1:
            values.append(36 + 1.5 * abs(math.sin(phase)))
        else:
            side = 1 if j in (4, 5) else -1
            angle = side * swing if j in (4, 6) else -math.radians(20) * max(0.0, side * math.sin(phase + 0.6))
            values.append(math.sin(angle / 2))
    return [round(v, 4) for v in values]


def _walk_bounds(values, flags):
    """Skin the walker's box corners with one frame (as the engine does: file quaternions conjugated,
    parents applied in order) and return the min and max corner, rounded outwards to 1/16 unit."""
    local = {}
    at = 0
    for j, (_, parent, pos) in enumerate(WALKER_JOINTS):
        t = list(pos if parent < 0 else [pos[k] - WALKER_JOINTS[parent][2][k] for k in range(3)])
        qy = 0.0
        if j in flags:
            if flags[j] & 4:
                t[2] = values[at] - (WALKER_JOINTS[0][2][2] if j == 0 else 0)
                at += 1
            if flags[j] & 16:
                qy = values[at]
                at += 1
        # File (0, qy, 0) with w >= 0, applied to row vectors: for column vectors a turn by -2 asin(qy).
        angle = -2 * math.asin(qy)
        local[j] = (angle, t)
    model = {}
    for j, (_, parent, _) in enumerate(WALKER_JOINTS):
        angle, t = local[j]
        if parent < 0:
            model[j] = (angle, t)
            continue
        pa, pt = model[parent]
        c, s = math.cos(pa), math.sin(pa)
        rotated = [c * t[0] + s * t[2], t[1], -s * t[0] + c * t[2]]   # rotation about +y by pa
        model[j] = (pa + angle, [rotated[k] + pt[k] for k in range(3)])
    lo, hi = [1e9] * 3, [-1e9] * 3
    for joint, blo, bhi in WALKER_BOXES:
        angle, t = model[joint]
        jp = WALKER_JOINTS[joint][2]
        c, s = math.cos(angle), math.sin(angle)
        for corner in range(8):
            p = (bhi[0] if corner & 1 else blo[0], bhi[1] if corner & 2 else blo[1], bhi[2] if corner & 4 else blo[2])
            o = [p[k] - jp[k] for k in range(3)]
            q = [c * o[0] + s * o[2] + t[0], o[1] + t[1], -s * o[0] + c * o[2] + t[2]]
            lo = [min(lo[k], q[k]) for k in range(3)]
            hi = [max(hi[k], q[k]) for k in range(3)]
    return [math.floor(v * 16) / 16 for v in lo], [math.ceil(v * 16) / 16 for v in hi]


def md5anim_text():
    """Walk in place: thighs swing about the side axis (+-30 degrees), shins bend, the pelvis bobs."""
    # Per joint: flags (Tx1 Ty2 Tz4 Qx8 Qy16 Qz32); animated: pelvis Tz, thighs and shins Qy.
    flags = {1: 4, 4: 16, 5: 16, 6: 16, 7: 16}
    first, components = {}, 0
    for j in range(len(WALKER_JOINTS)):
        if j in flags:
            first[j] = components
            components += bin(flags[j]).count("1")
    frames = [_walk_values(f, flags) for f in range(WALK_FRAMES)]
    out = ["MD5Version 10\n", 'commandline "generated by tools/gen_testmap.py"\n\n',
           "numFrames %d\nnumJoints %d\nframeRate %d\nnumAnimatedComponents %d\n\nhierarchy {\n"
           % (WALK_FRAMES, len(WALKER_JOINTS), WALK_RATE, components)]
    for j, (name, parent, _) in enumerate(WALKER_JOINTS):
        out.append('\t"%s"\t%d %d %d\n' % (name, parent, flags.get(j, 0), first.get(j, 0)))
    out.append("}\n\nbounds {\n")
    for values in frames:
        lo, hi = _walk_bounds(values, flags)
        out.append("\t( %s ) ( %s )\n" % (" ".join(fmt(v) for v in lo), " ".join(fmt(v) for v in hi)))
    out.append("}\n\nbaseframe {\n")
    for j, (name, parent, pos) in enumerate(WALKER_JOINTS):
        local = pos if parent < 0 else tuple(pos[k] - WALKER_JOINTS[parent][2][k] for k in range(3))
        out.append("\t( %s ) ( 0 0 0 )\n" % " ".join(fmt(v) for v in local))
    out.append("}\n")
    for f, values in enumerate(frames):
        out.append("frame %d {\n\t%s\n}\n" % (f, " ".join(_f(v) for v in values)))
    return "".join(out)


def model_files():
    return {
        ASE_PATH: ase_text().encode("ascii"),
        LWO_PATH: lwo_bytes(),
        MD5MESH_PATH: md5mesh_text().encode("ascii"),
        MD5ANIM_PATH: md5anim_text().encode("ascii"),
    }


# --- entity classes and skins ---------------------------------------------------------------------------

DEF_PATH = "def/testmap.def"
SKIN_PATH = "skins/testmap.skin"
WALKER_SKIN = "skins/testmap/walker_metal"

DEF_TEXT = """// Cohort test map entity classes. Generated by tools/gen_testmap.py; do not edit by hand.
// The engine's own classes the map uses, then the map's props: inherit chains, editor_* keys (ignored
// by the renderer), a modelDef for the walking character and a light subclass.

entityDef light
{
	"editor_color"		"0 1 0"
	"editor_mins"		"-8 -8 -8"
	"editor_maxs"		"8 8 8"
	"editor_usage"		"Light source."
	"spawnclass"		"idLight"
}

entityDef func_static
{
	"editor_color"		"0 .5 .8"
	"editor_usage"		"A model or brushes that never move."
	"spawnclass"		"idStaticEntity"
	"solid"				"1"
}

entityDef func_door
{
	"editor_usage"		"A sliding door."
	"spawnclass"		"idDoor"
}

entityDef func_rotating
{
	"editor_usage"		"Spins about an axis."
	"spawnclass"		"idRotator"
}

entityDef info_player_start
{
	"editor_usage"		"Where the player starts."
	"spawnclass"		"idPlayerStart"
}

entityDef testmap_prop
{
	"inherit"			"func_static"
	"editor_usage"		"Base of the test map's model props."
	"noshadows"			"0"
}

entityDef testmap_lamp
{
	"inherit"			"testmap_prop"
	"editor_usage"		"Standing lamp (ASE)."
	"model"				"%(ase)s"
}

entityDef testmap_wedge
{
	"inherit"			"testmap_prop"
	"editor_usage"		"Wedge (LWO2)."
	"model"				"%(lwo)s"
}

entityDef testmap_light_lamp
{
	"inherit"			"light"
	"editor_usage"		"The lamp's bulb: a light by inheritance."
	"light_radius"		"96 96 96"
	"_color"			"1 0.8 0.55"
	"texture"			"lights/testmap_round"
}

model testmap_walker
{
	mesh				%(mesh)s
	anim walk			%(anim)s
}

entityDef testmap_walker
{
	"inherit"			"func_static"
	"editor_usage"		"A character walking in place (MD5)."
	"spawnclass"		"idAnimated"
	"model"				"testmap_walker"
	"anim"				"walk"
}
""" % {"ase": ASE_PATH, "lwo": LWO_PATH, "mesh": MD5MESH_PATH, "anim": MD5ANIM_PATH}

SKIN_TEXT = """// Cohort test map skins. Generated by tools/gen_testmap.py; do not edit by hand.

skin %s
{
	model	%s
	%s	textures/testmap/door
}
""" % (WALKER_SKIN, MD5MESH_PATH, WALKER_MATERIAL)


def decl_files():
    return {DEF_PATH: DEF_TEXT.encode("ascii"), SKIN_PATH: SKIN_TEXT.encode("ascii")}


def light_classes():
    """Classnames the .def makes lights (inherit from `light`)."""
    return ["light", "testmap_light_lamp"]
