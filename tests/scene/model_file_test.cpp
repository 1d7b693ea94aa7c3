// ASE, LWO and MD5 readers against small files whose expected meshes are worked out by hand from the
// engine's rules (doom3-content.md sections 4-5), and against broken files that must fail with file:line.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "cohort/scene/md5.h"
#include "cohort/scene/model_file.h"
#include "test_files.h"

using namespace cohort::scene;

namespace {

// The vertex of the surface's k-th index.
const Vertex& corner(const ModelFile& m, size_t surface, size_t k) {
  return m.mesh.vertices[m.mesh.indices[m.mesh.surfaces[surface].first_index + k]];
}

void expect_vec(glm::vec3 got, glm::vec3 want, float tolerance = 1e-4f) {
  EXPECT_NEAR(got.x, want.x, tolerance);
  EXPECT_NEAR(got.y, want.y, tolerance);
  EXPECT_NEAR(got.z, want.z, tolerance);
}

// "file:N:" for the line holding needle.
std::string at_line_of(const std::string& file, const std::string& text, const std::string& needle) {
  size_t at = text.find(needle);
  return file + ":" + std::to_string(1 + std::count(text.begin(), text.begin() + static_cast<long>(at), '\n')) + ":";
}

template <typename F>
std::string parse_error_of(F f) {
  try {
    f();
  } catch (const ParseError& e) {
    return e.what();
  }
  return "(no error)";
}

// --- ASE ---------------------------------------------------------------------------------------------

const char* kAseTriangle = R"(*3DSMAX_ASCIIEXPORT	200
*COMMENT "one triangle"
*SCENE {
	*SCENE_FILENAME "x.max"
}
*MATERIAL_LIST {
	*MATERIAL_COUNT 2
	*MATERIAL 0 {
		*MATERIAL_NAME "ignored"
		*MAP_DIFFUSE {
			*BITMAP "C:\doom\base\Models\Props\Crate.TGA"
			*UVW_U_OFFSET 0.25
			*UVW_V_OFFSET 0.5
			*UVW_U_TILING 2
			*UVW_V_TILING 1
			*UVW_ANGLE 0
		}
	}
	*MATERIAL 1 {
		*SUBMATERIAL 0 { *MAP_DIFFUSE { *BITMAP "D:\base\textures\a.tga" } }
		*SUBMATERIAL 1 { *MAP_DIFFUSE { *BITMAP "D:\base\textures\b.tga" } *MAP_BUMP { *BITMAP "D:\base\textures\c.tga" } }
	}
}
*GEOMOBJECT {
	*NODE_NAME "tri"
	*NODE_TM {
		*TM_ROW0 0 1 0
		*TM_ROW1 -1 0 0
		*TM_ROW2 0 0 1
		*TM_ROW3 100 0 0
	}
	*MESH {
		*MESH_NUMVERTEX 3
		*MESH_NUMFACES 1
		*MESH_VERTEX_LIST {
			*MESH_VERTEX 0 0 0 0
			*MESH_VERTEX 1 10 0 0
			*MESH_VERTEX 2 0 10 0
		}
		*MESH_FACE_LIST {
			*MESH_FACE 0: A: 0 B: 1 C: 2 AB: 1 BC: 1 CA: 1 *MESH_SMOOTHING 1 *MESH_MTLID 0
		}
		*MESH_NUMTVERTEX 3
		*MESH_TVERTLIST {
			*MESH_TVERT 0 0 0 0
			*MESH_TVERT 1 1 0 0
			*MESH_TVERT 2 0 1 0
		}
		*MESH_NUMTVFACES 1
		*MESH_TFACELIST {
			*MESH_TFACE 0 0 1 2
		}
		*MESH_NUMCVERTEX 1
		*MESH_CVERTLIST {
			*MESH_VERTCOL 0 1 0.5 0
		}
		*MESH_NUMCVFACES 1
		*MESH_CFACELIST {
			*MESH_CFACE 0 0 0 0
		}
		*MESH_NORMALS {
			*MESH_FACENORMAL 0 0 0 1
			*MESH_VERTEXNORMAL 0 1 0 0
			*MESH_VERTEXNORMAL 1 0 0 1
			*MESH_VERTEXNORMAL 2 0 0 1
		}
	}
	*MATERIAL_REF 0
}
*GEOMOBJECT {
	*NODE_NAME "second"
	*MESH {
		*MESH_NUMVERTEX 3
		*MESH_NUMFACES 1
		*MESH_VERTEX_LIST {
			*MESH_VERTEX 0 0 0 5
			*MESH_VERTEX 1 0 10 5
			*MESH_VERTEX 2 10 0 5
		}
		*MESH_FACE_LIST {
			*MESH_FACE 0: A: 0 B: 1 C: 2
		}
	}
	*MATERIAL_REF 1
}
)";

