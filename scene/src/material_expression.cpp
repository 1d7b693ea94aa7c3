#include "cohort/scene/material_expression.h"

#include <cmath>

#include "ascii_case.h"

namespace cohort::scene {

namespace {

constexpr int kMaxDepth = 64;   // nested parentheses/brackets; deeper input is rejected, not recursed

const char* const kOperators[] = {"*", "/", "%", "+", "-", ">", ">=", "<", "<=", "==", "!=", "&&", "||"};
constexpr int kOperatorCount = int(sizeof(kOperators) / sizeof(kOperators[0]));

int operator_index(const Token& t) {
  // The lexer reads a lone '/' as a path name (material names hold slashes); here it divides.
  if (t.kind != Token::Kind::Punct && !(t.kind == Token::Kind::Name && t.text == "/")) return -1;
  for (int i = 0; i < kOperatorCount; ++i)
    if (t.text == kOperators[i]) return i;
  return -1;
}

// Higher binds tighter.
int precedence(int op) {
  if (op < 0) return 0;
  if (op <= 2) return 4;
  if (op <= 4) return 3;
  if (op <= 10) return 2;
  return 1;
}

float apply(int op, float a, float b) {
  switch (op) {
    case 0: return a * b;
    case 1: return b != 0.0f ? a / b : 0.0f;
    case 2: {
      if (!(std::fabs(a) < 2.0e9f) || !(std::fabs(b) < 2.0e9f)) return 0.0f;
      const int ib = static_cast<int>(b);
      return ib != 0 ? static_cast<float>(static_cast<int>(a) % ib) : 0.0f;
    }
    case 3: return a + b;
    case 4: return a - b;
    case 5: return a > b;
    case 6: return a >= b;
    case 7: return a < b;
    case 8: return a <= b;
    case 9: return a == b;
    case 10: return a != b;
    case 11: return a != 0.0f && b != 0.0f;
    default: return a != 0.0f || b != 0.0f;
  }
}

using Op = Expression::Op;
using OpKind = Expression::OpKind;

void parse_binary(Lexer& lex, ExpressionContext& context, Expression& out, int min_precedence, int depth);

void parse_term(Lexer& lex, ExpressionContext& context, Expression& out, int depth) {
  if (depth > kMaxDepth) lex.fail(lex.peek(), "expression nested too deeply");
  Token t = lex.expect_any("an expression");
  if (t.kind == Token::Kind::Number) {
    out.push(Op{OpKind::Constant, 0, 0, static_cast<float>(t.number)});
    return;
  }
  if (t.is("-")) {
    parse_term(lex, context, out, depth + 1);
    out.push(Op{OpKind::Negate});
    return;
  }
  if (t.is("(")) {
    parse_binary(lex, context, out, 1, depth + 1);
    lex.expect(")");
    return;
  }
  if (t.kind != Token::Kind::Name) lex.fail(t, "bad term '" + t.text + "' in an expression");
  const std::string name = lowercase(t.text);
  auto numbered = [&](const char* prefix, int count) -> int {
    const size_t n = std::char_traits<char>::length(prefix);
    if (name.size() <= n || name.compare(0, n, prefix) != 0) return -1;
    for (size_t i = n; i < name.size(); ++i)
      if (name[i] < '0' || name[i] > '9') return -1;
    const int index = std::atoi(name.c_str() + n);
    if (index >= count) lex.fail(t, "'" + t.text + "' is out of range (0.." + std::to_string(count - 1) + ")");
    return index;
  };
  if (name == "time") {
    out.push(Op{OpKind::Time});
    return;
  }
  if (int parm = numbered("parm", kMaterialParms); parm >= 0) {
    out.push(Op{OpKind::Parm, 0, uint16_t(parm)});
    return;
  }
  if (int global = numbered("global", kMaterialGlobals); global >= 0) {
    out.push(Op{OpKind::Global, 0, uint16_t(global)});
    return;
  }
  if (name == "fragmentprograms") {
    out.push(Op{OpKind::Constant, 0, 0, 1.0f});
    return;
  }
  if (name == "sound") {   // the entity's sound amplitude: Cohort plays no sound
    out.push(Op{OpKind::Constant, 0, 0, 0.0f});
    return;
  }
  if (lex.peek().is("[")) {
    const MaterialTable* table = nullptr;
    if (context.tables) {
      auto found = context.tables->find(name);
      if (found != context.tables->end()) table = &found->second;
    }
    if (!table) lex.fail(t, "unknown table '" + t.text + "' (tables must be declared before use)");
    lex.next();
    parse_binary(lex, context, out, 1, depth + 1);
    lex.expect("]");
    out.push(Op{OpKind::Table, 0, out.add_table(*table)});
    return;
  }
  lex.fail(t, "unknown name '" + t.text + "' in an expression");
}

// The engine parses both operands of a level at that level, so a chain of one level groups to the right.
void parse_binary(Lexer& lex, ExpressionContext& context, Expression& out, int min_precedence, int depth) {
  parse_term(lex, context, out, depth);
  const int op = operator_index(lex.peek());
  const int p = precedence(op);
  if (p == 0 || p < min_precedence) return;
  lex.next();
  // The right operand takes every operator of this level or tighter: right-associative.
  parse_binary(lex, context, out, p, depth + 1);
  out.push(Op{OpKind::Binary, uint8_t(op)});
  // Looser operators that follow apply to the whole: a * b + c = (a * b) + c.
  for (;;) {
    const int next = operator_index(lex.peek());
    const int q = precedence(next);
    if (q == 0 || q < min_precedence) return;
    lex.next();
    parse_binary(lex, context, out, q, depth + 1);
    out.push(Op{OpKind::Binary, uint8_t(next)});
  }
}

}  // namespace

Expression::Expression(float constant) { ops_[0].value = constant; }

Expression Expression::parm(int index) {
  Expression e;
  e.ops_.clear();
  e.push(Op{OpKind::Parm, 0, uint16_t(index)});
  return e;
}

void Expression::push(Op op) {
  if (!built_) {
    ops_.clear();
    built_ = true;
  }
  if (op.kind == OpKind::Time) depends_ |= kDependsTime;
  if (op.kind == OpKind::Parm) depends_ |= kDependsParms, parms_read_ |= 1u << op.index;
  if (op.kind == OpKind::Global) depends_ |= kDependsGlobals;
  ops_.push_back(op);
}

uint16_t Expression::add_table(const MaterialTable& table) {
  tables_.push_back(table);
  return uint16_t(tables_.size() - 1);
}

float Expression::evaluate(const RegisterInputs& registers) const {
  constexpr int kCapacity = 2 * kMaxDepth + 8;
  float stack[kCapacity];
  int top = 0;
  for (const Op& op : ops_) {
    if (top >= kCapacity) return 0.0f;   // cannot happen for parsed input (depth is bounded); never overrun
    if (top == 0 && (op.kind == OpKind::Table || op.kind == OpKind::Negate)) return 0.0f;
    if (top < 2 && op.kind == OpKind::Binary) return 0.0f;
    switch (op.kind) {
      case OpKind::Constant: stack[top++] = op.value; break;
      case OpKind::Time: stack[top++] = registers.time; break;
      case OpKind::Parm: stack[top++] = registers.parms[op.index]; break;
      case OpKind::Global: stack[top++] = registers.globals[op.index]; break;
      case OpKind::Table: stack[top - 1] = tables_[op.index].lookup(stack[top - 1]); break;
      case OpKind::Negate: stack[top - 1] = -stack[top - 1]; break;
      case OpKind::Binary:
        --top;
        stack[top - 1] = apply(op.binary, stack[top - 1], stack[top]);
        break;
    }
  }
  const float v = top > 0 ? stack[top - 1] : 0.0f;
  return std::isfinite(v) ? v : 0.0f;
}

float MaterialTable::lookup(float index) const {
  if (values.size() <= 1) return 1.0f;   // the engine's quirk: a one-entry table gives 1
  if (!std::isfinite(index)) return values[0];
  const size_t n = values.size();
  float scaled;
  if (clamp) {
    scaled = index * float(n - 1);
    if (scaled <= 0.0f) return values[0];
    if (scaled >= float(n - 1)) return values[n - 1];
  } else {
    scaled = std::fmod(index * float(n), float(n));
    if (scaled < 0.0f) scaled += float(n);
    if (scaled >= float(n)) scaled = 0.0f;
  }
  size_t i0 = static_cast<size_t>(scaled);
  if (i0 >= n) i0 = n - 1;
  if (snap) return values[i0];
  const size_t i1 = clamp ? std::min(i0 + 1, n - 1) : (i0 + 1) % n;
  const float f = scaled - static_cast<float>(i0);
  return values[i0] * (1.0f - f) + values[i1] * f;
}

Expression parse_expression(Lexer& lex, ExpressionContext& context) {
  Expression e;
  parse_binary(lex, context, e, 1, 0);
  return e;
}

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
