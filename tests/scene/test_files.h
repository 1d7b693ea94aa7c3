// Helpers shared by the scene tests: fixture paths and file reading.
#pragma once

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace cohort::scene::test {

inline std::filesystem::path data_dir() { return std::filesystem::path(COHORT_SOURCE_DIR) / "tests/scene/data"; }

inline std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream out;
  out << in.rdbuf();
  return out.str();
}

}  // namespace cohort::scene::test
