#include "cohort/scene/decl_file.h"
#include "cohort/scene/lexer.h"
#include "cohort/scene/model_file.h"
#include "ascii_case.h"

namespace cohort::scene {

namespace {

std::string where(const Lexer& lex, const Token& t) { return lex.file() + ":" + std::to_string(t.line); }

// entityDef body: quoted "key" "value" pairs. Anything else defaults the decl (engine: MakeDefault).
bool parse_entity_def(Lexer& lex, EntityDefDecl& def, std::vector<std::string>& warnings) {
  for (;;) {
    Token t = lex.expect_any("a key or '}'");
    if (t.kind == Token::Kind::Punct && t.text == "}") return true;
    if (t.kind != Token::Kind::String) {
      warnings.push_back(where(lex, t) + ": entityDef " + def.name + ": expected a quoted key, found '" + t.text +
                         "'; the def is defaulted");
      if (t.kind == Token::Kind::Punct && t.text == "{") lex.skip_braced_block();
      lex.skip_braced_block();
      def.keys = {{"DEFAULTED", "1"}};
      return false;
    }
    Token value = lex.expect_any("a value");
    if (value.kind != Token::Kind::String && value.kind != Token::Kind::Name && value.kind != Token::Kind::Number)
      lex.fail(value, "entityDef " + def.name + ": key \"" + t.text + "\" has no value");
    for (auto& [key, old] : def.keys) {
      if (equals_ignoring_case(key, t.text)) {
        warnings.push_back(where(lex, t) + ": entityDef " + def.name + ": key \"" + t.text +
                           "\" set twice; the last value wins");
        old = value.text;
        goto next;
      }
    }
    def.keys.emplace_back(t.text, value.text);
  next:;
  }
}

// modelDef body (idDeclModelDef::Parse): inherit, mesh, skin, offset, channel, anim, remove.
void parse_model_def(Lexer& lex, ModelDefDecl& def, std::vector<std::string>& warnings) {
  for (;;) {
    Token t = lex.expect_any("a modelDef keyword or '}'");
    if (t.is("}")) return;
    if (t.is("inherit")) {
      def.inherit = lex.expect_string("an inherited modelDef");
    } else if (t.is("mesh")) {
      def.mesh = lex.expect_string("a mesh file");
      if (!ends_with_ignoring_case(def.mesh, ".md5mesh"))
        warnings.push_back(where(lex, t) + ": modelDef " + def.name + ": mesh '" + def.mesh + "' is not an .md5mesh");
    } else if (t.is("skin")) {
      def.skin = lex.expect_string("a skin name");
    } else if (t.is("offset")) {
      float v[3];
      lex.expect_vector(v, 3, "the offset");
      def.offset = {v[0], v[1], v[2]};
    } else if (t.is("channel")) {
      lex.expect_string("a channel name");
      lex.expect("(");
      while (!lex.accept(")")) lex.expect_any("a joint name or ')'");
    } else if (t.is("anim")) {
      std::string name = lex.expect_string("an anim name");
      std::string file = lex.expect_string("an md5anim file");
      while (lex.accept(",")) lex.expect_string("an md5anim file");
      if (lex.accept("{")) lex.skip_braced_block();
      def.anims.emplace_back(std::move(name), std::move(file));
    } else if (t.is("remove")) {
      lex.expect_string("an anim name");
    } else {
      warnings.push_back(where(lex, t) + ": modelDef " + def.name + ": unknown keyword '" + t.text + "'; ignored");
    }
  }
}

// skin body (idDeclSkin::Parse): pairs from -> to; `model <name>` pairs are editor hints.
void parse_skin(Lexer& lex, SkinDecl& skin) {
  for (;;) {
    Token from = lex.expect_any("a material name or '}'");
    if (from.kind == Token::Kind::Punct && from.text == "}") return;
    std::string to = lex.expect_string("the material it becomes");
    if (from.kind != Token::Kind::String && from.is("model")) continue;
    skin.remaps.emplace_back(from.text == "*" ? "*" : canonical_decl_name(from.text), canonical_decl_name(to));
  }
}

}  // namespace

DeclFile parse_decls(std::string_view text, const std::string& file_name, std::string_view default_type) {
  Lexer lex(text, file_name);
  DeclFile out;
  while (!lex.at_end()) {
    Token first = lex.next();
    if (first.kind != Token::Kind::Name && first.kind != Token::Kind::String)
      lex.fail(first, "expected a decl type or name, found '" + first.text + "'");
    std::string type(default_type), name = first.text;
    if (!(lex.peek().kind == Token::Kind::Punct && lex.peek().text == "{")) {
      type = first.text;
      name = lex.expect_string("a decl name");
    }
    Token open = lex.next();
    if (!open.is("{")) lex.fail(open, "expected '{' after decl " + name + ", found '" + open.text + "'");
    if (equals_ignoring_case(type, "entityDef")) {
      EntityDefDecl def{name, file_name, first.line, {}};
      parse_entity_def(lex, def, out.warnings);
      out.entity_defs.push_back(std::move(def));
    } else if (equals_ignoring_case(type, "model")) {
      ModelDefDecl def;
      def.name = name;
      def.file = file_name;
      def.line = first.line;
      parse_model_def(lex, def, out.warnings);
      out.model_defs.push_back(std::move(def));
    } else if (equals_ignoring_case(type, "skin")) {
      SkinDecl skin{name, file_name, first.line, {}};
      parse_skin(lex, skin);
      out.skins.push_back(std::move(skin));
    } else {
      lex.skip_braced_block();   // material, table, mapDef, fx, particle, af, ...
    }
  }
  return out;
}

std::string apply_skin(const SkinDecl& skin, const std::string& material) {
  std::string key = canonical_decl_name(material);
  for (const auto& [from, to] : skin.remaps)
    if (from == "*" || from == key) return to;
  return material;
}

}  // namespace cohort::scene
