// Records for what differs between two versions of a TracerScene array: the count when it changed, and
// every element that is new or whose bytes differ. The core keeps the previous frame's small arrays
// (instances, lights, materials) and diffs them, which also covers a TLAS build that reordered the
// instances: only the slots whose content moved are sent.
#pragma once

#include <string>
#include <vector>

#include "cohort/commit/commit_buffer.h"

namespace cohort::commit {

void diff_instances(const std::vector<KInstance>& before, const std::vector<KInstance>& after, CommitBuffer& out);
void diff_lights(const std::vector<KLight>& before, const std::vector<KLight>& after, CommitBuffer& out);
void diff_materials(const std::vector<KMaterial>& before, const std::vector<KMaterial>& after, CommitBuffer& out);
void diff_textures(const std::vector<KTexture>& before, const std::vector<KTexture>& after, CommitBuffer& out);
// A TLAS record when the node arrays differ.
void diff_tlas(const std::vector<KBvhNode>& before, const std::vector<KBvhNode>& after, CommitBuffer& out);
// Whole-array records for the light tree and the emissive triangles when they differ.
void diff_light_tree(const std::vector<KLightNode>& before, const std::vector<KLightNode>& after, CommitBuffer& out);
void diff_emissive_triangles(const std::vector<KEmissiveTriangle>& before, const std::vector<KEmissiveTriangle>& after,
                             CommitBuffer& out);

// Byte-exact equality of two scenes' arrays, for tests and consistency checks; names the first
// difference in `where` (e.g. "instances[3]") when there is one.
bool same_tracer_scene(const TracerScene& a, const TracerScene& b, std::string* where = nullptr);

}  // namespace cohort::commit