TEST(AseParser, FacesTurnedMaterialFromBitmapStTransformedNormalsRotatedColours) {
  ModelFile m = parse_ase(kAseTriangle, "tri.ase");
  ASSERT_EQ(m.mesh.surfaces.size(), 2u);
  EXPECT_EQ(m.surface_materials[0], "models/props/crate");
  EXPECT_EQ(m.surface_materials[1], "textures/b");   // last diffuse bitmap of the sub-materials; bump ignored
  ASSERT_EQ(m.mesh.surfaces[0].index_count, 3u);
  // (A, B, C) = (0, 1, 2) is stored (A, C, B): positions as in the file, no NODE_TM applied.
  expect_vec(corner(m, 0, 0).position, {0, 0, 0});
  expect_vec(corner(m, 0, 1).position, {0, 10, 0});
  expect_vec(corner(m, 0, 2).position, {10, 0, 0});
  // st: t = 1 - v, then u * 2 - 0.25 and t * 1 + 0.5.
  EXPECT_NEAR(corner(m, 0, 0).st.x, -0.25f, 1e-6f);
  EXPECT_NEAR(corner(m, 0, 0).st.y, 1.5f, 1e-6f);
  EXPECT_NEAR(corner(m, 0, 2).st.x, 1.75f, 1e-6f);   // tvert 1 (1, 0)
  EXPECT_NEAR(corner(m, 0, 1).st.y, 0.5f, 1e-6f);    // tvert 2 (0, 1)
  // Vertex normal (1 0 0) of vertex 0, turned by the NODE_TM rows: x * row0 = (0 1 0).
  expect_vec(corner(m, 0, 0).normal, {0, 1, 0});
  expect_vec(corner(m, 0, 1).normal, {0, 0, 1});
  // Colours: 1 0.5 0 as bytes (0.5 * 255 rounds to 128), alpha 1.
  ASSERT_EQ(m.mesh.colors.size(), m.mesh.vertices.size());
  glm::vec4 c = unpack_rgba8(m.mesh.colors[m.mesh.indices[0]]);
  EXPECT_NEAR(c.r, 1.0f, 1e-6f);
  EXPECT_NEAR(c.g, 128.0f / 255.0f, 1e-6f);
  EXPECT_NEAR(c.b, 0.0f, 1e-6f);
  EXPECT_NEAR(c.a, 1.0f, 1e-6f);
  // The second object has no normals: generated from its face, clockwise front = (p2-p0)x(p1-p0).
  const Vertex& g = corner(m, 1, 0);
  glm::vec3 face = glm::normalize(glm::cross(corner(m, 1, 2).position - g.position, corner(m, 1, 1).position - g.position));
  expect_vec(g.normal, face);
  expect_vec(face, {0, 0, -1});   // Max's counter-clockwise front of (0,0)->(0,10)->(10,0) faces -z
  EXPECT_TRUE(m.warnings.empty());
}

TEST(AseParser, CornersWeldWithinAnObject) {
  const char* quad = R"(*GEOMOBJECT { *MESH {
    *MESH_NUMVERTEX 4 *MESH_NUMFACES 2
    *MESH_VERTEX_LIST { *MESH_VERTEX 0 0 0 0
    *MESH_VERTEX 1 1 0 0
    *MESH_VERTEX 2 1 1 0
    *MESH_VERTEX 3 0 1 0
    }
    *MESH_FACE_LIST { *MESH_FACE 0: A: 0 B: 1 C: 2
    *MESH_FACE 1: A:0 B:2 C:3
    }
  } })";
  ModelFile m = parse_ase(quad, "quad.ase");
  EXPECT_EQ(m.mesh.vertices.size(), 4u);
  EXPECT_EQ(m.mesh.indices.size(), 6u);
  EXPECT_EQ(m.surface_materials, std::vector<std::string>{"_default"});
}

TEST(AseParser, BrokenFilesNameFileAndLine) {
  std::string text = kAseTriangle;
  std::string bad_face = text;
  bad_face.replace(bad_face.find("C: 2 AB"), 4, "C: 7");
  EXPECT_NE(parse_error_of([&] { parse_ase(bad_face, "m.ase"); }).find(at_line_of("m.ase", bad_face, "C: 7")), std::string::npos)
      << parse_error_of([&] { parse_ase(bad_face, "m.ase"); });
  std::string bad_ref = text;
  bad_ref.replace(bad_ref.find("*MATERIAL_REF 1"), 15, "*MATERIAL_REF 5");
  EXPECT_NE(parse_error_of([&] { parse_ase(bad_ref, "m.ase"); }).find("*MATERIAL_REF 5 out of range"), std::string::npos);
  std::string bad_tv = text;
  bad_tv.replace(bad_tv.find("*MESH_NUMTVFACES 1"), 18, "*MESH_NUMTVFACES 2");
  EXPECT_NE(parse_error_of([&] { parse_ase(bad_tv, "m.ase"); }).find("differs from *MESH_NUMFACES"), std::string::npos);
  std::string tface_first = R"(*GEOMOBJECT { *MESH { *MESH_NUMVERTEX 3 *MESH_NUMFACES 1
    *MESH_NUMTVERTEX 1 *MESH_TVERTLIST { *MESH_TVERT 0 0 0 0 }
    *MESH_NUMTVFACES 1 *MESH_TFACELIST { *MESH_TFACE 0 0 0 0 } } })";
  EXPECT_NE(parse_error_of([&] { parse_ase(tface_first, "t.ase"); }).find("t.ase:3:"), std::string::npos);
  EXPECT_NE(parse_error_of([&] { parse_ase(text.substr(0, text.size() / 2), "cut.ase"); }).find("cut.ase:"),
            std::string::npos);
  EXPECT_NE(parse_error_of([&] { parse_ase("*GEOMOBJECT { *MESH { *MESH_NUMVERTEX 1 *MESH_NUMFACES 1 } }", "e.ase"); })
                .find("face 0"),
            std::string::npos);
}

