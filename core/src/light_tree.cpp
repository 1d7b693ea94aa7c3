// The light tree: each light's finite volume as a world-space box, and a median-split tree over them.
#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>

#include <glm/gtc/matrix_inverse.hpp>

#include "cohort/core/light_sampling.h"
#include "cohort/kernel/light_tree.h"
#include "cohort/kernel/vec.h"

namespace cohort::core {
namespace {

// Beyond this a light's box is treated as unbounded (no map is this large; Doom 3's is +-65536).
constexpr double kLargestCoordinate = 1.0e7;

glm::dvec4 plane(const float* p) { return {p[0], p[1], p[2], p[3]}; }
glm::dvec3 xyz(const glm::dvec4& p) { return {p.x, p.y, p.z}; }
double eval(const glm::dvec4& p, const glm::dvec3& x) { return glm::dot(xyz(p), x) + p.w; }

// The point where three planes (rows) meet: rows . x = rhs. nullopt when they do not meet in one point.
std::optional<glm::dvec3> meet(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, const glm::dvec3& rhs) {
  const double det = glm::dot(a, glm::cross(b, c));
  const double scale = glm::length(a) * glm::length(b) * glm::length(c);
  if (!(std::fabs(det) > 1e-12 * scale)) return std::nullopt;
  // Cramer's rule with the rows as a, b, c.
  const glm::dvec3 x = (rhs.x * glm::cross(b, c) + rhs.y * glm::cross(c, a) + rhs.z * glm::cross(a, b)) / det;
  return x;
}

// Box lights: 0 <= S, T, F <= 1 is a parallelepiped, the hull of its 8 corners.
bool box_light_corners(const KLight& light, std::vector<glm::dvec3>& points) {
  const glm::dvec4 s = plane(light.plane_s), t = plane(light.plane_t), f = plane(light.plane_f);
  for (int corner = 0; corner < 8; ++corner) {
    const double a = corner & 1, b = (corner >> 1) & 1, c = (corner >> 2) & 1;
    auto x = meet(xyz(s), xyz(t), xyz(f), {a - s.w, b - t.w, c - f.w});
    if (!x) return false;
    points.push_back(*x);
  }
  return true;
}

// Projected lights: the pyramid 0 <= S/Q, T/Q <= 1 (Q > 0) from its apex, cut by the slab 0 <= F <= 1.
// Along each of the pyramid's four edge rays F must change in the same direction, or the slab leaves
// the volume open. The volume's corners are then the apex (when inside the slab) and the points where
// the edge rays cross F = 0 and F = 1 ahead of the apex.
bool projected_light_corners(const KLight& light, std::vector<glm::dvec3>& points) {
  const glm::dvec4 s = plane(light.plane_s), t = plane(light.plane_t), q = plane(light.plane_q),
                   f = plane(light.plane_f);
  auto apex = meet(xyz(s), xyz(t), xyz(q), {-s.w, -t.w, -q.w});
  if (!apex) return false;
  const double f_apex = eval(f, *apex);
  if (f_apex >= 0.0 && f_apex <= 1.0) points.push_back(*apex);
  int sign = 0;
  for (int edge = 0; edge < 4; ++edge) {
    const double a = edge & 1, b = (edge >> 1) & 1;
    glm::dvec3 ray = glm::cross(xyz(s) - a * xyz(q), xyz(t) - b * xyz(q));
    const double q_rate = glm::dot(xyz(q), ray);
    if (!(std::fabs(q_rate) > 1e-12 * glm::length(ray) * glm::length(xyz(q)))) return false;
    if (q_rate < 0.0) ray = -ray;
    const double f_rate = glm::dot(xyz(f), ray);
    const int s_rate = f_rate > 1e-12 * glm::length(ray) * glm::length(xyz(f))    ? 1
                       : f_rate < -1e-12 * glm::length(ray) * glm::length(xyz(f)) ? -1
                                                                                   : 0;
    if (s_rate == 0 || (sign != 0 && s_rate != sign)) return false;
    sign = s_rate;
    for (double level : {0.0, 1.0}) {
      const double along = (level - f_apex) / f_rate;
      if (along >= 0.0) points.push_back(*apex + along * ray);
    }
  }
  return true;
}

float luminance(const float* c) { return v3_luminance(v3(c[0], c[1], c[2])); }

struct Item {
  uint32_t light = 0;
  LightBounds box;
  glm::vec3 centre{0.0f};
  float power = 0.0f;
};

// Median splits along the longest axis of the items' box centres, one item per leaf, children adjacent.
// Node indices are absolute: the tree's nodes will sit at `first_node` onwards of the node array.
class TreeBuilder {
 public:
  TreeBuilder(std::vector<Item> items, uint32_t first_node) : items_(std::move(items)), first_node_(first_node) {}
  std::vector<KLightNode> build() {
    if (items_.empty()) return {};
    nodes_.reserve(2 * items_.size() - 1);
    nodes_.emplace_back();
    build(0, K_NONE, 0, items_.size());
    return std::move(nodes_);
  }

