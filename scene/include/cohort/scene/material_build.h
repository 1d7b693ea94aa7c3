// From a parsed material declaration to the scene model's Material: which stage gives the diffuse,
// normal, specular and emissive images, how it blends (BlendClass), and light-material images.
#pragma once

#include <string>

#include "cohort/scene/image_library.h"
#include "cohort/scene/material_file.h"

namespace cohort::scene {

// `as_light`: the material is a light's shader (its first stage is the projected image).
Material build_material(const MaterialDecl& decl, ImageLibrary& images, bool as_light);

// The material for a name no declaration defines: like the engine, the image of that name if there
// is one, else a checker; is_default is set either way.
Material default_material(const std::string& name, ImageLibrary& images);

}  // namespace cohort::scene
