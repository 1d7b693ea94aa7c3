// Skinning on the host: the kernel's skinning routines (kernel/skinning.h) run over one skin of a
// TracerScene, in parallel over its vertices, then its BLAS refit bottom-up. The core runs it on its
// master scene, the CPU tracers on their own copies (apply_commit does, unless the tracer skins on its
// device), so every copy ends with the same bytes.
#pragma once

#include <cstdint>

#include "cohort/commit/tracer_scene.h"

namespace cohort::commit {

// Writes skin `skin`'s vertices from its joints and refits its BLAS's nodes. Throws std::out_of_range
// when the skin's ranges run past the scene's pools.
void skin_on_host(TracerScene& scene, uint32_t skin);

}  // namespace cohort::commit
