#include "cohort/scene/parse_error.h"

namespace cohort::scene {

static std::string format_location(const std::string& file, int line, int column, const std::string& message) {
  return file + ":" + std::to_string(line) + ":" + std::to_string(column) + ": " + message;
}

ParseError::ParseError(std::string file, int line, int column, std::string message)
    : std::runtime_error(format_location(file, line, column, message)),
      file_(std::move(file)), line_(line), column_(column), message_(std::move(message)) {}

}  // namespace cohort::scene
