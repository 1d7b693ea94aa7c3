"""What the test map contains: areas, solids, detail surfaces, props, entities and lights.

Units: Z up, 1 unit ~ 1 inch. Every coordinate is an exact small number so all output is exact.
"""
import math

from .mesh import Mesh, add_box
from .shell import Box

M = "textures/testmap/"

# Air boxes, one per area (index = area number). Touching faces become portals automatically.
AREAS = [
    Box("hall", (0, 0, 0), (512, 384, 160), floor=M + "floor_tiles", wall=M + "wall_bricks", ceiling=M + "ceiling"),
    Box("corridor_west", (512, 144, 0), (768, 240, 128), floor=M + "metalfloor", wall=M + "concrete",
        ceiling=M + "concrete"),
    Box("atrium", (768, 0, 0), (1152, 384, 192), floor=M + "floor_tiles", wall=M + "wall_bricks",
        ceiling=M + "ceiling"),
    Box("skylight_shaft", (896, 128, 192), (1024, 256, 320), floor=M + "concrete", wall=M + "concrete",
        ceiling=M + "sky"),
    Box("stairwell", (1152, 144, 0), (1408, 240, 224), floor=M + "metalfloor", wall=M + "concrete",
        ceiling=M + "concrete"),
    Box("gallery", (1408, 32, 96), (1792, 352, 256), floor=M + "wood_floor", wall=M + "wall_bricks",
        ceiling=M + "ceiling"),
    # Off the gallery's north wall, behind the gallery view: its opening stays out of every older view.
    Box("sky_court", (1408, 352, 96), (1536, 512, 256), floor=M + "concrete", wall=M + "wall_bricks",
        ceiling=M + "skybox"),
]

AREA_NOTES = {
    "hall": "four pillars, ceiling fan `fan_spin`, table, stacked crates, ceiling light panels, blood decal",
    "corridor_west": "door `door_main`, flickering light, sign decal, light strip",
    "atrium": "skylight with grate (sun through it), glass screen, plinth with a crate, blue wall panel, "
              "projected `light_beam`, floor decal",
    "skylight_shaft": "sky cap (emitter, noshadows), holds `light_sun`",
    "stairwell": "eight steps (rise 12, run 28) up to the gallery floor at z 96",
    "gallery": "raised room: pedestal with a glass case, gel projector `light_gel`, blue panels, crate",
    "sky_court": "ceiling is sky (`textures/testmap/skybox`: a cameraCubeMap with texgen skybox), a shrub "
                 "whose leaves are `noSelfShadow`, a chrome pipe reflecting the sky (`texgen reflect`), lit by "
                 "`light_court`",
}

# Suggested cameras (origin, yaw degrees, pitch degrees down) for renders and benchmarks.
VIEWS = [
    ("hall", (40, 192, 68), 0, 5),
    ("atrium_skylight", (790, 30, 110), 40, 20),
    ("stairs_up", (1168, 192, 68), 0, -10),
    ("gallery", (1440, 300, 164), -30, 15),
    ("sky_court", (1420, 364, 120), 60, -35),
]

STAIR_STEPS = 8
STAIR_RISE = 12
STAIR_RUN = 28
STAIR_X0 = 1184


def _solids():
    solids = []
    for cx, cy in ((128, 96), (128, 288), (384, 96), (384, 288)):
        solids.append(Box("pillar", (cx - 16, cy - 16, 0), (cx + 16, cy + 16, 160)))
    for step in range(STAIR_STEPS):
        x0 = STAIR_X0 + STAIR_RUN * step
        solids.append(Box("stairs", (x0, 144, 0), (1408, 240, STAIR_RISE * (step + 1))))
    solids.append(Box("plinth", (1056, 288, 0), (1152, 384, 24)))
    solids.append(Box("pedestal", (1600, 160, 96), (1664, 224, 128)))
    return solids


SOLIDS = _solids()

SOLID_MATERIALS = {
    "pillar": M + "pillar",
    "plinth": M + "concrete",
    "pedestal": M + "metal",
}


# World units per texture repeat on the shell (128 unless listed): bricks come out about 32 x 16 units.
TEXEL_SCALE = {M + "wall_bricks": 64.0, M + "metalfloor": 64.0}


def texel_scale_for(material):
    return TEXEL_SCALE.get(material, 128.0)


