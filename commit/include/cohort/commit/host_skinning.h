// Skinning on the host: the kernel's skinning routines (kernel/skinning.h) run over one skin of a
// TracerScene, in parallel over its vertices, then its BLAS refit bottom-up. The core runs it on its
// master scene, the CPU tracers on their own copies (apply_commit does, unless the tracer skins on its
// device), so every copy ends with the same bytes.
#pragma once

#include <cstdint>

#include "cohort/commit/tracer_scene.h"

namespace cohort::commit {

// Every index a skin's routines will follow stays inside the scene's pools (its vertices, weights,
// adjacency, BLAS); throws std::out_of_range naming what does not. Run once when a skin arrives.
void check_skin(const TracerScene& scene, uint32_t skin);

// Writes skin `skin`'s vertices from its joints and refits its BLAS's nodes. Throws std::out_of_range
// when the skin's own ranges run past the scene's pools (per-vertex ranges are check_skin's).
void skin_on_host(TracerScene& scene, uint32_t skin);

}  // namespace cohort::commit
