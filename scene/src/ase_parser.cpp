// ASE reader after the engine's Model_ase.cpp: see docs in model_file.h and doom3-content.md section 4.
#include <cctype>
#include <charconv>
#include <cmath>

#include "cohort/scene/lexer.h"
#include "cohort/scene/model_file.h"
#include "ascii_case.h"
#include "model_builder.h"

namespace cohort::scene {

namespace {

constexpr size_t kMinListItemBytes = 8;   // "*MESH_VERTEX 0 0 0 0" and the like, at the least

struct AseMaterial {
  std::string name;
  float u_offset = 0, v_offset = 0, u_tiling = 1, v_tiling = 1, angle = 0;
};

struct AseFace {
  uint32_t v[3] = {0, 0, 0};      // stored (A, C, B): idTech's clockwise fronts
  uint32_t tv[3] = {0, 0, 0};
  uint32_t cv[3] = {0, 0, 0};
  glm::vec3 normals[3]{};
  bool has_normal[3] = {false, false, false};
  bool listed = false;
};

struct AseObject {
  std::string name;
  int line = 0;
  glm::vec3 rows[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  std::vector<glm::vec3> vertices;
  std::vector<glm::vec2> tverts;
  std::vector<glm::vec3> cverts;
  std::vector<AseFace> faces;
  size_t tface_count = 0, cface_count = 0;
  int material_ref = -1;
};

// The bitmap path as a material name: from after the path's "base" folder, no extension (OSPathToRelativePath).
std::string material_from_bitmap(const std::string& bitmap) {
  std::string path = bitmap;
  for (char& c : path)
    if (c == '\\') c = '/';
  std::string lower = lowercase(path);
  size_t at = 0;
  for (;;) {
    size_t found = lower.find("base/", at);
    if (found == std::string::npos) return "";
    if (found == 0 || lower[found - 1] == '/') return canonical_decl_name(path.substr(found + 5));
    at = found + 1;
  }
}

class AseParser {
 public:
  AseParser(std::string_view text, const std::string& file) : lex_(text, file), builder_(file) {}

  ModelFile parse() {
    parse_top_level(false);
    if (builder_.triangle_count() == 0) lex_.fail_here("no triangles in any *GEOMOBJECT");
    ModelFile out = builder_.finish(true);
    out.warnings = std::move(warnings_);
    return out;
  }

 private:
  // The next keyword (`*NAME`, upper-cased), "{" / "}", or "" at the end.
  std::string keyword(Token& t) {
    t = lex_.next();
    if (t.kind == Token::Kind::End) return "";
    if (t.kind == Token::Kind::Punct && (t.text == "{" || t.text == "}")) return t.text;
    if (t.kind == Token::Kind::Punct && t.text == "*") {
      // A keyword is everything up to the next blank (the engine splits on bytes <= 32): join the
      // lexer's tokens that touch ("*3DSMAX_ASCIIEXPORT" lexes as '*', 3, DSMAX_ASCIIEXPORT).
      std::string word = "*";
      int line = t.line, column = t.column + 1;
      while (lex_.peek().kind != Token::Kind::End && lex_.peek().kind != Token::Kind::String &&
             lex_.peek().line == line && lex_.peek().column == column && lex_.peek().text != "{" &&
             lex_.peek().text != "}") {
        Token part = lex_.next();
        word += part.text;
        column += static_cast<int>(part.text.size());
      }
      if (word.size() == 1) lex_.fail(t, "expected a keyword after '*'");
      for (char& c : word) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
      return word;
    }
    lex_.fail(t, "expected an ASE *KEYWORD, found '" + t.text + "'");
  }

  // An unknown keyword's arguments: the rest of its line, and a braced block if the line opens one.
  void skip_arguments() {
    int line = lex_.last_line();
    while (!lex_.at_end() && lex_.peek().line == line) {
      Token t = lex_.next();
      if (t.kind == Token::Kind::Punct && t.text == "{") {
        lex_.skip_braced_block();
        return;
      }
      if (t.kind == Token::Kind::Punct && t.text == "}") lex_.fail(t, "unexpected '}'");
    }
  }

