#include "id_plane_output.h"

#include <algorithm>
#include <fstream>
#include <stdexcept>

namespace cohort::app {

void write_id_plane_pgm(const std::string& path, int width, int height, const std::vector<uint32_t>& id) {
  const size_t pixels = size_t(width) * size_t(height);
  if (width <= 0 || height <= 0 || id.size() != pixels)
    throw std::runtime_error(path + ": the id plane has " + std::to_string(id.size()) + " values for " +
                             std::to_string(width) + "x" + std::to_string(height) + " pixels");
  std::vector<unsigned char> bytes(2 * pixels);
  for (size_t p = 0; p < pixels; ++p) {
    const uint32_t v = id[p] == 0xFFFFFFFFu ? kIdPlaneMiss : id[p] >= kIdPlaneMiss ? kIdPlaneMiss - 1u : id[p];
    bytes[2 * p] = static_cast<unsigned char>(v >> 8);
    bytes[2 * p + 1] = static_cast<unsigned char>(v & 0xFFu);
  }
  std::ofstream out(path, std::ios::binary);
  out << "P5\n" << width << " " << height << "\n65535\n";
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  if (!out) throw std::runtime_error(path + ": cannot write the id plane");
}

std::map<std::string, uint32_t> entity_plane_ids(const scene::RenderWorld& world) {
  std::map<std::string, uint32_t> ids;
  const auto& entities = world.scene().entities;
  const auto& defs = world.entity_defs();
  for (size_t e = 0; e < entities.size() && e < defs.size(); ++e)
    if (defs[e] && !entities[e].name.empty()) ids.emplace(entities[e].name, uint32_t(e) + 1u);
  return ids;
}

std::vector<std::string> MovedEntities::update(const scene::RenderWorld& world) {
  const auto& defs = world.entity_defs();
  std::vector<std::optional<Placement>> now(defs.size());
  for (size_t h = 0; h < defs.size(); ++h)
    if (defs[h]) now[h] = Placement{defs[h]->origin, defs[h]->axis, defs[h]->joints};
  std::vector<std::string> moved;
  if (last_) {
    const auto& entities = world.scene().entities;
    for (size_t h = 0; h < std::max(now.size(), last_->size()); ++h) {
      const std::optional<Placement> before = h < last_->size() ? (*last_)[h] : std::nullopt;
      const std::optional<Placement> after = h < now.size() ? now[h] : std::nullopt;
      if (before == after) continue;
      if (h < entities.size() && !entities[h].name.empty()) {
        moved.push_back(entities[h].name);
      } else {
        std::string unnamed = std::to_string(h);
        unnamed.insert(unnamed.begin(), '#');
        moved.push_back(std::move(unnamed));
      }
    }
  }
  last_ = std::move(now);
  return moved;
}

}  // namespace cohort::app