 private:
  void build(size_t node, uint32_t parent, size_t begin, size_t end) {
    KLightNode n{};
    n.parent = parent;
    glm::vec3 lo(INFINITY), hi(-INFINITY), centre_lo(INFINITY), centre_hi(-INFINITY);
    float power = 0.0f, reach = 0.0f;
    for (size_t i = begin; i < end; ++i) {
      lo = glm::min(lo, items_[i].box.min);
      hi = glm::max(hi, items_[i].box.max);
      const glm::vec3 half = 0.5f * (items_[i].box.max - items_[i].box.min);
      reach = std::max(reach, std::max(half.x, std::max(half.y, half.z)));
      centre_lo = glm::min(centre_lo, items_[i].centre);
      centre_hi = glm::max(centre_hi, items_[i].centre);
      power += items_[i].power;
    }
    for (int k = 0; k < 3; ++k) {
      n.bmin[k] = lo[k];
      n.bmax[k] = hi[k];
    }
    n.power = power;
    n.reach = reach;
    n.light_count = uint32_t(end - begin);
    if (end - begin == 1) {
      n.count = 1;
      n.left_first = items_[begin].light;
      nodes_[node] = n;
      return;
    }
    const glm::vec3 extent = centre_hi - centre_lo;
    const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : extent.y >= extent.z ? 1 : 2;
    const size_t mid = begin + (end - begin) / 2;
    std::nth_element(items_.begin() + long(begin), items_.begin() + long(mid), items_.begin() + long(end),
                     [axis](const Item& a, const Item& b) {
                       return a.centre[axis] < b.centre[axis] || (a.centre[axis] == b.centre[axis] && a.light < b.light);
                     });
    const size_t left = nodes_.size();
    nodes_.emplace_back();
    nodes_.emplace_back();
    n.count = 0;
    n.left_first = first_node_ + uint32_t(left);
    nodes_[node] = n;
    build(left, first_node_ + uint32_t(node), begin, mid);
    build(left + 1, first_node_ + uint32_t(node), mid, end);
  }

