#!/usr/bin/env python3
"""Checks for tools/gen_testmap.py: committed assets are up to date (byte for byte), the generated
.proc is self-consistent, textures decode, and the watertight/winding/node checks reject broken input."""
import argparse
import copy
import os
import re
import shutil
import subprocess
import sys
import unittest

from tree_files import read_tree

ARGS = None


class CommittedAssets(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        if os.path.isdir(ARGS.work):
            shutil.rmtree(ARGS.work)
        result = subprocess.run([sys.executable, os.path.join(ARGS.repo, "tools", "gen_testmap.py"),
                                 "--out", ARGS.work], capture_output=True, text=True)
        if result.returncode != 0:
            raise AssertionError("generator failed:\n" + result.stdout + result.stderr)
        cls.summary = result.stdout
        cls.generated = read_tree(ARGS.work)
        cls.committed = read_tree(os.path.join(ARGS.repo, "assets", "testmap"))

    def test_same_files(self):
        self.assertEqual(sorted(self.generated), sorted(self.committed),
                         "assets/testmap is stale: run python3 tools/gen_testmap.py and commit")

    def test_same_bytes(self):
        stale = [p for p in self.generated if self.committed.get(p) != self.generated[p]]
        self.assertEqual(stale, [], "assets/testmap differs from the generator: run python3 tools/gen_testmap.py")

    def test_under_five_megabytes(self):
        self.assertLess(sum(len(b) for b in self.generated.values()), 5 * 1024 * 1024)

    def test_summary_mentions_watertight(self):
        self.assertRegex(self.summary, r"watertight: \d+ shell edges closed")


def tokens(text):
    text = re.sub(r"/\*.*?\*/", " ", text, flags=re.S)
    return re.findall(r'"[^"]*"|[(){}]|[^\s(){}"]+', text)


class ProcFile(unittest.TestCase):
    """An independent reading of the .proc, so a generator bug cannot hide behind its own writer."""

    @classmethod
    def setUpClass(cls):
        with open(os.path.join(ARGS.repo, "assets", "testmap", "maps", "testmap.proc")) as handle:
            cls.tok = tokens(handle.read())
        cls.models = {}
        cls.portals = []
        cls.nodes = []
        t = cls.tok
        assert t[0] == "mapProcFile003"
        i = 1
        while i < len(t):
            word = t[i]
            if word == "model":
                name = t[i + 2].strip('"')
                count = int(t[i + 3])
                i += 4
                surfaces = []
                for _ in range(count):
                    assert t[i] == "{"
                    material = t[i + 1].strip('"')
                    nv, ni = int(t[i + 2]), int(t[i + 3])
                    i += 4
                    verts = []
                    for _ in range(nv):
                        assert t[i] == "(" and t[i + 9] == ")"
                        verts.append([float(x) for x in t[i + 1:i + 9]])
                        i += 10
                    idx = [int(x) for x in t[i:i + ni]]
                    i += ni
                    assert t[i] == "}"
                    i += 1
                    surfaces.append((material, verts, idx))
                assert t[i] == "}"
                i += 1
                cls.models[name] = surfaces
            elif word == "shadowModel":
                depth = 0
                while True:
                    depth += {"{": 1, "}": -1}.get(t[i], 0)
                    i += 1
                    if depth == 0 and t[i - 1] == "}":
                        break
            elif word == "interAreaPortals":
                cls.num_areas, count = int(t[i + 2]), int(t[i + 3])
                i += 4
                for _ in range(count):
                    n, pos, neg = int(t[i]), int(t[i + 1]), int(t[i + 2])
                    i += 3
                    pts = []
                    for _ in range(n):
                        pts.append([float(x) for x in t[i + 1:i + 4]])
                        i += 5
                    cls.portals.append((pos, neg, pts))
                i += 1
            elif word == "nodes":
                count = int(t[i + 2])
                i += 3
                for _ in range(count):
                    plane = [float(x) for x in t[i + 1:i + 5]]
                    cls.nodes.append((plane, int(t[i + 6]), int(t[i + 7])))
                    i += 8
                i += 1
            else:
                raise AssertionError("unexpected token %r" % word)

    def test_area_models_and_inline_models(self):
        for n in range(self.num_areas):
            self.assertIn("_area%d" % n, self.models)
        for name in ("door_main", "fan_spin", "testmap_crate", "testmap_table"):
            self.assertIn(name, self.models)

    def test_triangles_clockwise_from_front(self):
        for name, surfaces in self.models.items():
            for material, verts, idx in surfaces:
                self.assertEqual(len(idx) % 3, 0)
                for k in range(0, len(idx), 3):
                    a, b, c = (verts[j] for j in idx[k:k + 3])
                    e1 = [b[m] - a[m] for m in range(3)]
                    e2 = [c[m] - a[m] for m in range(3)]
                    face = (e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0])
                    self.assertLess(sum(face[m] * a[5 + m] for m in range(3)), 0, "%s %s" % (name, material))

    def test_portals_face_their_positive_area(self):
        centre = {}
        for n in range(self.num_areas):
            pts = [v[:3] for _, verts, _ in self.models["_area%d" % n] for v in verts]
            centre[n] = [sum(p[m] for p in pts) / len(pts) for m in range(3)]
        for pos, neg, pts in self.portals:
            c = [sum(p[m] for p in pts) / len(pts) for m in range(3)]
            v1 = [pts[0][m] - c[m] for m in range(3)]
            v2 = [pts[1][m] - c[m] for m in range(3)]
            normal = (v2[1] * v1[2] - v2[2] * v1[1], v2[2] * v1[0] - v2[0] * v1[2], v2[0] * v1[1] - v2[1] * v1[0])
            to_pos = [centre[pos][m] - c[m] for m in range(3)]
            self.assertGreater(sum(normal[m] * to_pos[m] for m in range(3)), 0, "portal %d-%d" % (pos, neg))

    def test_nodes_reference_valid_children(self):
        for plane, pos, neg in self.nodes:
            for child in (pos, neg):
                self.assertTrue(0 < child < len(self.nodes) or -self.num_areas <= child <= 0)

    def test_world_shell_closed_across_areas(self):
        """Edges of all opaque world surfaces (floor/wall/ceiling materials) pair up exactly."""
        shell = ("floor_tiles", "wall_bricks", "ceiling", "concrete", "metalfloor", "wood_floor", "sky", "skybox",
                 "pillar", "metal")
        edges = {}
        for n in range(self.num_areas):
            for material, verts, idx in self.models["_area%d" % n]:
                if material.split("/")[-1] not in shell:
                    continue
                for k in range(0, len(idx), 3):
                    tri = [tuple(verts[j][:3]) for j in idx[k:k + 3]]
                    for e in range(3):
                        key = (tri[e], tri[(e + 1) % 3])
                        edges[key] = edges.get(key, 0) + 1
        self.assertGreater(len(edges), 1000)
        for (a, b), count in edges.items():
            self.assertEqual((count, edges.get((b, a), 0)), (1, 1), "edge %s -> %s" % (a, b))