def material_for(area_index, inward_normal, neighbour):
    """Material of a shell face of `area_index` whose other side is `neighbour` (solid name or 'void')."""
    area = AREAS[area_index]
    if neighbour == "stairs":
        return M + "metalfloor" if inward_normal[2] > 0 else M + "concrete"
    if neighbour in SOLID_MATERIALS:
        return SOLID_MATERIALS[neighbour]
    if inward_normal[2] > 0:
        return area.props["floor"]
    if inward_normal[2] < 0:
        return area.props["ceiling"]
    return area.props["wall"]


# --- detail surfaces inside areas (not part of the watertight shell) -----------------------------------

def _quad(mesh, material, points, normal, texel_scale=None):
    """Quad whose texture spans it once (decals, panels, grates use the whole image)."""
    st = [(0.0, 1.0), (1.0, 1.0), (1.0, 0.0), (0.0, 0.0)] if texel_scale is None else None
    mesh.add_polygon(material, points, normal, st=st, texel_scale=texel_scale or 128.0)


def add_details(area_meshes):
    hall, corridor, atrium, shaft, stairwell, gallery, sky_court = area_meshes
    panel = M + "lightpanel"
    # Ceiling light panels hang a quarter unit below the ceiling, facing down.
    for x0, y0 in ((224, 32), (224, 320), (32, 176), (448, 176)):
        z = 159.75
        _quad(hall, panel, [(x0, y0, z), (x0 + 64, y0, z), (x0 + 64, y0 + 32, z), (x0, y0 + 32, z)], (0, 0, -1))
    # The corridor's light strip pulses (an animated emitter).
    _quad(corridor, M + "lightpanel_pulse",
          [(576, 176, 127.75), (704, 176, 127.75), (704, 208, 127.75), (576, 208, 127.75)], (0, 0, -1))
    for y0 in (96, 256):
        z = 255.75
        _quad(gallery, M + "lightpanel_blue", [(1504, y0, z), (1568, y0, z), (1568, y0 + 32, z), (1504, y0 + 32, z)],
              (0, 0, -1))
    # Wall panel in the atrium, facing +y, emissive strip.
    _quad(atrium, M + "lightpanel_blue", [(1024, 0.25, 96), (1088, 0.25, 96), (1088, 0.25, 128), (1024, 0.25, 128)],
          (0, 1, 0))

    # A turning vent grille on the hall's west wall (animated texture rotation).
    _quad(hall, M + "vent", [(0.25, 164, 64), (0.25, 100, 64), (0.25, 100, 128), (0.25, 164, 128)], (1, 0, 0))

    # Decals: slightly off the surface they sit on.
    _quad(hall, M + "decal_blood", [(0.25, 264, 24), (0.25, 200, 24), (0.25, 200, 88), (0.25, 264, 88)], (1, 0, 0))
    _quad(atrium, M + "decal_blood", [(880, 96, 0.25), (944, 96, 0.25), (944, 160, 0.25), (880, 160, 0.25)],
          (0, 0, 1))
    _quad(corridor, M + "decal_sign", [(600, 144.25, 80), (664, 144.25, 80), (664, 144.25, 112), (600, 144.25, 112)],
          (0, 1, 0))

    # Skylight grate just below the opening into the shaft, seen from the atrium (material is twoSided).
    z = 191.5
    _quad(atrium, M + "grate", [(896, 128, z), (1024, 128, z), (1024, 256, z), (896, 256, z)], (0, 0, -1))

    # Glass display case on the gallery pedestal: closed box, normals out.
    add_box(gallery, M + "glass", (1604, 164, 128), (1660, 220, 176), texel_scale=64.0)
    # A glass screen across part of the atrium.
    add_box(atrium, M + "glass", (832, 250, 0.5), (960, 252, 96), texel_scale=64.0)

    # A chrome pipe from the sky court's floor to its sky, in the court view: it reflects the sky cube.
    _add_pipe(sky_court, M + "chrome", (1432, 488), 8, 96.25, 255.75)


def _add_pipe(mesh, material, centre, radius, z0, z1, sides=8):
    """A vertical prism of `sides` flat faces round `centre` (each face its own normal), no caps."""
    def corner(i):
        a = 2.0 * math.pi * i / sides
        return (round(centre[0] + radius * math.cos(a), 4), round(centre[1] + radius * math.sin(a), 4))
    for i in range(sides):
        (xa, ya), (xb, yb) = corner(i), corner(i + 1)
        mid = 2.0 * math.pi * (i + 0.5) / sides
        normal = (round(math.cos(mid), 6), round(math.sin(mid), 6), 0.0)
        mesh.add_polygon(material, [(xa, ya, z0), (xb, yb, z0), (xb, yb, z1), (xa, ya, z1)], normal, texel_scale=32.0)