  void parse_top_level(bool in_group) {
    for (;;) {
      Token t;
      std::string word = keyword(t);
      if (word.empty()) {
        if (in_group) lex_.fail(t, "unexpected end of file inside *GROUP");
        return;
      }
      if (word == "}") {
        if (!in_group) lex_.fail(t, "unexpected '}'");
        return;
      }
      if (word == "{") lex_.fail(t, "unexpected '{'");
      if (word == "*GROUP") {
        lex_.expect_string("a group name");
        lex_.expect("{");
        parse_top_level(true);
      } else if (word == "*MATERIAL_LIST") {
        parse_material_list();
      } else if (word == "*GEOMOBJECT") {
        parse_geomobject(t.line);
      } else {
        skip_arguments();   // *3DSMAX_ASCIIEXPORT, *COMMENT, *SCENE, *SHAPEOBJECT, *CAMERAOBJECT, ...
      }
    }
  }

  // Walks a block whose "{" was consumed, calling handle(word, token) for each keyword at any depth;
  // handle returns false for keywords it does not know, whose arguments are then skipped.
  template <typename Handle>
  void walk_block(Handle handle) {
    int depth = 1;
    while (depth > 0) {
      Token t;
      std::string word = keyword(t);
      if (word.empty()) lex_.fail(t, "unexpected end of file inside a { } block");
      if (word == "{") ++depth;
      else if (word == "}") --depth;
      else if (!handle(word, t)) skip_arguments_keeping_blocks(depth);
    }
  }
  // As skip_arguments, but a block the line opens is walked (the engine reads nested blocks with the
  // enclosing parser), so it only counts the brace.
  void skip_arguments_keeping_blocks(int& depth) {
    int line = lex_.last_line();
    while (!lex_.at_end() && lex_.peek().line == line) {
      if (lex_.peek().kind == Token::Kind::Punct && (lex_.peek().text == "{" || lex_.peek().text == "}" ||
                                                    lex_.peek().text == "*"))
        return;
      lex_.next();
    }
    (void)depth;
  }

  void parse_material_list() {
    lex_.expect("{");
    walk_block([&](const std::string& word, const Token& at) {
      if (word == "*MATERIAL_COUNT") {
        size_t count = lex_.expect_count("material count", kMinListItemBytes);
        if (count > 100000) lex_.fail(at, "material count " + std::to_string(count) + " is implausible");
        return true;
      }
      if (word != "*MATERIAL") return false;
      long long index = lex_.expect_integer("a material number");
      if (index != static_cast<long long>(materials_.size()))
        lex_.fail(at, "*MATERIAL " + std::to_string(index) + " out of order (expected " +
                          std::to_string(materials_.size()) + ")");
      lex_.expect("{");
      AseMaterial material;
      // Every *MAP_DIFFUSE inside, sub-materials included, sets the bitmap: the last one wins, as in the
      // engine, which has no per-face sub-materials.
      walk_block([&](const std::string& inner, const Token&) {
        if (inner != "*MAP_DIFFUSE") return false;
        lex_.expect("{");
        walk_block([&](const std::string& key, const Token&) {
          if (key == "*BITMAP") material.name = material_from_bitmap(lex_.expect_string("a bitmap path"));
          else if (key == "*UVW_U_OFFSET") material.u_offset = lex_.expect_float("*UVW_U_OFFSET");
          else if (key == "*UVW_V_OFFSET") material.v_offset = lex_.expect_float("*UVW_V_OFFSET");
          else if (key == "*UVW_U_TILING") material.u_tiling = lex_.expect_float("*UVW_U_TILING");
          else if (key == "*UVW_V_TILING") material.v_tiling = lex_.expect_float("*UVW_V_TILING");
          else if (key == "*UVW_ANGLE") material.angle = lex_.expect_float("*UVW_ANGLE");
          else return false;
          return true;
        });
        return true;
      });
      if (material.name.empty()) {
        warnings_.push_back(lex_.file() + ":" + std::to_string(at.line) + ": *MATERIAL " + std::to_string(index) +
                            " has no diffuse *BITMAP under a base folder; using _default");
        material.name = "_default";
      }
      materials_.push_back(material);
      return true;
    });
  }