// --- LWO ---------------------------------------------------------------------------------------------

struct IffWriter {
  std::string bytes;
  void id(const char* s) { bytes.append(s, 4); }
  void u2(unsigned v) { bytes += char(v >> 8); bytes += char(v & 0xff); }
  void u4(uint32_t v) { for (int s = 24; s >= 0; s -= 8) bytes += char((v >> s) & 0xff); }
  void f4(float f) { uint32_t b; std::memcpy(&b, &f, 4); u4(b); }
  void s0(const std::string& s) { bytes += s; bytes += '\0'; if ((s.size() + 1) % 2) bytes += '\0'; }
};

std::string chunk(const char* id, const std::string& payload) {
  IffWriter w;
  w.id(id);
  w.u4(uint32_t(payload.size()));
  w.bytes += payload;
  if (payload.size() % 2) w.bytes += '\0';
  return w.bytes;
}

std::string form(const std::string& body, const char* type = "LWO2") {
  IffWriter w;
  w.id("FORM");
  w.u4(uint32_t(body.size() + 4));
  w.id(type);
  return w.bytes + body;
}

// Two triangles sharing an edge (a square in LightWave's x/z floor plane at height y = 2) and a quad.
std::string lwo_square(bool with_uv = true) {
  IffWriter tags, pnts, pols, ptag, vmap, surf;
  tags.s0("Models/Floor.tga");
  tags.s0("second");
  const float points[5][3] = {{0, 2, 0}, {4, 2, 0}, {4, 2, 4}, {0, 2, 4}, {9, 9, 9}};
  for (auto& p : points) for (float f : p) pnts.f4(f);
  pols.id("FACE");
  for (auto tri : {std::array<int, 3>{0, 1, 2}, std::array<int, 3>{0, 2, 3}}) {
    pols.u2(3);
    for (int i : tri) pols.u2(unsigned(i));
  }
  pols.u2(4);
  for (int i : {0, 1, 2, 4}) pols.u2(unsigned(i));
  ptag.id("SURF");
  for (int p = 0; p < 3; ++p) { ptag.u2(unsigned(p)); ptag.u2(p == 1 ? 1 : 0); }
  vmap.id("TXUV"); vmap.u2(2); vmap.s0("uv");
  for (int p = 0; p < 4; ++p) { vmap.u2(unsigned(p)); vmap.f4(points[p][0] / 4); vmap.f4(points[p][2] / 4); }
  surf.s0("Models/Floor.tga"); surf.s0("");
  surf.id("COLR"); surf.u2(14); surf.f4(1.0f); surf.f4(0.5f); surf.f4(0.25f); surf.u2(0);
  std::string body = chunk("TAGS", tags.bytes) + chunk("LAYR", std::string(16, '\0')) + chunk("PNTS", pnts.bytes) +
                     chunk("POLS", pols.bytes) + chunk("PTAG", ptag.bytes) + (with_uv ? chunk("VMAP", vmap.bytes) : "") +
                     chunk("SURF", surf.bytes);
  return form(body);
}

TEST(LwoParser, AxesSwappedVFlippedSurfacesByTagColoursFromSurf) {
  ModelFile m = parse_lwo(lwo_square(), "sq.lwo");
  ASSERT_EQ(m.mesh.surfaces.size(), 2u);
  EXPECT_EQ(m.surface_materials[0], "models/floor");   // canonical: lower case, extension dropped
  EXPECT_EQ(m.surface_materials[1], "second");
  // LightWave (x, y, z) -> idTech (x, z, y); indices in file order.
  expect_vec(corner(m, 0, 0).position, {0, 0, 2});
  expect_vec(corner(m, 0, 1).position, {4, 0, 2});
  expect_vec(corner(m, 0, 2).position, {4, 4, 2});
  EXPECT_NEAR(corner(m, 0, 1).st.x, 1.0f, 1e-6f);
  EXPECT_NEAR(corner(m, 0, 2).st.y, 0.0f, 1e-6f);     // v = 1 -> t = 0
  EXPECT_NEAR(corner(m, 0, 0).st.y, 1.0f, 1e-6f);
  // LW normal (p1-p0)x(p2-p0) = (0,-16,0)... points down in LW (y), so -z in idTech.
  expect_vec(corner(m, 0, 0).normal, {0, 0, -1});
  // And the idTech winding agrees: (p2-p0)x(p1-p0) is the front.
  glm::vec3 p0 = corner(m, 0, 0).position, p1 = corner(m, 0, 1).position, p2 = corner(m, 0, 2).position;
  expect_vec(glm::normalize(glm::cross(p2 - p0, p1 - p0)), {0, 0, -1});
  // Colour: SURF COLR for the defined surface, 200/255 grey for the tag without a SURF.
  glm::vec4 defined = unpack_rgba8(m.mesh.colors[m.mesh.indices[m.mesh.surfaces[0].first_index]]);
  glm::vec4 fallback = unpack_rgba8(m.mesh.colors[m.mesh.indices[m.mesh.surfaces[1].first_index]]);
  EXPECT_NEAR(defined.g, 128.0f / 255.0f, 1e-6f);
  EXPECT_NEAR(fallback.r, 200.0f / 255.0f, 1e-6f);
  ASSERT_EQ(m.warnings.size(), 1u);   // the quad
  EXPECT_NE(m.warnings[0].find("1 polygons are not triangles"), std::string::npos);
}

