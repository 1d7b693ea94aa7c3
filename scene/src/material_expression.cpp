#include "cohort/scene/material_expression.h"

#include <cmath>

#include "ascii_case.h"

namespace cohort::scene {

namespace {

constexpr int kMaxDepth = 64;   // nested parentheses/brackets; deeper input is rejected, not recursed

int precedence(const Token& t) {
  if (t.kind != Token::Kind::Punct) return 0;
  const std::string& op = t.text;
  if (op == "*" || op == "/" || op == "%") return 4;
  if (op == "+" || op == "-") return 3;
  if (op == ">" || op == ">=" || op == "<" || op == "<=" || op == "==" || op == "!=") return 2;
  if (op == "&&" || op == "||") return 1;
  return 0;
}

float apply(const std::string& op, float a, float b) {
  if (op == "*") return a * b;
  if (op == "/") return b != 0.0f ? a / b : 0.0f;
  if (op == "%") {
    int ib = static_cast<int>(b);
    return ib != 0 && std::fabs(a) < 2.0e9f ? static_cast<float>(static_cast<int>(a) % ib) : 0.0f;
  }
  if (op == "+") return a + b;
  if (op == "-") return a - b;
  if (op == ">") return a > b;
  if (op == ">=") return a >= b;
  if (op == "<") return a < b;
  if (op == "<=") return a <= b;
  if (op == "==") return a == b;
  if (op == "!=") return a != b;
  if (op == "&&") return a != 0.0f && b != 0.0f;
  return a != 0.0f || b != 0.0f;
}

void note(ExpressionContext& context, const std::string& what) {
  if (!context.approximated) context.approximation = what;
  context.approximated = true;
}

float parse_binary(Lexer& lex, ExpressionContext& context, int min_precedence, int depth);

float parse_term(Lexer& lex, ExpressionContext& context, int depth) {
  if (depth > kMaxDepth) lex.fail(lex.peek(), "expression nested too deeply");
  Token t = lex.expect_any("an expression");
  if (t.kind == Token::Kind::Number) return static_cast<float>(t.number);
  if (t.is("-")) return -parse_term(lex, context, depth + 1);
  if (t.is("(")) {
    float v = parse_binary(lex, context, 1, depth + 1);
    lex.expect(")");
    return v;
  }
  if (t.kind != Token::Kind::Name) lex.fail(t, "bad term '" + t.text + "' in an expression");
  std::string name = lowercase(t.text);
  if (name == "time") {
    note(context, "time");
    return 0.0f;
  }
  if (name.rfind("parm", 0) == 0 && name.size() > 4) {
    int index = std::atoi(name.c_str() + 4);
    return index < 4 ? 1.0f : 0.0f;
  }
  if (name.rfind("global", 0) == 0 && name.size() > 6) {
    note(context, t.text);
    return 0.0f;
  }
  if (name == "fragmentprograms") return 1.0f;
  if (name == "sound") {
    note(context, "sound");
    return 0.0f;
  }
  if (lex.peek().is("[")) {
    lex.next();
    float index = parse_binary(lex, context, 1, depth + 1);
    lex.expect("]");
    note(context, "table " + t.text);
    if (context.tables) {
      auto found = context.tables->find(name);
      if (found != context.tables->end()) return found->second.lookup(index);
    }
    return 1.0f;
  }
  lex.fail(t, "unknown name '" + t.text + "' in an expression");
}

float parse_binary(Lexer& lex, ExpressionContext& context, int min_precedence, int depth) {
  float left = parse_term(lex, context, depth);
  for (;;) {
    int p = precedence(lex.peek());
    if (p < min_precedence || p == 0) return left;
    std::string op = lex.next().text;
    float right = parse_binary(lex, context, p + 1, depth + 1);
    left = apply(op, left, right);
  }
}

}  // namespace

float MaterialTable::lookup(float index) const {
  if (values.empty()) return 1.0f;
  if (!std::isfinite(index)) return values[0];
  const float n = static_cast<float>(values.size());
  float scaled = index * n;
  if (clamp) {
    scaled = std::fmin(std::fmax(scaled, 0.0f), n - 1.0f);
  } else {
    scaled = std::fmod(scaled, n);
    if (scaled < 0.0f) scaled += n;
  }
  size_t i0 = static_cast<size_t>(scaled);
  if (i0 >= values.size()) i0 = values.size() - 1;
  if (snap) return values[i0];
  size_t i1 = clamp ? std::min(i0 + 1, values.size() - 1) : (i0 + 1) % values.size();
  float f = scaled - static_cast<float>(i0);
  return values[i0] * (1.0f - f) + values[i1] * f;
}

float parse_expression(Lexer& lex, ExpressionContext& context) { return parse_binary(lex, context, 1, 0); }

MaterialTable parse_table_body(Lexer& lex) {
  MaterialTable table;
  while (!lex.at_end()) {
    Token t = lex.next();
    if (t.is("snap")) {
      table.snap = true;
    } else if (t.is("clamp")) {
      table.clamp = true;
    } else if (t.is("{")) {
      while (!lex.accept("}")) {
        table.values.push_back(lex.expect_float("a table value"));
        lex.accept(",");
      }
    } else {
      lex.fail(t, "unexpected '" + t.text + "' in a table");
    }
  }
  return table;
}

}  // namespace cohort::scene
