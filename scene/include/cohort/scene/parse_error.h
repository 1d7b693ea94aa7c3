// The one error type every Doom 3 file parser throws: where (file:line:column) and what went wrong.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>

namespace cohort::scene {

class ParseError : public std::runtime_error {
 public:
  ParseError(std::string file, int line, int column, std::string message);
  // For binary files, which have no lines: "file: byte N: message" (line and column 0).
  static ParseError at_byte(std::string file, size_t offset, std::string message);

  const std::string& file() const { return file_; }
  int line() const { return line_; }
  int column() const { return column_; }
  const std::string& message() const { return message_; }

 private:
  struct Formatted {};
  ParseError(Formatted, std::string what, std::string file, std::string message);
  std::string file_;
  int line_, column_;
  std::string message_;
};

}  // namespace cohort::scene