def parse_map_entities(text):
    """Entities of a Version 2 .map as lists of (key, value); brush and patch primitives skipped."""
    text = re.sub(r"//[^\n]*", "", text)
    t = re.findall(r'"[^"]*"|[{}()]|[^\s{}()"]+', text)
    assert t[0] == "Version" and t[1] == "2"
    i = 2
    entities = []
    while i < len(t):
        assert t[i] == "{", t[i]
        i += 1
        keys = []
        while t[i] != "}":
            if t[i] == "{":
                depth = 0
                while True:
                    depth += {"{": 1, "}": -1}.get(t[i], 0)
                    i += 1
                    if depth == 0:
                        break
                continue
            keys.append((t[i].strip('"'), t[i + 1].strip('"')))
            i += 2
        i += 1
        entities.append(keys)
    return entities


class MapAndMaterials(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        root = os.path.join(ARGS.repo, "assets", "testmap")
        with open(os.path.join(root, "maps", "testmap.map")) as handle:
            cls.entities = [dict(e) for e in parse_map_entities(handle.read())]
        with open(os.path.join(root, "materials", "testmap.mtr")) as handle:
            cls.mtr = handle.read()
        cls.root = root
        cls.materials = set(re.findall(r"^((?:textures|models|lights)/\S+)\s*$", cls.mtr, re.M))
        ProcFile.setUpClass()
        cls.models = ProcFile.models

    def by_name(self, name):
        return next(e for e in self.entities if e.get("name") == name)

    def test_worldspawn_first_and_player_start(self):
        self.assertEqual(self.entities[0]["classname"], "worldspawn")
        start = next(e for e in self.entities if e["classname"] == "info_player_start")
        self.assertEqual(len(start["origin"].split()), 3)
        self.assertIn("angle", start)

    def test_light_kinds_and_keys(self):
        lights = [e for e in self.entities if e["classname"] == "light"]
        self.assertEqual(sum(1 for l in lights if l.get("parallel") == "1"), 1)
        projected = [l for l in lights if "light_target" in l]
        self.assertGreaterEqual(len(projected), 2)
        self.assertTrue(all("light_right" in l and "light_up" in l for l in projected))
        self.assertTrue(any("light_start" in l and "light_end" in l for l in projected))
        self.assertTrue(any(l.get("texture") == "lights/testmap_gel" for l in projected))
        self.assertTrue(any(l.get("noshadows") == "1" for l in lights))
        self.assertTrue(any(l.get("nospecular") == "1" for l in lights))
        self.assertTrue(any("light_center" in l and "parallel" not in l for l in lights))
        self.assertIn("light_flicker", {l["name"] for l in lights})
        for light in lights:
            if "texture" in light:
                self.assertIn(light["texture"], self.materials)

    def test_projected_vectors_are_perpendicular(self):
        for light in self.entities:
            if "light_target" not in light:
                continue
            target, right, up = ([float(x) for x in light[k].split()] for k in ("light_target", "light_right", "light_up"))
            self.assertEqual(sum(a * b for a, b in zip(target, right)), 0, light["name"])
            self.assertEqual(sum(a * b for a, b in zip(target, up)), 0, light["name"])

    def test_movers_and_props_name_proc_models_or_model_files(self):
        self.assertEqual(self.by_name("door_main")["classname"], "func_door")
        self.assertEqual(self.by_name("fan_spin")["classname"], "func_rotating")
        for entity in self.entities:
            if entity["classname"] in ("func_static", "func_door", "func_rotating"):
                model = entity["model"]
                if model.endswith((".ase", ".lwo", ".md5mesh")):
                    self.assertTrue(os.path.isfile(os.path.join(ARGS.repo, "assets", "testmap", model)), model)
                else:
                    self.assertIn(model, self.models, entity["name"])
                self.assertIn("origin", entity)

    def test_model_props_classes_and_skins(self):
        root = os.path.join(ARGS.repo, "assets", "testmap")
        with open(os.path.join(root, "def", "testmap.def")) as handle:
            defs = handle.read()
        with open(os.path.join(root, "skins", "testmap.skin")) as handle:
            skins = handle.read()
        classes = set(re.findall(r"^entityDef (\S+)", defs, re.M))
        for entity in self.entities:
            self.assertIn(entity["classname"], classes | {"worldspawn"}, entity.get("name"))
        for path in re.findall(r'(models/\S+\.(?:ase|lwo|md5mesh|md5anim))', defs + skins):
            self.assertTrue(os.path.isfile(os.path.join(root, path)), path)
        for entity in self.entities:
            if "skin" in entity:
                self.assertRegex(skins, r"(?m)^skin %s$" % re.escape(entity["skin"]))
        # The ASE's bitmaps and the LWO's surface names are materials of the .mtr (or remapped by a skin).
        with open(os.path.join(root, "models", "testmap", "lamp.ase")) as handle:
            for bitmap in re.findall(r'\*BITMAP "[^"]*\\base\\([^"]*)\.tga"', handle.read()):
                self.assertIn(bitmap.replace("\\", "/"), self.materials)
        with open(os.path.join(root, "models", "testmap", "wedge.lwo"), "rb") as handle:
            data = handle.read()
        self.assertEqual(data[:4] + data[8:12], b"FORMLWO2")
        self.assertEqual(int.from_bytes(data[4:8], "big"), len(data) - 8)

    def test_every_used_material_defined_and_every_image_present(self):
        for name, surfaces in self.models.items():
            for material, _, _ in surfaces:
                self.assertIn(material, self.materials, name)
        for image in set(re.findall(r"((?:textures|lights)/[\w/]+\.tga)", self.mtr)):
            self.assertTrue(os.path.isfile(os.path.join(self.root, image)), image)

    def test_emitters_have_no_interaction_stages(self):
        for name in ("textures/testmap/lightpanel", "textures/testmap/lightpanel_blue"):
            body = re.search(re.escape(name) + r"\s*\n\{(.*?)^\}", self.mtr, re.S | re.M).group(1)
            self.assertIn("blend\tadd", body)
            self.assertNotRegex(body.lower(), r"diffusemap|bumpmap|specularmap")


class GeneratorChecks(unittest.TestCase):
    """The generator's own checks must fail on broken geometry."""

    @classmethod
    def setUpClass(cls):
        sys.path.insert(0, os.path.join(ARGS.repo, "tools"))
        from testmap import checks, layout
        from testmap.portals import merge_portals
        from testmap.shell import Grid, build_shell
        cls.checks = checks
        cls.grid = Grid(layout.AREAS, layout.SOLIDS)
        cls.meshes, faces = build_shell(cls.grid, layout.material_for, layout.texel_scale_for)
        cls.portals = merge_portals(faces)

    def broken(self, mutate):
        meshes = copy.deepcopy(self.meshes)
        mutate(meshes)
        return meshes

    def test_intact_shell_passes(self):
        self.checks.check_world_closed(self.meshes)
        self.checks.check_area_shells(self.meshes, self.portals)
        self.checks.check_winding(self.meshes)

    def test_missing_triangle_is_a_crack(self):
        def drop(meshes):
            tris = meshes[0].surfaces["textures/testmap/wall_bricks"]
            del tris[len(tris) // 2]
        meshes = self.broken(drop)
        with self.assertRaises(self.checks.CheckError):
            self.checks.check_world_closed(meshes)
        with self.assertRaises(self.checks.CheckError):
            self.checks.check_area_shells(meshes, self.portals)

    def test_moved_vertex_is_a_crack(self):
        def nudge(meshes):
            tris = meshes[2].surfaces["textures/testmap/floor_tiles"]
            (x, y, z), st, n = tris[5][1]
            tris[5][1] = ((x + 0.5, y, z), st, n)
        with self.assertRaises(self.checks.CheckError):
            self.checks.check_world_closed(self.broken(nudge))

    def test_split_edge_is_a_t_junction(self):
        def split(meshes):
            tris = meshes[1].surfaces["textures/testmap/concrete"]
            a, b, c = tris[0]
            mid = tuple((a[0][m] + b[0][m]) / 2 for m in range(3))
            m = (mid, a[1], a[2])
            tris[0] = [a, m, c]
            tris.append([m, b, c])
        with self.assertRaises(self.checks.CheckError):
            self.checks.check_world_closed(self.broken(split))

    def test_flipped_triangle_fails_winding(self):
        def flip(meshes):
            tris = meshes[3].surfaces["textures/testmap/concrete"]
            tris[0] = [tris[0][0], tris[0][2], tris[0][1]]
        with self.assertRaises(self.checks.CheckError):
            self.checks.check_winding(self.broken(flip))

    def test_inside_out_wall_is_rejected(self):
        from testmap.bsp import build_nodes
        nodes = build_nodes(self.grid)
        self.checks.check_shell_faces_air(self.meshes, nodes)

        def invert(meshes):
            tris = meshes[0].surfaces["textures/testmap/floor_tiles"]
            a, b, c = tris[0]
            flipped = tuple(-x for x in a[2])
            tris[0] = [(a[0], a[1], flipped), (c[0], c[1], flipped), (b[0], b[1], flipped)]
        with self.assertRaises(self.checks.CheckError):
            self.checks.check_shell_faces_air(self.broken(invert), nodes)

    def test_node_tree_rejects_wrong_area(self):
        from testmap.bsp import build_nodes
        nodes = build_nodes(self.grid)
        self.checks.check_nodes(nodes, self.grid, [("hall", (10, 10, 10), 0)])
        with self.assertRaises(self.checks.CheckError):
            self.checks.check_nodes(nodes, self.grid, [("hall", (10, 10, 10), 2)])


class Textures(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        sys.path.insert(0, os.path.join(ARGS.repo, "tools"))
        from testmap.tga import decode_tga
        cls.decode = staticmethod(decode_tga)
        cls.root = os.path.join(ARGS.repo, "assets", "testmap")

    def load(self, path):
        with open(os.path.join(self.root, path), "rb") as handle:
            return self.decode(handle.read())

    def test_grate_has_holes(self):
        w, h, channels, rows = self.load("textures/testmap/grate_d.tga")
        self.assertEqual(channels, 4)
        alphas = {p[3] for row in rows for p in row}
        self.assertIn(0, alphas)
        self.assertIn(255, alphas)

    def test_normal_maps_point_out_and_have_bumps(self):
        for name in ("bricks_local", "tiles_local", "metalfloor_local", "crate_local", "grate_local"):
            w, h, channels, rows = self.load("textures/testmap/%s.tga" % name)
            pixels = [p for row in rows for p in row]
            self.assertTrue(all(p[2] >= 128 for p in pixels), name)
            tilted = sum(1 for p in pixels if abs(p[0] - 128) > 20 or abs(p[1] - 128) > 20)
            self.assertGreater(tilted, len(pixels) // 20, name)
            for p in pixels[::97]:
                n = [(c / 255.0) * 2 - 1 for c in p[:3]]
                self.assertAlmostEqual(sum(c * c for c in n), 1.0, delta=0.03)

    def test_normal_map_y_follows_plus_t(self):
        """Y = +t (down the rows), as the engine's heightmap(): where height rises going down the image
        (top bevel of a brick) the normal leans to -Y (green below 128), and the other way at the bottom."""
        w, h, _, rows = self.load("textures/testmap/bricks_local.tga")
        top = [rows[y][x][1] for y in (2, 3, 4) for x in range(40, 50)]
        bottom = [rows[y][x][1] for y in (27, 28, 29) for x in range(40, 50)]
        self.assertLess(sum(top) / len(top), 110)
        self.assertGreater(sum(bottom) / len(bottom), 146)

    def test_gel_is_colourful_and_falloff_fades(self):
        w, h, _, rows = self.load("lights/testmap_gel.tga")
        colours = {tuple(c // 64 for c in p[:3]) for row in rows for p in row}
        self.assertGreater(len(colours), 5)
        w, h, _, rows = self.load("lights/testmap_falloff.tga")
        mid = rows[h // 2]
        self.assertEqual(mid[0][0], 0)
        self.assertGreater(mid[w // 2][0], 240)

    def test_all_images_decode_with_sane_sizes(self):
        for folder, _, names in os.walk(self.root):
            for name in names:
                if name.endswith(".tga"):
                    w, h, channels, rows = self.load(os.path.relpath(os.path.join(folder, name), self.root))
                    self.assertIn(channels, (3, 4))
                    self.assertTrue(8 <= w <= 256 and 8 <= h <= 256, name)
                    self.assertEqual((len(rows), len(rows[0])), (h, w))


if __name__ == "__main__":
    parser = argparse.ArgumentParser()
    parser.add_argument("--repo", required=True)
    parser.add_argument("--work", required=True)
    ARGS, rest = parser.parse_known_args()
    unittest.main(argv=[sys.argv[0]] + rest, verbosity=1)
