#include "default_map.h"

#include <filesystem>

namespace cohort::app {

std::vector<std::string> bases_or_test_map(const std::vector<std::string>& given) {
  if (!given.empty()) return given;
  std::error_code ec;
  std::filesystem::path fallback = kTestMapBase;
  if (!std::filesystem::is_directory(fallback, ec)) fallback = std::filesystem::path(COHORT_SOURCE_DIR) / kTestMapBase;
  if (std::filesystem::is_directory(fallback, ec)) return {fallback.string()};
  return {};
}

}  // namespace cohort::app