  uint32_t index_in(const std::string& what, size_t limit) {
    Token at = lex_.peek();
    long long v = lex_.expect_integer(what);
    if (v < 0 || static_cast<size_t>(v) >= limit)
      lex_.fail(at, what + " " + std::to_string(v) + " out of range (" + std::to_string(limit) + ")");
    return static_cast<uint32_t>(v);
  }

  void parse_face(AseObject& object, const Token& at) {
    uint32_t face = index_in("*MESH_FACE number", object.faces.size());
    uint32_t abc[3] = {0, 0, 0};
    bool seen[3] = {false, false, false};
    int line = at.line;
    while (!(seen[0] && seen[1] && seen[2])) {
      Token t = lex_.peek();
      if (t.kind == Token::Kind::End || t.line != line) lex_.fail(at, "*MESH_FACE needs A:, B: and C: vertex numbers");
      lex_.next();
      if (t.kind != Token::Kind::Name || t.text.size() < 2 || t.text[1] != ':') continue;
      int k = ascii_lower(t.text[0]) - 'a';
      if (k < 0 || k > 2) continue;
      if (t.text.size() == 2) {
        abc[k] = index_in("*MESH_FACE vertex", object.vertices.size());
      } else {   // "A:12" written without a blank
        unsigned long long v = 0;
        auto [end, ec] = std::from_chars(t.text.data() + 2, t.text.data() + t.text.size(), v);
        if (ec != std::errc() || end != t.text.data() + t.text.size() || v >= object.vertices.size())
          lex_.fail(t, "*MESH_FACE vertex '" + t.text + "' is not a vertex number below " +
                           std::to_string(object.vertices.size()));
        abc[k] = static_cast<uint32_t>(v);
      }
      seen[k] = true;
    }
    lex_.skip_rest_of_line();   // edge flags, *MESH_SMOOTHING, *MESH_MTLID: the engine ignores them
    AseFace& f = object.faces[face];
    f.v[0] = abc[0];
    f.v[1] = abc[2];
    f.v[2] = abc[1];
    f.listed = true;
  }

