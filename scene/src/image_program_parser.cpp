#include "cohort/scene/image_program.h"

#include <sstream>

#include "ascii_case.h"

namespace cohort::scene {

namespace {

constexpr int kMaxNesting = 16;

bool is_function(const std::string& lower_name) {
  static const char* const kFunctions[] = {"heightmap", "addnormals", "smoothnormals", "add", "scale",
                                           "invertalpha", "invertcolor", "makeintensity", "makealpha", "downsize"};
  for (const char* f : kFunctions)
    if (lower_name == f) return true;
  return false;
}

ImageProgram parse(Lexer& lex, int depth) {
  if (depth > kMaxNesting) lex.fail(lex.peek(), "image program nested too deeply");
  Token t = lex.expect_any("an image name");
  if (t.kind != Token::Kind::Name && t.kind != Token::Kind::String)
    lex.fail(t, "expected an image name, found '" + t.text + "'");
  ImageProgram program;
  std::string lower = lowercase(t.text);
  if (t.kind == Token::Kind::Name && is_function(lower) && lex.peek().is("(")) {
    lex.next();
    program.function = lower;
    for (bool first = true; !lex.accept(")"); first = false) {
      if (!first) lex.expect(",");
      const Token& arg = lex.peek();
      if (arg.kind == Token::Kind::Number || arg.is("-")) {
        program.numbers.push_back(lex.expect_float("an image program number"));
      } else {
        program.inputs.push_back(parse(lex, depth + 1));
      }
    }
    if (program.inputs.empty()) lex.fail(t, program.function + "() needs an image argument");
    return program;
  }
  program.path = t.text;
  return program;
}

}  // namespace

std::string ImageProgram::text() const {
  if (function.empty()) return path;
  std::ostringstream out;
  out << function << '(';
  bool first = true;
  for (const ImageProgram& input : inputs) {
    out << (first ? "" : ", ") << input.text();
    first = false;
  }
  for (float n : numbers) {
    out << (first ? "" : ", ") << n;
    first = false;
  }
  out << ')';
  return out.str();
}

ImageProgram parse_image_program(Lexer& lex) { return parse(lex, 0); }

}  // namespace cohort::scene
