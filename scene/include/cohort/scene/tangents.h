// Per-vertex tangent frames from texture coordinates, for normal mapping.
#pragma once

#include "cohort/scene/scene.h"

namespace cohort::scene {

// Fills Vertex::tangent (xyz unit tangent along +s, w = bitangent sign) for every vertex of the mesh
// from its triangles' st derivatives; vertices whose triangles have degenerate st get an arbitrary
// basis perpendicular to the normal.
void compute_tangents(Mesh& mesh);

}  // namespace cohort::scene
