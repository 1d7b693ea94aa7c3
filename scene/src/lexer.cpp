#include "cohort/scene/lexer.h"

#include <charconv>
#include <cmath>
#include <vector>

#include "ascii_case.h"

namespace cohort::scene {

namespace {

bool is_name_start(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_';
}
bool is_path_char(char c) { return c == '/' || c == '\\' || c == ':' || c == '.'; }
bool is_digit(char c) { return c >= '0' && c <= '9'; }
bool is_name_char(char c) { return is_name_start(c) || is_digit(c) || is_path_char(c); }

constexpr std::string_view kTwoCharPunct[] = {"==", "!=", ">=", "<=", "&&", "||"};

std::string describe(const Token& t) {
  switch (t.kind) {
    case Token::Kind::End: return "end of file";
    case Token::Kind::String: return "string \"" + t.text + "\"";
    default: return "'" + t.text + "'";
  }
}

}  // namespace

bool Token::is(std::string_view word) const {
  return (kind == Kind::Name || kind == Kind::Punct || kind == Kind::Number) && equals_ignoring_case(text, word);
}

Lexer::Lexer(std::string_view text, std::string file_name) : text_(text), file_(std::move(file_name)) {}

Lexer::Lexer(std::string_view text, std::string file_name, int first_line, int first_column)
    : text_(text), file_(std::move(file_name)), line_(first_line), column_(first_column), last_line_(first_line) {}

void Lexer::advance() {
  if (pos_ >= text_.size()) return;
  if (text_[pos_] == '\n') {
    ++line_;
    column_ = 1;
  } else {
    ++column_;
  }
  ++pos_;
}

void Lexer::skip_whitespace_and_comments() {
  for (;;) {
    while (pos_ < text_.size() && static_cast<unsigned char>(current()) <= ' ') advance();
    if (current() == '/' && ahead(1) == '/') {
      while (pos_ < text_.size() && current() != '\n') advance();
    } else if (current() == '/' && ahead(1) == '*') {
      int line = line_, column = column_;
      advance();
      advance();
      while (pos_ < text_.size() && !(current() == '*' && ahead(1) == '/')) advance();
      if (pos_ >= text_.size()) throw ParseError(file_, line, column, "unterminated /* comment");
      advance();
      advance();
    } else {
      return;
    }
  }
}

Token Lexer::read_token() {
  skip_whitespace_and_comments();
  Token t;
  t.line = line_;
  t.column = column_;
  t.offset = pos_;
  if (pos_ >= text_.size()) return t;
  char c = current();
  if (c == '"') {
    advance();
    size_t start = pos_;
    while (pos_ < text_.size() && current() != '"' && current() != '\n') advance();
    if (current() != '"') throw ParseError(file_, t.line, t.column, "unterminated string");
    t.kind = Token::Kind::String;
    t.text.assign(text_.substr(start, pos_ - start));
    advance();
    return t;
  }
  if (is_digit(c) || (c == '.' && is_digit(ahead(1)))) {
    size_t start = pos_;
    while (is_digit(current())) advance();
    if (current() == '.') {
      advance();
      while (is_digit(current())) advance();
    }
    if ((current() == 'e' || current() == 'E') &&
        (is_digit(ahead(1)) || ((ahead(1) == '-' || ahead(1) == '+') && is_digit(ahead(2))))) {
      advance();
      if (current() == '-' || current() == '+') advance();
      while (is_digit(current())) advance();
    }
    t.kind = Token::Kind::Number;
    t.text.assign(text_.substr(start, pos_ - start));
    auto [end, ec] = std::from_chars(t.text.data(), t.text.data() + t.text.size(), t.number);
    if (ec != std::errc() || end != t.text.data() + t.text.size() || !std::isfinite(t.number))
      throw ParseError(file_, t.line, t.column, "number out of range: " + t.text);
    return t;
  }
  if (is_name_start(c) || (is_path_char(c) && !(c == '/' && (ahead(1) == '/' || ahead(1) == '*')))) {
    size_t start = pos_;
    while (pos_ < text_.size() && is_name_char(current())) {
      if (current() == '/' && (ahead(1) == '/' || ahead(1) == '*') && pos_ > start) break;
      advance();
    }
    t.kind = Token::Kind::Name;
    t.text.assign(text_.substr(start, pos_ - start));
    return t;
  }
  t.kind = Token::Kind::Punct;
  for (std::string_view two : kTwoCharPunct) {
    if (c == two[0] && ahead(1) == two[1]) {
      t.text.assign(two);
      advance();
      advance();
      return t;
    }
  }
  t.text.assign(1, c);
  advance();
  return t;
}

Token Lexer::next() {
  Token t;
  if (has_peeked_) {
    has_peeked_ = false;
    t = std::move(peeked_);
  } else {
    t = read_token();
  }
  if (t.kind != Token::Kind::End) last_line_ = t.line;
  return t;
}

const Token& Lexer::peek() {
  if (!has_peeked_) {
    peeked_ = read_token();
    has_peeked_ = true;
  }
  return peeked_;
}

bool Lexer::accept(std::string_view word) {
  if (!peek().is(word) || peek().kind == Token::Kind::String) return false;
  next();
  return true;
}

void Lexer::expect(std::string_view word) {
  Token t = next();
  if (!t.is(word)) fail(t, "expected '" + std::string(word) + "', found " + describe(t));
}

Token Lexer::expect_any(std::string_view what) {
  Token t = next();
  if (t.kind == Token::Kind::End) fail(t, "unexpected end of file, expected " + std::string(what));
  return t;
}

std::string Lexer::expect_string(std::string_view what) {
  Token t = next();
  if (t.kind != Token::Kind::String && t.kind != Token::Kind::Name)
    fail(t, "expected " + std::string(what) + ", found " + describe(t));
  return t.text;
}

double Lexer::expect_number(std::string_view what) {
  Token t = next();
  double sign = 1.0;
  if (t.kind == Token::Kind::Punct && (t.text == "-" || t.text == "+")) {
    sign = t.text == "-" ? -1.0 : 1.0;
    Token after = next();
    if (after.kind != Token::Kind::Number)
      fail(after, "expected a number for " + std::string(what) + ", found " + describe(after));
    return sign * after.number;
  }
  if (t.kind != Token::Kind::Number) fail(t, "expected a number for " + std::string(what) + ", found " + describe(t));
  return t.number;
}

float Lexer::expect_float(std::string_view what) {
  double v = expect_number(what);
  if (std::fabs(v) > 3.0e38) fail_here("number out of float range for " + std::string(what));
  return static_cast<float>(v);
}

long long Lexer::expect_integer(std::string_view what) {
  Token t = peek();
  double v = expect_number(what);
  if (v != std::floor(v) || std::fabs(v) > 9.0e15) fail(t, "expected an integer for " + std::string(what) + ", found '" + t.text + "'");
  return static_cast<long long>(v);
}

size_t Lexer::expect_count(std::string_view what, size_t min_bytes_each) {
  Token t = peek();
  long long v = expect_integer(what);
  if (v < 0) fail(t, "negative " + std::string(what) + ": " + std::to_string(v));
  if (min_bytes_each > 0 && static_cast<unsigned long long>(v) > bytes_left() / min_bytes_each + 1)
    fail(t, std::string(what) + " " + std::to_string(v) + " is more than the rest of the file can hold");
  return static_cast<size_t>(v);
}

void Lexer::expect_vector(float* out, int n, std::string_view what) {
  expect("(");
  for (int i = 0; i < n; ++i) out[i] = expect_float(what);
  expect(")");
}

void Lexer::skip_braced_block() {
  int depth = 1;
  Token open_at = peek();
  while (depth > 0) {
    Token t = next();
    if (t.kind == Token::Kind::End) fail(open_at, "unexpected end of file inside a { } block");
    if (t.kind != Token::Kind::Punct) continue;
    if (t.text == "{") ++depth;
    else if (t.text == "}") --depth;
  }
}

std::string_view Lexer::braced_block_text(const Token& open) {
  int depth = 1;
  for (;;) {
    Token t = next();
    if (t.kind == Token::Kind::End) fail(open, "'{' is never closed");
    if (t.kind != Token::Kind::Punct) continue;
    if (t.text == "{") ++depth;
    else if (t.text == "}" && --depth == 0) return text_.substr(open.offset + 1, t.offset - open.offset - 1);
  }
}

void Lexer::skip_rest_of_line() {
  int line = last_line_;
  while (peek().kind != Token::Kind::End && peek().line == line) next();
}

void Lexer::fail(const Token& at, const std::string& message) const {
  throw ParseError(file_, at.line, at.column, message);
}

void Lexer::fail_here(const std::string& message) { throw ParseError(file_, last_line_, 0, message); }

}  // namespace cohort::scene
