// Internal to gpu_scene: fills TracerScene::textures and ::texels (see texture_slot in gpu_scene.h).
#pragma once

#include "cohort/core/gpu_scene.h"

namespace cohort::core {

void compile_textures(const scene::Scene& scene, commit::TracerScene& out);

}  // namespace cohort::core