  std::vector<Item> items_;
  uint32_t first_node_;
  std::vector<KLightNode> nodes_;
};

}  // namespace

std::optional<LightBounds> light_bounds(const KLight& light) {
  for (const float* p : {light.plane_s, light.plane_t, light.plane_q, light.plane_f})
    for (int k = 0; k < 4; ++k)
      if (!std::isfinite(p[k])) return std::nullopt;
  std::vector<glm::dvec3> points;
  const bool closed = light.type == K_LIGHT_PROJECTED ? projected_light_corners(light, points)
                                                      : box_light_corners(light, points);
  if (!closed || points.empty()) return std::nullopt;
  glm::dvec3 lo(INFINITY), hi(-INFINITY);
  for (const glm::dvec3& p : points) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  for (int k = 0; k < 3; ++k)
    if (!std::isfinite(lo[k]) || !std::isfinite(hi[k]) || std::fabs(lo[k]) > kLargestCoordinate ||
        std::fabs(hi[k]) > kLargestCoordinate)
      return std::nullopt;
  // A margin for the kernel's float plane tests at the volume's faces.
  const glm::dvec3 margin = 1e-4 * (hi - lo) + glm::dvec3(1e-2);
  return LightBounds{glm::vec3(lo - margin), glm::vec3(hi + margin)};
}

std::vector<KLightNode> build_light_tree(const std::vector<KLight>& lights) {
  std::vector<Item> items;
  items.reserve(lights.size());
  for (size_t i = 0; i < lights.size(); ++i) {
    std::optional<LightBounds> box = light_bounds(lights[i]);
    // Fog and blend lights light nothing: the integrator applies them along rays, never by NEE.
    if (!box || (lights[i].flags & K_LIGHT_VOLUME_EFFECT)) continue;
    Item item;
    item.light = uint32_t(i);
    item.box = *box;
    item.centre = 0.5f * (box->min + box->max);
    item.power = std::max(luminance(lights[i].color), 0.0f);
    items.push_back(item);
  }
  return TreeBuilder(std::move(items), 0).build();
}

std::vector<KLightNode> build_light_nodes(const std::vector<KLight>& lights, EmissiveList& emissive) {
  std::vector<KLightNode> nodes = build_light_tree(lights);
  std::vector<Item> items;
  items.reserve(emissive.triangles.size());
  for (size_t i = 0; i < emissive.triangles.size(); ++i) {
    const KEmissiveTriangle& e = emissive.triangles[i];
    Item item;
    item.light = uint32_t(i);
    item.box.min = item.box.max = glm::vec3(e.p0[0], e.p0[1], e.p0[2]);
    for (const float* p : {e.p1, e.p2}) {
      item.box.min = glm::min(item.box.min, glm::vec3(p[0], p[1], p[2]));
      item.box.max = glm::max(item.box.max, glm::vec3(p[0], p[1], p[2]));
    }
    item.centre = 0.5f * (item.box.min + item.box.max);
    item.power = emissive.power[i];
    items.push_back(item);
  }
  const uint32_t first = uint32_t(nodes.size());
  std::vector<KLightNode> tree = TreeBuilder(std::move(items), first).build();
  for (uint32_t n = 0; n < tree.size(); ++n)
    if (tree[n].count > 0) emissive.triangles[tree[n].left_first].leaf = first + n;
  nodes.insert(nodes.end(), tree.begin(), tree.end());
  return nodes;
}

float light_density(const commit::TracerScene& scene) {
  const std::vector<KLightNode>& nodes = scene.light_nodes;
  // The Doom 3 lights' tree, before the emissive triangles' (kernel/scene_view.h, as the kernel finds it).
  KSceneView view{};
  view.light_node_count = static_cast<kuint>(nodes.size());
  view.emissive_count = static_cast<kuint>(scene.emissive_triangles.size());
  const size_t tree = k_light_tree_nodes(&view);
  if (tree == 0) return 0.0f;
  size_t lights = 0, in_range = 0;
  std::vector<uint32_t> stack;
  for (size_t leaf = 0; leaf < tree; ++leaf) {
    if (nodes[leaf].count == 0) continue;
    const KVec3 centre = v3(0.5f * (nodes[leaf].bmin[0] + nodes[leaf].bmax[0]),
                            0.5f * (nodes[leaf].bmin[1] + nodes[leaf].bmax[1]),
                            0.5f * (nodes[leaf].bmin[2] + nodes[leaf].bmax[2]));
    ++lights;
    stack.assign(1, 0u);
    while (!stack.empty()) {
      const KLightNode& n = nodes[stack.back()];
      stack.pop_back();
      if (!k_light_node_holds(&n, centre)) continue;
      if (n.count > 0) {
        ++in_range;
      } else {
        stack.push_back(n.left_first);
        stack.push_back(n.left_first + 1);
      }
    }
  }
  return lights > 0 ? float(double(in_range) / double(lights)) : 0.0f;
}

kuint resolve_light_sampling(kuint mode, float density) {
  if (mode != K_LIGHTS_AUTO) return mode;
  return density > kDenseLightDensity ? K_LIGHTS_DENSE : K_LIGHTS_IN_RANGE;
}

}  // namespace cohort::core