TEST(LwoParser, NoUvMapWarns) {
  ModelFile m = parse_lwo(lwo_square(false), "sq.lwo");
  EXPECT_EQ(m.warnings.size(), 2u);
  EXPECT_EQ(corner(m, 0, 1).st, glm::vec2(0.0f, 1.0f));
}

TEST(LwoParser, BrokenFilesNameFileAndByte) {
  std::string good = lwo_square();
  EXPECT_NE(parse_error_of([&] { parse_lwo(good.substr(0, 40), "cut.lwo"); }).find("cut.lwo: byte"), std::string::npos);
  std::string bad_type = good;
  bad_type.replace(8, 4, "ILBM");
  EXPECT_NE(parse_error_of([&] { parse_lwo(bad_type, "x.lwo"); }).find("neither LWO2 nor LWOB"), std::string::npos);
  std::string bad_index = good;
  size_t pols = bad_index.find("POLS");
  bad_index[pols + 8 + 4 + 2 + 1] = 9;   // first polygon's first point -> 9 of 5
  EXPECT_NE(parse_error_of([&] { parse_lwo(bad_index, "x.lwo"); }).find("point 9 out of range"), std::string::npos);
  EXPECT_NE(parse_error_of([&] { parse_lwo("FORM", "x.lwo"); }).find("x.lwo: byte 4: truncated"), std::string::npos);
}

// --- MD5 ---------------------------------------------------------------------------------------------

// Two joints: a root at the origin and a child at (0 0 10) turned by the stored quaternion (0 0 s) with
// s = sin 45 deg, which the engine applies to row vectors: a -90 degree turn about z for column vectors.
const char* kMd5Mesh = R"(MD5Version 10
commandline "test"
numJoints 2
numMeshes 1
joints {
	"root" -1 ( 0 0 0 ) ( 0 0 0 )
	"child" 0 ( 0 0 10 ) ( 0 0 0.7071068 )		// turned
}
mesh {
	shader "models/test/Skin.tga"
	numverts 3
	vert 0 ( 0 0 ) 0 1
	vert 1 ( 1 0 ) 1 1
	vert 2 ( 0 1 ) 2 2
	numtris 1
	tri 0 0 1 2
	numweights 4
	weight 0 0 1 ( 0 0 0 )
	weight 1 1 1 ( 1 0 0 )
	weight 2 0 0.5 ( 0 2 0 )
	weight 3 1 0.5 ( 2 0 0 )
}
)";

const char* kMd5Anim = R"(MD5Version 10
commandline "test"
numFrames 3
numJoints 2
frameRate 10
numAnimatedComponents 2
hierarchy {
	"root" -1 1 0
	"child" 0 32 1
}
bounds {
	( 0 0 0 ) ( 1 1 1 )
	( 0 0 0 ) ( 1 1 1 )
	( 0 0 0 ) ( 1 1 1 )
}
baseframe {
	( 5 0 0 ) ( 0 0 0 )
	( 0 0 10 ) ( 0 0 0 )
}
frame 0 {
	5 0
}
frame 1 {
	7 0.7071068
}
frame 2 {
	9 0
}
)";

TEST(Md5, BindPoseSkinsWithTheEnginesRotationConvention) {
  Md5Mesh mesh = parse_md5mesh(kMd5Mesh, "t.md5mesh");
  ASSERT_EQ(mesh.joints.size(), 2u);
  ModelFile m = skin_md5(mesh, bind_pose(mesh));
  EXPECT_EQ(m.surface_materials, std::vector<std::string>{"models/test/skin"});
  expect_vec(m.mesh.vertices[0].position, {0, 0, 0});
  // child: R (column form) turns x to -y: (1 0 0) -> (0 -1 0), plus (0 0 10).
  expect_vec(m.mesh.vertices[1].position, {0, -1, 10});
  // 0.5 * (0 2 0) + 0.5 * ((0 -2 0) + (0 0 10)) = (0 0 5)
  expect_vec(m.mesh.vertices[2].position, {0, 0, 5});
  EXPECT_EQ(m.mesh.vertices[1].st, glm::vec2(1, 0));
  // Normals regenerated from the skinned triangle (clockwise front).
  glm::vec3 a = m.mesh.vertices[0].position, b = m.mesh.vertices[1].position, c = m.mesh.vertices[2].position;
  expect_vec(m.mesh.vertices[0].normal, glm::normalize(glm::cross(c - a, b - a)));
  // Scale (entity parm8) scales offsets and positions about the origin.
  expect_vec(skin_md5(mesh, bind_pose(mesh), 2.0f).mesh.vertices[1].position, {0, -2, 20});
}

