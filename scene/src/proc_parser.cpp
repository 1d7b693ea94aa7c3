#include <algorithm>
#include <cctype>
#include <charconv>

#include "cohort/scene/lexer.h"
#include "cohort/scene/proc_file.h"
#include "cohort/scene/tangents.h"

namespace cohort::scene {

namespace {

// The fewest characters each item can take in the text, used to reject counts the file cannot hold.
constexpr size_t kMinVertexBytes = 16;   // "(0 0 0 0 0 0 0 0)"
constexpr size_t kMinIndexBytes = 2;     // "0 "
constexpr size_t kMinSurfaceBytes = 8;   // "{\"\" 0 0}"
constexpr size_t kMinPortalBytes = 6;    // "0 0 0 "
constexpr size_t kMinPointBytes = 7;     // "(0 0 0)"
constexpr size_t kMinNodeBytes = 13;     // "(0 0 0 0) 0 0"

int area_number(const std::string& name) {
  if (name.size() < 6 || name.compare(0, 5, "_area") != 0) return -1;
  int n = -1;
  auto [end, ec] = std::from_chars(name.data() + 5, name.data() + name.size(), n);
  if (ec != std::errc() || end != name.data() + name.size() || n < 0) return -1;
  return n;
}

void parse_surface(Lexer& lex, ProcModel& model) {
  lex.expect("{");
  Token material_token = lex.peek();
  std::string material = lex.expect_string("a material name");
  size_t vertex_count = lex.expect_count("vertex count", kMinVertexBytes);
  Token index_count_token = lex.peek();
  size_t index_count = lex.expect_count("index count", kMinIndexBytes);
  if (index_count % 3 != 0)
    lex.fail(index_count_token, "index count " + std::to_string(index_count) + " is not a multiple of 3");

  Mesh& mesh = model.mesh;
  const size_t base = mesh.vertices.size();
  if (base + vertex_count > 0xffffffffull) lex.fail(material_token, "model has too many vertices");
  mesh.vertices.reserve(base + vertex_count);
  for (size_t i = 0; i < vertex_count; ++i) {
    float v[8];
    lex.expect_vector(v, 8, "a vertex (x y z s t nx ny nz)");
    Vertex vertex;
    vertex.position = {v[0], v[1], v[2]};
    vertex.st = {v[3], v[4]};
    vertex.normal = {v[5], v[6], v[7]};
    mesh.vertices.push_back(vertex);
  }
  Surface surface;
  surface.first_index = static_cast<uint32_t>(mesh.indices.size());
  surface.index_count = static_cast<uint32_t>(index_count);
  mesh.indices.reserve(mesh.indices.size() + index_count);
  for (size_t i = 0; i < index_count; ++i) {
    Token at = lex.peek();
    long long index = lex.expect_integer("an index");
    if (index < 0 || static_cast<size_t>(index) >= vertex_count)
      lex.fail(at, "index " + std::to_string(index) + " out of range for a surface of " +
                       std::to_string(vertex_count) + " vertices");
    mesh.indices.push_back(static_cast<uint32_t>(base + static_cast<size_t>(index)));
  }
  lex.expect("}");
  mesh.surfaces.push_back(surface);
  model.surface_materials.push_back(std::move(material));
}

ProcModel parse_model(Lexer& lex) {
  lex.expect("{");
  ProcModel model;
  model.mesh.name = lex.expect_string("a model name");
  model.area = area_number(model.mesh.name);
  size_t surface_count = lex.expect_count("surface count", kMinSurfaceBytes);
  for (size_t i = 0; i < surface_count; ++i) parse_surface(lex, model);
  lex.expect("}");
  compute_tangents(model.mesh);
  return model;
}

void parse_portals(Lexer& lex, ProcFile& proc) {
  lex.expect("{");
  Token area_token = lex.peek();
  size_t area_count = lex.expect_count("area count", 0);
  if (area_count > 1000000) lex.fail(area_token, "area count " + std::to_string(area_count) + " is implausible");
  proc.area_count = static_cast<int>(area_count);
  size_t portal_count = lex.expect_count("portal count", kMinPortalBytes);
  proc.portals.reserve(portal_count);
  for (size_t i = 0; i < portal_count; ++i) {
    size_t point_count = lex.expect_count("portal point count", kMinPointBytes);
    Portal portal;
    for (int* side : {&portal.area_pos, &portal.area_neg}) {
      Token at = lex.peek();
      long long area = lex.expect_integer("a portal area");
      if (area < 0 || area >= static_cast<long long>(area_count))
        lex.fail(at, "portal area " + std::to_string(area) + " out of range (" + std::to_string(area_count) + " areas)");
      *side = static_cast<int>(area);
    }
    portal.points.reserve(point_count);
    for (size_t p = 0; p < point_count; ++p) {
      float xyz[3];
      lex.expect_vector(xyz, 3, "a portal point");
      portal.points.emplace_back(xyz[0], xyz[1], xyz[2]);
    }
    proc.portals.push_back(std::move(portal));
  }
  lex.expect("}");
}

void parse_nodes(Lexer& lex, ProcFile& proc) {
  lex.expect("{");
  size_t node_count = lex.expect_count("node count", kMinNodeBytes);
  proc.nodes.reserve(node_count);
  for (size_t i = 0; i < node_count; ++i) {
    AreaNode node;
    float plane[4];
    lex.expect_vector(plane, 4, "a node plane");
    node.plane = {plane[0], plane[1], plane[2], plane[3]};
    for (int* child : {&node.pos_child, &node.neg_child}) {
      Token at = lex.peek();
      long long c = lex.expect_integer("a node child");
      if (c >= static_cast<long long>(node_count) || c < -1000000000ll)
        lex.fail(at, "node child " + std::to_string(c) + " out of range (" + std::to_string(node_count) + " nodes)");
      *child = static_cast<int>(c);
    }
    proc.nodes.push_back(node);
  }
  lex.expect("}");
}

}  // namespace

ProcFile parse_proc(std::string_view text, const std::string& file_name) {
  Lexer lex(text, file_name);
  Token header = lex.next();
  if (!header.is("mapProcFile003"))
    lex.fail(header, "not a Doom 3 .proc file (expected mapProcFile003, found '" + header.text + "')");
  ProcFile proc;
  int highest_area = -1;
  while (!lex.at_end()) {
    Token section = lex.next();
    if (section.is("model")) {
      proc.models.push_back(parse_model(lex));
      highest_area = std::max(highest_area, proc.models.back().area);
    } else if (section.is("shadowModel")) {
      lex.expect("{");
      lex.skip_braced_block();
      ++proc.shadow_models_skipped;
    } else if (section.is("interAreaPortals")) {
      parse_portals(lex, proc);
    } else if (section.is("nodes")) {
      parse_nodes(lex, proc);
    } else {
      lex.fail(section, "unknown .proc section '" + section.text + "'");
    }
  }
  if (highest_area >= proc.area_count) {
    if (!proc.portals.empty())
      throw ParseError(file_name, lex.last_line(), 0,
                       "model _area" + std::to_string(highest_area) + " beyond the " + std::to_string(proc.area_count) +
                           " areas of interAreaPortals");
    proc.area_count = highest_area + 1;
  }
  for (const AreaNode& node : proc.nodes)
    for (int child : {node.pos_child, node.neg_child})
      if (child < 0 && -1 - child >= proc.area_count && proc.area_count > 0)
        throw ParseError(file_name, lex.last_line(), 0,
                         "node child names area " + std::to_string(-1 - child) + " beyond the " +
                             std::to_string(proc.area_count) + " areas");
  return proc;
}

}  // namespace cohort::scene
