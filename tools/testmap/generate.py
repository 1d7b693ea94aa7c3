"""Builds the whole test map in memory, runs the self-checks, returns {relative path: bytes}."""
from . import checks, layout, materials, models as model_files
from .bsp import build_nodes
from .map_writer import map_text
from .portals import merge_portals
from .proc_writer import proc_text
from .readme import readme_text
from .shell import Grid, build_shell
from .tga import encode_tga


def build():
    grid = Grid(layout.AREAS, layout.SOLIDS)
    area_meshes, portal_faces = build_shell(grid, layout.material_for, layout.texel_scale_for)
    portals = merge_portals(portal_faces)
    layout.add_details(area_meshes)
    models = layout.inline_models()
    nodes = build_nodes(grid)
    ents = layout.entities()
    images = layout_images()

    entity_points = []
    for classname, keys in ents:
        values = dict(keys)
        expected = layout.expected_area_of_entity(values["name"])
        if expected is None:
            raise checks.CheckError("entity %s has no expected area" % values["name"])
        o = values["origin"]
        entity_points.append((values["name"], (o[0], o[1], o[2] + 1), expected))
    stats = checks.check_level(area_meshes, models, portals, nodes, grid, entity_points, images.keys())

    files = {}
    files["maps/testmap.proc"] = proc_text(area_meshes, models, ((400, 16, 0), (448, 64, 48)), portals,
                                           nodes).encode("ascii")
    files["maps/testmap.map"] = map_text(ents).encode("ascii")
    files["materials/testmap.mtr"] = materials.MTR.encode("ascii")
    for path, (rows, channels, rle) in images.items():
        files[path] = encode_tga(rows, channels, rle)
    files.update(model_files.model_files())
    files.update(model_files.decl_files())

    lights = [dict(keys) for classname, keys in ents if classname in model_files.light_classes()]
    stats.update({
        "areas": len(area_meshes),
        "portals": len(portals),
        "nodes": len(nodes),
        "area_triangles": sum(m.triangle_count() for m in area_meshes),
        "model_triangles": sum(m.triangle_count() for m in models),
        "inline_models": [m.name for m in models],
        "materials": materials.material_names(),
        "images": len(images),
        "lights_point": sum(1 for l in lights if "light_target" not in l and "parallel" not in l),
        "lights_projected": sum(1 for l in lights if "light_target" in l),
        "lights_parallel": sum(1 for l in lights if "parallel" in l),
        "entities": [(classname, dict(keys)["name"]) for classname, keys in ents
                     if classname not in model_files.light_classes()],
        "area_names": [a.name for a in layout.AREAS],
        "area_boxes": [(a.name, a.lo, a.hi, layout.AREA_NOTES[a.name]) for a in layout.AREAS],
        "views": layout.VIEWS,
    })
    files["README.md"] = readme_text(stats, lights, files).encode("utf-8")
    stats["bytes"] = sum(len(b) for b in files.values())
    return files, stats


def layout_images():
    from .textures import build_images
    return build_images()