TEST(Md5, AnimationFramesInterpolateAndRootMotionIsRelative) {
  Md5Mesh mesh = parse_md5mesh(kMd5Mesh, "t.md5mesh");
  Md5Anim anim = parse_md5anim(kMd5Anim, "t.md5anim");
  check_anim_matches(mesh, anim);
  EXPECT_EQ(anim.length_ms(), 200);
  // Root Tx: the baseframe's 5 is subtracted, so frames hold 0, 2, 4; total delta = last frame's.
  EXPECT_NEAR(anim.total_delta.x, 4.0f, 1e-6f);
  auto f1 = anim_frame_pose(anim, 1);
  expect_vec(f1[0].position, {2, 0, 0});
  expect_vec(f1[1].position, {2, 0, 10});
  expect_vec(f1[1].rotation * glm::vec3(1, 0, 0), {0, -1, 0});
  // 50 ms at 10 fps: halfway between frames 0 and 1: Tx 1, the child turned -45 degrees.
  auto half = anim_pose(anim, 50);
  expect_vec(half[0].position, {1, 0, 0});
  float r = std::sqrt(0.5f);
  expect_vec(half[1].rotation * glm::vec3(1, 0, 0), {r, -r, 0});
  // Looping: 200 ms is frame 0 of the next cycle (the last frame is only a lerp target).
  auto wrapped = anim_pose(anim, 200);
  expect_vec(wrapped[0].position, {0, 0, 0});
  // The pose skins the mesh: vertex 1 at frame 1 = (2 0 10) + (0 -1 0).
  expect_vec(skin_md5(mesh, f1).mesh.vertices[1].position, {2, -1, 10});
}

TEST(Md5, MismatchedHierarchyNamesBothFiles) {
  Md5Mesh mesh = parse_md5mesh(kMd5Mesh, "a.md5mesh");
  std::string renamed = kMd5Anim;
  renamed.replace(renamed.find("\"child\""), 7, "\"other\"");
  Md5Anim anim = parse_md5anim(renamed, "b.md5anim");
  try {
    check_anim_matches(mesh, anim);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("b.md5anim does not fit a.md5mesh"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("'other'"), std::string::npos);
  }
}

TEST(Md5, BrokenFilesNameFileAndLine) {
  std::string mesh = kMd5Mesh;
  auto broken = [&](const std::string& from, const std::string& to) {
    std::string text = mesh;
    text.replace(text.find(from), from.size(), to);
    std::string error = parse_error_of([&] { parse_md5mesh(text, "b.md5mesh"); });
    return error + " [expected at " + at_line_of("b.md5mesh", text, to) + "]";
  };
  auto at_expected_line = [](const std::string& error) {
    size_t open = error.find(" [expected at ");
    std::string where = error.substr(open + 14, error.size() - open - 15);
    return error.rfind(where, 0) == 0;
  };
  EXPECT_TRUE(at_expected_line(broken("weight 3 1 0.5", "weight 3 4 0.5")));
  EXPECT_TRUE(at_expected_line(broken("tri 0 0 1 2", "tri 0 0 1 3")));
  EXPECT_TRUE(at_expected_line(broken("\"child\" 0", "\"child\" 1")));
  EXPECT_NE(broken("vert 2 ( 0 1 ) 2 2", "vert 2 ( 0 1 ) 3 2").find("run past numweights"), std::string::npos);
  EXPECT_NE(broken("vert 1 ( 1 0 ) 1 1", "vert 1 ( 1 0 ) 1 0").find("has no weights"), std::string::npos);
  EXPECT_NE(broken("MD5Version 10", "MD5Version 11").find("not 10"), std::string::npos);
  std::string anim = kMd5Anim;
  auto broken_anim = [&](const std::string& from, const std::string& to) {
    std::string text = anim;
    text.replace(text.find(from), from.size(), to);
    return parse_error_of([&] { parse_md5anim(text, "b.md5anim"); });
  };
  EXPECT_NE(broken_anim("\"child\" 0 32 1", "\"child\" -1 32 1").find("second root"), std::string::npos);
  EXPECT_NE(broken_anim("\"child\" 0 32 1", "\"child\" 0 96 1").find("out of range (0..63)"), std::string::npos);
  EXPECT_NE(broken_anim("\"child\" 0 32 1", "\"child\" 0 32 2").find("past numAnimatedComponents"), std::string::npos);
  std::string renumbered = anim;
  renumbered.replace(renumbered.find("frame 1 {"), 9, "frame 2 {");
  EXPECT_NE(broken_anim("frame 1 {", "frame 2 {").find(at_line_of("b.md5anim", renumbered, "frame 2 {")), std::string::npos);
}