  void parse_mesh(AseObject& object) {
    lex_.expect("{");
    size_t face_count = 0, tvface_count = 0, cvface_count = 0;
    bool faces_read = false;
    walk_block([&](const std::string& word, const Token& at) {
      if (word == "*MESH_NUMVERTEX") {
        object.vertices.assign(lex_.expect_count("vertex count", kMinListItemBytes), glm::vec3(0.0f));
      } else if (word == "*MESH_NUMFACES") {
        face_count = lex_.expect_count("face count", kMinListItemBytes);
        object.faces.assign(face_count, AseFace{});
      } else if (word == "*MESH_VERTEX") {
        uint32_t i = index_in("*MESH_VERTEX number", object.vertices.size());
        for (int k = 0; k < 3; ++k) object.vertices[i][k] = lex_.expect_float("a vertex coordinate");
      } else if (word == "*MESH_FACE") {
        parse_face(object, at);
        faces_read = true;
      } else if (word == "*MESH_NUMTVERTEX") {
        object.tverts.assign(lex_.expect_count("texture vertex count", kMinListItemBytes), glm::vec2(0.0f));
      } else if (word == "*MESH_TVERT") {
        uint32_t i = index_in("*MESH_TVERT number", object.tverts.size());
        float u = lex_.expect_float("u"), v = lex_.expect_float("v");
        lex_.expect_float("w");
        object.tverts[i] = {u, 1.0f - v};
      } else if (word == "*MESH_NUMTVFACES") {
        tvface_count = lex_.expect_count("texture face count", kMinListItemBytes);
        object.tface_count = tvface_count;
      } else if (word == "*MESH_TFACE") {
        if (!faces_read) lex_.fail(at, "*MESH_TFACELIST before *MESH_FACE_LIST");
        read_corner_face(object, tvface_count, object.tverts.size(), "*MESH_TFACE", &AseFace::tv);
      } else if (word == "*MESH_NUMCVERTEX") {
        object.cverts.assign(lex_.expect_count("colour vertex count", kMinListItemBytes), glm::vec3(1.0f));
      } else if (word == "*MESH_VERTCOL") {
        uint32_t i = index_in("*MESH_VERTCOL number", object.cverts.size());
        for (int k = 0; k < 3; ++k) object.cverts[i][k] = lex_.expect_float("a colour component");
      } else if (word == "*MESH_NUMCVFACES") {
        cvface_count = lex_.expect_count("colour face count", kMinListItemBytes);
        object.cface_count = cvface_count;
      } else if (word == "*MESH_CFACE") {
        if (!faces_read) lex_.fail(at, "*MESH_CFACELIST before *MESH_FACE_LIST");
        read_corner_face(object, cvface_count, object.cverts.size(), "*MESH_CFACE", &AseFace::cv);
      } else if (word == "*MESH_FACENORMAL") {
        current_normal_face_ = index_in("*MESH_FACENORMAL number", object.faces.size());
        for (int k = 0; k < 3; ++k) lex_.expect_float("a normal component");
        have_normal_face_ = true;
      } else if (word == "*MESH_VERTEXNORMAL") {
        if (!have_normal_face_) lex_.fail(at, "*MESH_VERTEXNORMAL without a *MESH_FACENORMAL before it");
        uint32_t v = index_in("*MESH_VERTEXNORMAL vertex", object.vertices.size());
        glm::vec3 n;
        for (int k = 0; k < 3; ++k) n[k] = lex_.expect_float("a normal component");
        AseFace& f = object.faces[current_normal_face_];
        int corner = f.v[0] == v ? 0 : f.v[1] == v ? 1 : f.v[2] == v ? 2 : -1;
        if (corner < 0) lex_.fail(at, "*MESH_VERTEXNORMAL vertex " + std::to_string(v) + " is not a corner of face " +
                                          std::to_string(current_normal_face_));
        f.normals[corner] = n.x * object.rows[0] + n.y * object.rows[1] + n.z * object.rows[2];
        f.has_normal[corner] = true;
      } else {
        return false;
      }
      return true;
    });
    have_normal_face_ = false;
    if (object.tface_count != 0 && object.tface_count != face_count)
      lex_.fail_here("*MESH_NUMTVFACES " + std::to_string(object.tface_count) + " differs from *MESH_NUMFACES " +
                     std::to_string(face_count) + " in object " + object.name);
    if (object.cface_count != 0 && object.cface_count != face_count)
      lex_.fail_here("*MESH_NUMCVFACES " + std::to_string(object.cface_count) + " differs from *MESH_NUMFACES " +
                     std::to_string(face_count) + " in object " + object.name);
    // A count given again after the faces that index it: those indices must still be in range.
    for (const AseFace& f : object.faces)
      for (int k = 0; k < 3; ++k)
        if (object.cface_count != 0 && f.cv[k] >= object.cverts.size())
          lex_.fail_here("*MESH_CFACE colour vertex " + std::to_string(f.cv[k]) + " out of range (" +
                         std::to_string(object.cverts.size()) + ") in object " + object.name);
  }

  void read_corner_face(AseObject& object, size_t listed, size_t limit, const std::string& what,
                        uint32_t (AseFace::*member)[3]) {
    uint32_t face = index_in(what + " number", std::min(listed, object.faces.size()));
    uint32_t a = index_in(what + " index", limit), b = index_in(what + " index", limit),
             c = index_in(what + " index", limit);
    uint32_t(&out)[3] = object.faces[face].*member;
    out[0] = a;
    out[1] = c;
    out[2] = b;
  }

