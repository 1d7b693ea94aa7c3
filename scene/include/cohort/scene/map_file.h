// The editor map (.map, "Version 2") reader: entities with their key/value pairs. Brush and patch
// primitives are skipped (the .proc holds the compiled geometry) but must be well formed.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "cohort/scene/parse_error.h"

namespace cohort::scene {

struct MapEntity {
  std::vector<std::pair<std::string, std::string>> keys;  // in file order
  int line = 0;                 // of the opening brace
  int brush_count = 0, patch_count = 0;

  // The value of a key (case-insensitive, the last one wins as in idDict::Set), or nothing.
  std::optional<std::string> get(std::string_view key) const;
  std::string get_or(std::string_view key, std::string_view fallback) const;
  std::string classname() const { return get_or("classname", ""); }
};

struct MapFile {
  int version = 0;
  std::vector<MapEntity> entities;
  std::vector<std::string> warnings;
};

// Throws ParseError (file_name:line:column) on malformed input.
MapFile parse_map(std::string_view text, const std::string& file_name);

}  // namespace cohort::scene