TEST(PlaceholderModel, ClosedCubeOfHalfSizeEightFacingOut) {
  ModelFile m = placeholder_model("missing.lwo");
  EXPECT_EQ(m.mesh.triangle_count(), 12u);
  for (size_t t = 0; t < m.mesh.triangle_count(); ++t) {
    glm::vec3 p0 = m.mesh.vertices[m.mesh.indices[t * 3]].position, p1 = m.mesh.vertices[m.mesh.indices[t * 3 + 1]].position,
              p2 = m.mesh.vertices[m.mesh.indices[t * 3 + 2]].position;
    glm::vec3 front = glm::cross(p2 - p0, p1 - p0);
    EXPECT_GT(glm::dot(front, (p0 + p1 + p2) / 3.0f), 0.0f);   // faces away from the centre
    EXPECT_FLOAT_EQ(std::max({std::abs(p0.x), std::abs(p0.y), std::abs(p0.z)}), 8.0f);
  }
}

TEST(CanonicalDeclName, LowerCaseSlashesNoExtension) {
  EXPECT_EQ(canonical_decl_name("Models\\Foo\\Bar.TGA"), "models/foo/bar");
  EXPECT_EQ(canonical_decl_name("a.b/c"), "a.b/c");
  EXPECT_EQ(canonical_decl_name("x.y.z"), "x.y");
}

}  // namespace

namespace {

TEST(LwoParser, LwobSurfacesFromSrfsDetailPolygonsAndByteColours) {
  std::string bytes = cohort::scene::test::read_text(std::filesystem::path(COHORT_SOURCE_DIR) /
                                                     "scene/fuzz/corpus/lwo/square.lwob.lwo");
  ModelFile m = parse_lwo(bytes, "square.lwo");
  EXPECT_EQ(m.surface_materials, std::vector<std::string>{"textures/lwob"});
  EXPECT_EQ(m.mesh.triangle_count(), 3u);   // the detail polygon is read as an ordinary one
  glm::vec4 c = unpack_rgba8(m.mesh.colors.at(0));
  EXPECT_NEAR(c.r, 1.0f, 1e-6f);
  EXPECT_NEAR(c.g, 128.0f / 255.0f, 1e-6f);
  EXPECT_NEAR(c.b, 0.0f, 1e-6f);
  ASSERT_EQ(m.warnings.size(), 1u);   // LWOB has no UVs
  // LightWave's z = 0 plane is idTech's y = 0: the first polygon's normal (0 0 1) in LW becomes (0 1 0);
  // the third is wound the other way, and at 180 degrees apart FLAG's smoothing does not mix them.
  for (size_t k = 0; k < 3; ++k) expect_vec(m.mesh.vertices[m.mesh.indices[k]].normal, {0, 1, 0});
  for (size_t k = 6; k < 9; ++k) expect_vec(m.mesh.vertices[m.mesh.indices[k]].normal, {0, -1, 0});
}

}  // namespace

// --- Vertex colours ------------------------------------------------------------------------------

namespace {

glm::vec4 corner_color(const ModelFile& m, size_t surface, size_t k) {
  return unpack_rgba8(m.mesh.colors.at(m.mesh.indices[m.mesh.surfaces[surface].first_index + k]));
}

void expect_rgba(glm::vec4 got, glm::vec4 want) {
  EXPECT_NEAR(got.r, want.r, 1e-6f);
  EXPECT_NEAR(got.g, want.g, 1e-6f);
  EXPECT_NEAR(got.b, want.b, 1e-6f);
  EXPECT_NEAR(got.a, want.a, 1e-6f);
}

// One triangle whose three corners have their own colour (red, green, blue) through a CFACE that names
// them out of order, and a second object without colours.
const char* kAseColoured = R"(*3DSMAX_ASCIIEXPORT	200
*GEOMOBJECT {
	*NODE_NAME "coloured"
	*MESH {
		*MESH_NUMVERTEX 3
		*MESH_NUMFACES 1
		*MESH_VERTEX_LIST {
			*MESH_VERTEX 0 0 0 0
			*MESH_VERTEX 1 10 0 0
			*MESH_VERTEX 2 0 10 0
		}
		*MESH_FACE_LIST {
			*MESH_FACE 0: A: 0 B: 1 C: 2
		}
		*MESH_NUMCVERTEX 3
		*MESH_CVERTLIST {
			*MESH_VERTCOL 0 1 0 0
			*MESH_VERTCOL 1 0 1 0
			*MESH_VERTCOL 2 0 0 1.5
		}
		*MESH_NUMCVFACES 1
		*MESH_CFACELIST {
			*MESH_CFACE 0 2 0 1
		}
	}
}
*GEOMOBJECT {
	*NODE_NAME "plain"
	*MESH {
		*MESH_NUMVERTEX 3
		*MESH_NUMFACES 1
		*MESH_VERTEX_LIST {
			*MESH_VERTEX 0 0 0 5
			*MESH_VERTEX 1 0 10 5
			*MESH_VERTEX 2 10 0 5
		}
		*MESH_FACE_LIST {
			*MESH_FACE 0: A: 0 B: 1 C: 2
		}
	}
}
)";

}  // namespace

