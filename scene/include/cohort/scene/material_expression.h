// Material register expressions ("time * 0.5", "flickertable[ time ]", "parm0 * 2"). Cohort renders
// one instant, so an expression is evaluated once: time 0, entity parms at their defaults (parm0-3
// = 1, others 0), tables looked up at the evaluated index. Anything time- or table-dependent is an
// approximation, which the context records so that the caller can warn once.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "cohort/scene/lexer.h"

namespace cohort::scene {

struct MaterialTable {
  std::vector<float> values;
  bool snap = false, clamp = false;
  float lookup(float index) const;
};

// Tables by lower-case name.
using MaterialTables = std::map<std::string, MaterialTable>;

struct ExpressionContext {
  const MaterialTables* tables = nullptr;
  bool approximated = false;    // time, sound, globals or a table lookup took part
  std::string approximation;    // the first such term, for the warning
};

// Parses one expression from the lexer and returns its value; ParseError on a malformed one.
float parse_expression(Lexer& lex, ExpressionContext& context);

// The text between the braces of `table name { [snap] [clamp] { v, v, ... } }`, to the lexer's end.
MaterialTable parse_table_body(Lexer& lex);

}  // namespace cohort::scene