  void parse_geomobject(int line) {
    lex_.expect("{");
    AseObject object;
    object.line = line;
    walk_block([&](const std::string& word, const Token&) {
      if (word == "*NODE_NAME") {
        object.name = lex_.expect_string("a node name");
      } else if (word == "*NODE_TM") {
        lex_.expect("{");
        walk_block([&](const std::string& key, const Token&) {
          for (int r = 0; r < 3; ++r) {
            if (key == "*TM_ROW" + std::to_string(r)) {
              for (int k = 0; k < 3; ++k) object.rows[r][k] = lex_.expect_float("a *NODE_TM component");
              return true;
            }
          }
          return false;
        });
      } else if (word == "*MESH") {
        parse_mesh(object);
      } else if (word == "*MESH_ANIMATION") {
        lex_.expect("{");
        lex_.skip_braced_block();
      } else if (word == "*MATERIAL_REF") {
        Token at = lex_.peek();
        long long ref = lex_.expect_integer("*MATERIAL_REF");
        if (ref < 0 || static_cast<size_t>(ref) >= materials_.size())
          lex_.fail(at, "*MATERIAL_REF " + std::to_string(ref) + " out of range (" + std::to_string(materials_.size()) +
                            " materials)");
        object.material_ref = static_cast<int>(ref);
      } else {
        return false;
      }
      return true;
    });
    add_object(object);
  }

  void add_object(const AseObject& object) {
    AseMaterial none;
    none.name = "_default";
    const AseMaterial& material =
        object.material_ref >= 0 ? materials_[static_cast<size_t>(object.material_ref)] : (materials_.empty() ? none : materials_[0]);
    if (object.material_ref < 0 && !materials_.empty())
      warnings_.push_back(lex_.file() + ":" + std::to_string(object.line) + ": object " + object.name +
                          " has no *MATERIAL_REF; using material 0");
    const bool use_st = !object.tverts.empty() && object.tface_count == object.faces.size();
    const bool use_color = !object.cverts.empty() && object.cface_count == object.faces.size();
    const float c = std::cos(material.angle), s = std::sin(material.angle);
    for (size_t i = 0; i < object.faces.size(); ++i)
      if (!object.faces[i].listed)
        lex_.fail_here("object " + object.name + " (line " + std::to_string(object.line) + "): face " +
                       std::to_string(i) + " of *MESH_NUMFACES " + std::to_string(object.faces.size()) +
                       " is not in its *MESH_FACE_LIST");
    builder_.begin_group();
    for (const AseFace& f : object.faces) {
      ModelCorner corners[3];
      for (int k = 0; k < 3; ++k) {
        ModelCorner& corner = corners[k];
        corner.position = object.vertices[f.v[k]];
        if (use_st) {
          glm::vec2 st = object.tverts[f.tv[k]];
          float u = st.x * material.u_tiling - material.u_offset, v = st.y * material.v_tiling + material.v_offset;
          corner.st = {u * c + v * s, -u * s + v * c};
        }
        if (f.has_normal[k]) {
          float length = glm::length(f.normals[k]);
          corner.normal = length > 0.0f ? f.normals[k] / length : glm::vec3(0.0f, 0.0f, 1.0f);
          corner.has_normal = true;
        }
        if (use_color) {
          glm::vec3 rgb = glm::clamp(object.cverts[f.cv[k]], 0.0f, 1.0f);
          corner.color = glm::vec4(glm::round(rgb * 255.0f) / 255.0f, 1.0f);
        }
      }
      builder_.add_triangle(material.name, corners);
    }
  }

  Lexer lex_;
  ModelBuilder builder_;
  std::vector<AseMaterial> materials_;
  std::vector<std::string> warnings_;
  uint32_t current_normal_face_ = 0;
  bool have_normal_face_ = false;
};

}  // namespace

ModelFile parse_ase(std::string_view text, const std::string& file_name) { return AseParser(text, file_name).parse(); }

}  // namespace cohort::scene