TEST(AseParser, CornerColoursFollowTheTurnedCFaceAndObjectsWithoutColoursAreWhite) {
  ModelFile m = parse_ase(kAseColoured, "colours.ase");
  ASSERT_EQ(m.mesh.surfaces.size(), 1u);   // both objects use the default material
  ASSERT_EQ(m.mesh.colors.size(), m.mesh.vertices.size());
  // CFACE (a, b, c) = (2, 0, 1) is stored (a, c, b) like the face: corner 0 blue, 1 green, 2 red.
  expect_vec(corner(m, 0, 0).position, {0, 0, 0});
  expect_rgba(corner_color(m, 0, 0), {0, 0, 1, 1});   // 1.5 clamps to 1
  expect_rgba(corner_color(m, 0, 1), {0, 1, 0, 1});
  expect_rgba(corner_color(m, 0, 2), {1, 0, 0, 1});
  // The second object's triangle: no CVERTLIST, white like the engine's ASE default.
  for (size_t k = 3; k < 6; ++k) expect_rgba(corner_color(m, 0, k), {1, 1, 1, 1});
}

TEST(AseParser, BrokenColourDataNamesFileAndLine) {
  const std::string text = kAseColoured;
  auto error_of = [](const std::string& bad) { return parse_error_of([&] { parse_ase(bad, "c.ase"); }); };
  std::string cface_index = text;
  cface_index.replace(cface_index.find("*MESH_CFACE 0 2 0 1"), 19, "*MESH_CFACE 0 2 0 3");
  std::string e = error_of(cface_index);
  EXPECT_NE(e.find(at_line_of("c.ase", cface_index, "*MESH_CFACE 0 2 0 3")), std::string::npos) << e;
  EXPECT_NE(e.find("*MESH_CFACE index 3 out of range (3)"), std::string::npos) << e;

  std::string cface_number = text;
  cface_number.replace(cface_number.find("*MESH_CFACE 0 2 0 1"), 19, "*MESH_CFACE 4 2 0 1");
  e = error_of(cface_number);
  EXPECT_NE(e.find(at_line_of("c.ase", cface_number, "*MESH_CFACE 4")), std::string::npos) << e;
  EXPECT_NE(e.find("*MESH_CFACE number 4 out of range"), std::string::npos) << e;

  std::string vertcol = text;
  vertcol.replace(vertcol.find("*MESH_VERTCOL 2 0 0 1.5"), 23, "*MESH_VERTCOL 7 0 0 1.5");
  e = error_of(vertcol);
  EXPECT_NE(e.find(at_line_of("c.ase", vertcol, "*MESH_VERTCOL 7")), std::string::npos) << e;
  EXPECT_NE(e.find("*MESH_VERTCOL number 7 out of range (3)"), std::string::npos) << e;

  std::string component = text;
  component.replace(component.find("*MESH_VERTCOL 1 0 1 0"), 21, "*MESH_VERTCOL 1 0 one 0");
  e = error_of(component);
  EXPECT_NE(e.find(at_line_of("c.ase", component, "*MESH_VERTCOL 1 0 one")), std::string::npos) << e;

  std::string face_count = text;
  face_count.replace(face_count.find("*MESH_NUMCVFACES 1"), 18, "*MESH_NUMCVFACES 2");
  e = error_of(face_count);
  EXPECT_NE(e.find("c.ase:"), std::string::npos) << e;
  EXPECT_NE(e.find("*MESH_NUMCVFACES 2 differs from *MESH_NUMFACES 1 in object coloured"), std::string::npos) << e;

  // A colour vertex count given again, smaller, after the CFACE that indexed past it.
  std::string shrunk = text;
  shrunk.replace(shrunk.find("\t}\n}\n*GEOMOBJECT"), 0, "\t\t*MESH_NUMCVERTEX 1\n");
  e = error_of(shrunk);
  EXPECT_NE(e.find("c.ase:"), std::string::npos) << e;
  EXPECT_NE(e.find("*MESH_CFACE colour vertex 2 out of range (1) in object coloured"), std::string::npos) << e;
}

