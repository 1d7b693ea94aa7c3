// A tokenizer for idTech 4 text files in the manner of idLexer: quoted strings, numbers, names (with
// path characters / \ : .), punctuation, // and /* */ comments, and line/column tracking. Every
// failure is a ParseError naming file:line:column; no input makes it loop or allocate without bound.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

#include "cohort/scene/parse_error.h"

namespace cohort::scene {

struct Token {
  enum class Kind { End, Name, String, Number, Punct };
  Kind kind = Kind::End;
  std::string text;
  double number = 0.0;   // for Kind::Number
  int line = 0, column = 0;
  size_t offset = 0;     // of the token's first character in the text

  bool is(std::string_view word) const;   // an unquoted name or punctuation equal (case-insensitive) to word
};

class Lexer {
 public:
  Lexer(std::string_view text, std::string file_name);
  // Lexes a piece of a larger file, reporting positions as in that file.
  Lexer(std::string_view text, std::string file_name, int first_line, int first_column);

  // The next token; Kind::End at the end of the text.
  Token next();
  const Token& peek();
  bool at_end() { return peek().kind == Token::Kind::End; }

  // Consumes the next token if it is(word).
  bool accept(std::string_view word);
  void expect(std::string_view word);
  Token expect_any(std::string_view what);           // any token but End
  std::string expect_string(std::string_view what);  // a quoted string or a bare name
  double expect_number(std::string_view what);       // with an optional leading '-' or '+'
  float expect_float(std::string_view what);
  long long expect_integer(std::string_view what);
  // An integer count of items, each of which takes at least min_bytes_each characters of what is
  // left of the text: a count the file cannot hold is an error before anything is allocated.
  size_t expect_count(std::string_view what, size_t min_bytes_each);
  // `( n numbers )`.
  void expect_vector(float* out, int n, std::string_view what);

  // Skips to the brace that closes a block whose opening "{" was just consumed.
  void skip_braced_block();
  // The same, returning the text between the braces (a view into the lexed text).
  std::string_view braced_block_text(const Token& open);
  // Skips the tokens left on the line of the last token returned.
  void skip_rest_of_line();

  size_t bytes_left() const { return text_.size() - pos_; }
  int last_line() const { return last_line_; }
  const std::string& file() const { return file_; }

  [[noreturn]] void fail(const Token& at, const std::string& message) const;
  [[noreturn]] void fail_here(const std::string& message);

 private:
  Token read_token();
  void skip_whitespace_and_comments();
  char current() const { return pos_ < text_.size() ? text_[pos_] : '\0'; }
  char ahead(size_t k) const { return pos_ + k < text_.size() ? text_[pos_ + k] : '\0'; }
  void advance();

  std::string_view text_;
  std::string file_;
  size_t pos_ = 0;
  int line_ = 1, column_ = 1;
  int last_line_ = 1;
  bool has_peeked_ = false;
  Token peeked_;
};

}  // namespace cohort::scene
