// Material register expressions ("time * 0.5", "flickertable[ time ]", "parm0 * 2"), compiled once
// when the .mtr is read and evaluated every frame against the registers the engine gives them
// (Material.cpp EvaluateRegisters): time in seconds, the entity's or light's parm0-11 and the view's
// global0-7. Grammar as the engine's: `* / %` bind tighter than `+ -`, then comparisons, then `&& ||`,
// and chains of one level are right-associative (a - b - c = a - (b - c)). Unlike the engine, a
// division or `%` by zero gives 0 and a non-finite result 0, so a broken expression never makes a NaN.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "cohort/scene/lexer.h"

namespace cohort::scene {

struct MaterialTable {
  std::vector<float> values;
  bool snap = false, clamp = false;
  float lookup(float index) const;   // DeclTable.cpp TableLookup: the table spans index 0..1
};

// Tables by lower-case name.
using MaterialTables = std::map<std::string, MaterialTable>;

// What an expression reads besides constants.
enum : uint32_t { kDependsTime = 1u, kDependsParms = 2u, kDependsGlobals = 4u };
constexpr int kMaterialParms = 12, kMaterialGlobals = 8;

struct RegisterInputs {
  float time = 0.0f;   // seconds
  float parms[kMaterialParms] = {1, 1, 1, 1, 0, 0, 0, 0, 0, 0, 0, 0};   // the engine's world-surface parms
  float globals[kMaterialGlobals] = {};
};

class Expression {
 public:
  Expression() = default;
  explicit Expression(float constant);
  static Expression parm(int index);

  float evaluate(const RegisterInputs& registers) const;
  uint32_t depends() const { return depends_; }
  bool constant() const { return depends_ == 0; }
  // Which parms it reads, bit i for parmi.
  uint32_t parms_read() const { return parms_read_; }

  // Building, in postfix order (the parser's job).
  enum class OpKind : uint8_t { Constant, Time, Parm, Global, Table, Negate, Binary };
  struct Op {
    OpKind kind = OpKind::Constant;
    uint8_t binary = 0;     // Binary: index into the operator list of the parser
    uint16_t index = 0;     // Parm / Global / Table index
    float value = 0.0f;     // Constant
  };
  void push(Op op);
  uint16_t add_table(const MaterialTable& table);

 private:
  std::vector<Op> ops_{Op{}};
  std::vector<MaterialTable> tables_;
  uint32_t depends_ = 0, parms_read_ = 0;
  bool built_ = false;
};

struct ExpressionContext {
  const MaterialTables* tables = nullptr;
};

// Parses one expression from the lexer; ParseError (file:line) on a malformed one or an unknown name or
// table.
Expression parse_expression(Lexer& lex, ExpressionContext& context);

// The text between the braces of `table name { [snap] [clamp] { v, v, ... } }`, to the lexer's end.
MaterialTable parse_table_body(Lexer& lex);

}  // namespace cohort::scene