# --- inline models (model space; entities place them) -------------------------------------------------

def inline_models():
    models = []
    door = Mesh("door_main")
    # Overlaps the corridor walls, floor and ceiling so no light leaks round it while closed.
    add_box(door, M + "door", (-4, -52, -4), (4, 52, 132), texel_scale=64.0)
    models.append(door)

    fan = Mesh("fan_spin")
    add_box(fan, M + "fan", (-8, -8, -6), (8, 8, 6), texel_scale=32.0)
    add_box(fan, M + "fan", (-2, -2, 6), (2, 2, 36), texel_scale=32.0)
    for lo, hi in (((8, -6, -1), (72, 6, 1)), ((-6, 8, -1), (6, 72, 1)),
                   ((-72, -6, -1), (-8, 6, 1)), ((-6, -72, -1), (6, -8, 1))):
        add_box(fan, M + "fan", lo, hi, texel_scale=32.0)
    models.append(fan)

    crate = Mesh("testmap_crate")
    add_box(crate, M + "crate", (-24, -24, 0), (24, 24, 48), texel_scale=48.0)
    models.append(crate)

    # Crossed leaf slabs on a stem: the leaves are noSelfShadow (they do not shadow each other, but do
    # shadow the floor and the stem).
    shrub = Mesh("testmap_shrub")
    add_box(shrub, M + "wood", (-3, -3, 0), (3, 3, 40), texel_scale=32.0)
    for lo, hi in (((-28, -4, 30), (28, 4, 70)), ((-4, -28, 30), (4, 28, 70)), ((-20, -20, 50), (20, 20, 56))):
        add_box(shrub, M + "leaves", lo, hi, texel_scale=32.0)
    models.append(shrub)

    table = Mesh("testmap_table")
    add_box(table, M + "wood", (-48, -32, 30), (48, 32, 34), texel_scale=64.0)
    for sx in (-1, 1):
        for sy in (-1, 1):
            x0 = 38 if sx > 0 else -46
            y0 = 22 if sy > 0 else -30
            add_box(table, M + "metal", (x0, y0, 0), (x0 + 8, y0 + 8, 30), texel_scale=32.0)
    models.append(table)
    return models


def yaw_rotation(degrees):
    """Doom 3 `rotation` key: 9 floats, rows = the entity's forward, left, up axes."""
    c = round(math.cos(math.radians(degrees)), 6)
    s = round(math.sin(math.radians(degrees)), 6)
    return (c, s, 0.0, -s, c, 0.0, 0.0, 0.0, 1.0)


# --- entities ------------------------------------------------------------------------------------------
# Each entity: (classname, [(key, value), ...]); values are tuples of numbers or strings.

