#include "cohort/scene/parse_error.h"

namespace cohort::scene {

static std::string format_location(const std::string& file, int line, int column, const std::string& message) {
  return file + ":" + std::to_string(line) + ":" + std::to_string(column) + ": " + message;
}

ParseError::ParseError(std::string file, int line, int column, std::string message)
    : std::runtime_error(format_location(file, line, column, message)),
      file_(std::move(file)), line_(line), column_(column), message_(std::move(message)) {}

ParseError::ParseError(Formatted, std::string what, std::string file, std::string message)
    : std::runtime_error(what), file_(std::move(file)), line_(0), column_(0), message_(std::move(message)) {}

ParseError ParseError::at_byte(std::string file, size_t offset, std::string message) {
  std::string what = file;
  what.append(": byte ").append(std::to_string(offset)).append(": ").append(message);
  return ParseError(Formatted{}, std::move(what), std::move(file), std::move(message));
}

}  // namespace cohort::scene
