#include <gtest/gtest.h>

#include <cmath>

#include "cohort/scene/proc_file.h"
#include "test_files.h"

using namespace cohort::scene;
using cohort::scene::test::data_dir;
using cohort::scene::test::read_text;

TEST(ProcParser, ReadsAreasInlineModelsPortalsAndNodes) {
  ProcFile proc = parse_proc(read_text(data_dir() / "base/maps/two_rooms.proc"), "two_rooms.proc");
  ASSERT_EQ(proc.models.size(), 3u);
  EXPECT_EQ(proc.area_count, 2);
  EXPECT_EQ(proc.shadow_models_skipped, 1);

  const ProcModel& area0 = proc.models[0];
  EXPECT_EQ(area0.mesh.name, "_area0");
  EXPECT_EQ(area0.area, 0);
  EXPECT_EQ(area0.mesh.vertices.size(), 4u);
  EXPECT_EQ(area0.mesh.triangle_count(), 2u);
  EXPECT_EQ(area0.surface_materials, std::vector<std::string>{"textures/test/floor"});
  EXPECT_FLOAT_EQ(area0.mesh.vertices[2].position.x, 64.0f);
  EXPECT_FLOAT_EQ(area0.mesh.vertices[2].st.y, -1.0f);

  const ProcModel& area1 = proc.models[1];
  ASSERT_EQ(area1.mesh.surfaces.size(), 2u);
  EXPECT_EQ(area1.mesh.surfaces[1].first_index, 3u);
  EXPECT_EQ(area1.mesh.surfaces[1].index_count, 3u);
  EXPECT_EQ(area1.mesh.indices[3], 3u);  // second surface's indices are offset past the first's vertices
  EXPECT_EQ(area1.surface_materials[1], "textures/test/wall");

  EXPECT_EQ(proc.models[2].area, -1);
  EXPECT_EQ(proc.models[2].mesh.name, "func_static_crate");

  ASSERT_EQ(proc.portals.size(), 1u);
  EXPECT_EQ(proc.portals[0].area_pos, 1);
  EXPECT_EQ(proc.portals[0].area_neg, 0);
  ASSERT_EQ(proc.portals[0].points.size(), 4u);
  EXPECT_FLOAT_EQ(proc.portals[0].points[2].z, 64.0f);
  ASSERT_EQ(proc.nodes.size(), 1u);
  EXPECT_FLOAT_EQ(proc.nodes[0].plane.w, -64.0f);
  EXPECT_EQ(proc.nodes[0].pos_child, -2);
}

TEST(ProcParser, TangentsFollowTextureS) {
  ProcFile proc = parse_proc(read_text(data_dir() / "base/maps/two_rooms.proc"), "two_rooms.proc");
  for (const Vertex& v : proc.models[0].mesh.vertices) {
    // s grows along +x on the floor quad; t decreases along +y, so the bitangent (+t) points to -y.
    EXPECT_NEAR(v.tangent.x, 1.0f, 1e-5f);
    EXPECT_NEAR(v.tangent.y, 0.0f, 1e-5f);
    float bitangent_y = (glm::cross(v.normal, glm::vec3(v.tangent)) * v.tangent.w).y;
    EXPECT_LT(bitangent_y, 0.0f);
  }
}

TEST(ProcParser, DegenerateTexCoordsStillGiveAUnitTangentPerpendicularToTheNormal) {
  ProcFile proc = parse_proc(
      "mapProcFile003 model { \"m\" 1 { \"x\" 3 3 ( 0 0 0 0 0 0 0 1 ) ( 1 0 0 0 0 0 0 1 ) ( 0 1 0 0 0 0 0 1 ) 0 1 2 } }",
      "inline.proc");
  for (const Vertex& v : proc.models[0].mesh.vertices) {
    glm::vec3 t(v.tangent);
    EXPECT_NEAR(glm::length(t), 1.0f, 1e-5f);
    EXPECT_NEAR(glm::dot(t, v.normal), 0.0f, 1e-5f);
  }
}

struct BrokenFile {
  const char* file;
  int line;
  const char* message_part;
};

class BrokenProc : public ::testing::TestWithParam<BrokenFile> {};

TEST_P(BrokenProc, GivesFileLineAndMessage) {
  const BrokenFile& b = GetParam();
  try {
    parse_proc(read_text(data_dir() / "broken" / b.file), b.file);
    FAIL() << b.file << " parsed without error";
  } catch (const ParseError& e) {
    EXPECT_EQ(e.file(), b.file);
    EXPECT_EQ(e.line(), b.line) << e.what();
    EXPECT_NE(std::string(e.what()).find(b.message_part), std::string::npos) << e.what();
    EXPECT_EQ(std::string(e.what()).rfind(std::string(b.file) + ":" + std::to_string(b.line) + ":", 0), 0u) << e.what();
  }
}

INSTANTIATE_TEST_SUITE_P(
    Files, BrokenProc,
    ::testing::Values(BrokenFile{"truncated.proc", 5, "end of file"},
                      BrokenFile{"wrong_vertex_count.proc", 5, "expected a number for an index, found '('"},
                      BrokenFile{"index_out_of_range.proc", 5, "index 7 out of range"},
                      BrokenFile{"huge_count.proc", 3, "more than the rest of the file can hold"},
                      BrokenFile{"bad_number.proc", 4, "found 'zero'"},
                      BrokenFile{"unterminated_comment.proc", 2, "unterminated /* comment"}),
    [](const auto& info) {
      std::string n = info.param.file;
      for (char& c : n)
        if (!isalnum(static_cast<unsigned char>(c))) c = '_';
      return n;
    });

TEST(ProcParser, RejectsOtherFormatsAndUnknownSections) {
  EXPECT_THROW(parse_proc("PROC \"4\"", "q4.proc"), ParseError);
  EXPECT_THROW(parse_proc("mapProcFile003 bogus { }", "x.proc"), ParseError);
  EXPECT_THROW(parse_proc("", "empty.proc"), ParseError);
  EXPECT_THROW(parse_proc("mapProcFile003 model { \"m\" 1 { \"x\" 3 4 ( 0 0 0 0 0 0 0 1 ) ( 0 0 0 0 0 0 0 1 ) "
                          "( 0 0 0 0 0 0 0 1 ) 0 1 2 0 } }", "x.proc"),
               ParseError);  // index count not a multiple of 3
}
