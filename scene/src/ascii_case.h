// Case folding for names in Doom 3's files (keywords, material and image names, paths, entity keys).
// ASCII only, like the engine's idStr::Icmp and ToLower, and independent of the C locale. Private to
// the scene library.
#pragma once

#include <string>
#include <string_view>

namespace cohort::scene {

char ascii_lower(char c);
std::string lowercase(std::string s);
bool equals_ignoring_case(std::string_view a, std::string_view b);
bool starts_with_ignoring_case(std::string_view s, std::string_view prefix);
bool ends_with_ignoring_case(std::string_view s, std::string_view suffix);

}  // namespace cohort::scene