namespace {

// lwo_square's two triangles (points 0 1 2 and 0 2 3) with a colour vertex map of the given type and
// dimension on points 0-3 (point p: (p/3, 1 - p/3, 0.5, alpha 0.25) or RGB without alpha), and a
// VMAD that gives point 2 its own colour on polygon 1 only.
std::string lwo_coloured(const char* type, int dimension, uint32_t bad_point = 0) {
  IffWriter tags, pnts, pols, ptag, vmap, vmad;
  tags.s0("textures/vc");
  const float points[4][3] = {{0, 0, 0}, {4, 0, 0}, {4, 0, 4}, {0, 0, 4}};
  for (auto& p : points) for (float f : p) pnts.f4(f);
  pols.id("FACE");
  for (auto tri : {std::array<int, 3>{0, 1, 2}, std::array<int, 3>{0, 2, 3}}) {
    pols.u2(3);
    for (int i : tri) pols.u2(unsigned(i));
  }
  ptag.id("SURF");
  for (int p = 0; p < 2; ++p) { ptag.u2(unsigned(p)); ptag.u2(0); }
  vmap.id(type); vmap.u2(unsigned(dimension)); vmap.s0("colours");
  for (uint32_t p = 0; p < 4; ++p) {
    vmap.u2(p == 3 && bad_point ? bad_point : p);
    const float rgba[4] = {float(p) / 3.0f, 1.0f - float(p) / 3.0f, 0.5f, 0.25f};
    for (int k = 0; k < dimension; ++k) vmap.f4(rgba[k]);
  }
  vmad.id(type); vmad.u2(unsigned(dimension)); vmad.s0("colours");
  vmad.u2(2); vmad.u2(1);
  const float override_rgba[4] = {0.0f, 0.0f, 1.0f, 1.0f};
  for (int k = 0; k < dimension; ++k) vmad.f4(override_rgba[k]);
  std::string body = chunk("TAGS", tags.bytes) + chunk("LAYR", std::string(16, '\0')) + chunk("PNTS", pnts.bytes) +
                     chunk("POLS", pols.bytes) + chunk("PTAG", ptag.bytes) + chunk("VMAP", vmap.bytes) +
                     chunk("VMAD", vmad.bytes);
  return form(body);
}

}  // namespace

TEST(LwoParser, RgbaAndRgbVertexMapsColourTheCornersAndVmadOverridesPerPolygon) {
  for (int dimension : {4, 3}) {
    SCOPED_TRACE(dimension == 4 ? "RGBA" : "RGB");
    ModelFile m = parse_lwo(lwo_coloured(dimension == 4 ? "RGBA" : "RGB ", dimension), "vc.lwo");
    ASSERT_EQ(m.mesh.colors.size(), m.mesh.vertices.size());
    const float alpha = dimension == 4 ? 64.0f / 255.0f : 1.0f;   // 0.25 as a byte; RGB is opaque
    // Polygon 0 = points 0 1 2 from the VMAP, bytes rounded (1/3 -> 85).
    expect_rgba(corner_color(m, 0, 0), {0, 1, 128.0f / 255.0f, alpha});
    expect_rgba(corner_color(m, 0, 1), {85.0f / 255.0f, 170.0f / 255.0f, 128.0f / 255.0f, alpha});
    expect_rgba(corner_color(m, 0, 2), {170.0f / 255.0f, 85.0f / 255.0f, 128.0f / 255.0f, alpha});
    // Polygon 1 = points 0 2 3: point 2 takes the VMAD's blue on this polygon only.
    expect_rgba(corner_color(m, 0, 3), {0, 1, 128.0f / 255.0f, alpha});
    expect_rgba(corner_color(m, 0, 4), {0, 0, 1, 1});
    expect_rgba(corner_color(m, 0, 5), {1, 0, 128.0f / 255.0f, alpha});
  }
}

TEST(LwoParser, ColourMapsOfOtherDimensionsAreIgnoredAndBadPointsNamed) {
  // An RGBA map written with dimension 3 is not one the engine reads: the surface colour stays.
  ModelFile m = parse_lwo(lwo_coloured("RGBA", 3), "odd.lwo");
  expect_rgba(corner_color(m, 0, 0), {200.0f / 255.0f, 200.0f / 255.0f, 200.0f / 255.0f, 1});
  std::string e = parse_error_of([] { parse_lwo(lwo_coloured("RGBA", 4, 9), "bad.lwo"); });
  EXPECT_NE(e.find("bad.lwo: byte"), std::string::npos) << e;
  EXPECT_NE(e.find("point 9 out of range"), std::string::npos) << e;
  std::string cut = lwo_coloured("RGB ", 3);
  cut.resize(cut.find("VMAD") + 8 + 6);   // the VMAD chunk header says more than the file holds
  e = parse_error_of([&] { parse_lwo(cut, "cut.lwo"); });
  EXPECT_NE(e.find("cut.lwo: byte"), std::string::npos) << e;
}

TEST(PackRgba8, RoundsClampsAndPutsRedInTheLowByte) {
  EXPECT_EQ(pack_rgba8({1, 0, 0, 1}), 0xFF0000FFu);
  EXPECT_EQ(pack_rgba8({0.5f, -1, 2, 0}), 0x00FF0080u);
  EXPECT_EQ(pack_rgba8({std::nanf(""), 0, 0, 0}), 0u);
  EXPECT_EQ(unpack_rgba8(0x80FF0040u), glm::vec4(64, 0, 255, 128) / 255.0f);
}