def entities():
    ents = []
    ents.append(("info_player_start", [("name", "info_player_start_1"), ("origin", (64, 192, 1)), ("angle", 0)]))

    ents.append(("func_door", [("name", "door_main"), ("model", "door_main"), ("origin", (544, 192, 0)),
                               ("movedir", -1), ("lip", 8), ("speed", 120), ("wait", 3)]))
    ents.append(("func_rotating", [("name", "fan_spin"), ("model", "fan_spin"), ("origin", (256, 192, 124)),
                                   ("speed", 90), ("rotation", yaw_rotation(0))]))
    for name, origin, yaw in (("crate_1", (424, 40, 0), 0), ("crate_2", (424, 40, 48), 30),
                              ("crate_3", (1720, 300, 96), 45), ("crate_4", (1100, 336, 24), 15)):
        keys = [("name", name), ("model", "testmap_crate"), ("origin", origin), ("rotation", yaw_rotation(yaw))]
        if name == "crate_2":
            keys.append(("_color", (0.55, 0.8, 1)))   # shaderParm tint through the crate's `colored` stage
        ents.append(("func_static", keys))
    ents.append(("func_static", [("name", "shrub_1"), ("model", "testmap_shrub"), ("origin", (1472, 448, 96)),
                                 ("rotation", yaw_rotation(20))]))
    ents.append(("func_static", [("name", "table_1"), ("model", "testmap_table"), ("origin", (160, 192, 0)),
                                 ("rotation", yaw_rotation(90))]))

    # Model props (tools/testmap/models.py): classes from def/testmap.def, one prop per model format.
    ents.append(("testmap_lamp", [("name", "lamp_1"), ("origin", (40, 40, 0))]))
    ents.append(("testmap_lamp", [("name", "lamp_2"), ("origin", (472, 344, 0)), ("angle", 45)]))
    ents.append(("testmap_light_lamp", [("name", "light_lamp"), ("origin", (40, 40, 72))]))
    ents.append(("testmap_wedge", [("name", "wedge_1"), ("origin", (820, 330, 0)), ("angle", 90)]))
    ents.append(("func_static", [("name", "wedge_2"), ("model", "models/testmap/wedge.lwo"),
                                 ("origin", (1480, 300, 96))]))
    # In the hall, facing the player start: the scenario walks it around a circle in the camera's view.
    ents.append(("testmap_walker", [("name", "walker_1"), ("origin", (352, 264, 0)), ("angle", 180)]))
    ents.append(("testmap_walker", [("name", "walker_2"), ("origin", (1700, 120, 96)), ("angle", 180),
                                    ("skin", "skins/testmap/walker_metal")]))

    lights = [
        ("light_hall", [("origin", (224, 192, 150)), ("light_radius", (320, 288, 200)), ("_color", (1, 0.9, 0.75)),
                        ("light_center", (0, 0, -20)), ("texture", "lights/testmap_round")]),
        ("light_hall_fill", [("origin", (48, 336, 112)), ("light_radius", (256, 256, 160)),
                             ("_color", (0.35, 0.45, 0.7)), ("noshadows", 1)]),
        ("light_flicker", [("origin", (640, 192, 112)), ("light_radius", (160, 80, 128)),
                           ("_color", (1, 0.6, 0.25)), ("texture", "lights/testmap_flicker"), ("shaderParm4", 0.3)]),
        ("light_beam", [("origin", (800, 192, 160)), ("light_target", (256, 0, -96)), ("light_right", (0, -64, 0)),
                        ("light_up", (24, 0, 64)), ("light_start", (32, 0, -12)), ("light_end", (320, 0, -120)),
                        ("_color", (0.9, 0.95, 1)), ("texture", "lights/testmap_round")]),
        ("light_sun", [("origin", (960, 192, 300)), ("light_radius", (480, 480, 480)), ("parallel", 1),
                       ("light_center", (160, -96, 480)), ("_color", (1, 0.95, 0.85))]),
        ("light_stairs", [("origin", (1280, 192, 200)), ("light_radius", (200, 96, 224)),
                          ("_color", (0.8, 0.9, 1)), ("nospecular", 1)]),
        ("light_gallery", [("origin", (1600, 96, 220)), ("light_radius", (320, 256, 180)),
                           ("_color", (1, 0.85, 0.7)), ("texture", "lights/testmap_round")]),
        ("light_gel", [("origin", (1552, 256, 240)), ("light_target", (0, 0, -144)), ("light_right", (64, 0, 0)),
                       ("light_up", (0, 64, 0)), ("_color", (1, 1, 1)), ("texture", "lights/testmap_gel")]),
        # Light kinds: fog over the stairs, a blend light tinting the flicker room, ambient fill in the gallery.
        ("light_fog", [("origin", (1280, 192, 120)), ("light_radius", (120, 80, 100)), ("_color", (0.55, 0.6, 0.7)),
                       ("shaderParm3", 600), ("texture", "lights/testmap_fog")]),
        ("light_blend", [("origin", (640, 192, 48)), ("light_radius", (64, 64, 64)), ("_color", (1, 0.5, 0.3)),
                         ("texture", "lights/testmap_blend")]),
        ("light_ambient", [("origin", (1600, 96, 150)), ("light_radius", (320, 256, 180)),
                           ("_color", (0.12, 0.12, 0.16)), ("texture", "lights/testmap_ambient")]),
        ("light_court", [("origin", (1500, 420, 230)), ("light_radius", (160, 160, 200)),
                         ("_color", (1, 0.95, 0.85))]),
    ]
    for name, keys in lights:
        ents.append(("light", [("name", name)] + keys))
    return ents


def expected_area_of_entity(name):
    """Area each entity's origin must fall in (checked against the node tree)."""
    return {
        "info_player_start_1": 0, "door_main": 1, "fan_spin": 0, "crate_1": 0, "crate_2": 0, "crate_3": 5,
        "crate_4": 2, "table_1": 0, "light_hall": 0, "light_hall_fill": 0, "light_flicker": 1, "light_beam": 2,
        "light_sun": 3, "light_stairs": 4, "light_gallery": 5, "light_gel": 5,
        "light_fog": 4, "light_blend": 1, "light_ambient": 5,
        "shrub_1": 6, "light_court": 6,
        "lamp_1": 0, "lamp_2": 0, "light_lamp": 0, "wedge_1": 2, "wedge_2": 5, "walker_1": 0, "walker_2": 5,
    }.get(name)
