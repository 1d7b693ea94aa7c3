#include "cohort/scene/lexer.h"
#include "cohort/scene/map_file.h"
#include "ascii_case.h"

namespace cohort::scene {

namespace {

// A primitive after its opening "{": brushDef3 { ... }, patchDef2 { ... }, or an old-style brush of
// plane lines. Only the nesting is checked; the contents belong to the map compiler.
void skip_primitive(Lexer& lex, MapEntity& entity, MapFile& map, const Token& open) {
  const Token& kind = lex.peek();
  if (kind.is("brushDef3") || kind.is("brushDef2") || kind.is("brushDef")) {
    ++entity.brush_count;
  } else if (kind.is("patchDef2") || kind.is("patchDef3")) {
    ++entity.patch_count;
  } else if (kind.is("(")) {
    ++entity.brush_count;  // Version 1 brush: plane lines straight inside the braces
  } else if (kind.kind == Token::Kind::End) {
    lex.fail(kind, "unexpected end of file inside a primitive");
  } else if (kind.kind == Token::Kind::Name) {
    map.warnings.push_back(lex.file() + ":" + std::to_string(kind.line) + ": unknown primitive '" + kind.text +
                           "' skipped");
  } else {
    lex.fail(kind, "expected a primitive (brushDef3, patchDef2, ...) after '{', found '" + kind.text + "'");
  }
  (void)open;
  lex.skip_braced_block();
}

}  // namespace

std::optional<std::string> MapEntity::get(std::string_view key) const {
  for (auto it = keys.rbegin(); it != keys.rend(); ++it)
    if (equals_ignoring_case(it->first, key)) return it->second;
  return std::nullopt;
}

std::string MapEntity::get_or(std::string_view key, std::string_view fallback) const {
  auto v = get(key);
  return v ? *v : std::string(fallback);
}

MapFile parse_map(std::string_view text, const std::string& file_name) {
  Lexer lex(text, file_name);
  MapFile map;
  if (lex.peek().is("Version")) {
    lex.next();
    Token at = lex.peek();
    long long version = lex.expect_integer("the map version");
    if (version < 1 || version > 3) lex.fail(at, "unsupported map version " + std::to_string(version));
    map.version = static_cast<int>(version);
  } else {
    map.version = 1;
  }
  while (!lex.at_end()) {
    Token open = lex.next();
    if (!open.is("{")) lex.fail(open, "expected '{' to start an entity, found '" + open.text + "'");
    MapEntity entity;
    entity.line = open.line;
    for (;;) {
      Token t = lex.next();
      if (t.kind == Token::Kind::End) lex.fail(open, "entity is not closed before the end of the file");
      if (t.kind == Token::Kind::Punct && t.text == "}") break;
      if (t.kind == Token::Kind::Punct && t.text == "{") {
        skip_primitive(lex, entity, map, t);
        continue;
      }
      if (t.kind != Token::Kind::String) lex.fail(t, "expected a quoted key, '{' or '}' in an entity, found '" + t.text + "'");
      Token value = lex.next();
      if (value.kind != Token::Kind::String)
        lex.fail(value, "expected a quoted value for key \"" + t.text + "\"");
      entity.keys.emplace_back(std::move(t.text), std::move(value.text));
    }
    map.entities.push_back(std::move(entity));
  }
  return map;
}

}  // namespace cohort::scene
