// Turns .map entities into the scene model's lights and entities, reading the keys the way the
// engine's spawn code does (idGameEdit::ParseSpawnArgsToRenderLight / ...RenderEntity).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "cohort/scene/map_file.h"
#include "cohort/scene/scene.h"

namespace cohort::scene {

// A light and the name of its light shader ("texture" key; empty: the default for its type).
struct MapLight {
  Light light;
  std::string texture;
};

bool is_light_entity(const MapEntity& e);

// `where` prefixes warnings about malformed values ("maps/x.map:120").
MapLight light_from_entity(const MapEntity& e, const std::string& where, std::vector<std::string>& warnings);
// Name, classname, origin, axis, keys, noshadows; Entity::mesh is left for the loader to resolve.
Entity entity_from_map(const MapEntity& e, const std::string& where, std::vector<std::string>& warnings);

// Key value helpers: `n` whitespace-separated floats, or nothing when the value does not hold n numbers.
std::optional<std::vector<float>> parse_floats(const std::string& value, size_t n);
// A map's bool ("1", "0"): as the engine's atoi(value) != 0.
bool parse_bool(const std::string& value);

}  // namespace cohort::scene
