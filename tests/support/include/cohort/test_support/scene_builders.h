// Pieces for building small scenes in memory in tests: meshes, materials and images added to a Scene.
#pragma once

#include <functional>
#include <string>

#include <glm/glm.hpp>

#include "cohort/kernel/layout.h"
#include "cohort/scene/scene.h"

namespace cohort::test {

// Adds a quad (two triangles) with corners p0..p3 in order, all with vertex normal `normal`.
void add_quad(scene::Mesh& mesh, int material, glm::vec3 p0, glm::vec3 p1, glm::vec3 p2, glm::vec3 p3,
              glm::vec3 normal);

// An axis-aligned box centred on the origin, one surface of `material`.
scene::Mesh box_mesh(const std::string& name, glm::vec3 half, int material);

// A size x size RGBA checkerboard.
scene::Image checker(const std::string& name, int size);

// Each returns the index of what it added.
int add_diffuse_material(scene::Scene& scene, const std::string& name, glm::vec3 albedo);
int add_image(scene::Scene& scene, const std::string& name, int w, int h,
              const std::function<glm::u8vec4(int, int)>& texel);
int add_world_mesh(scene::Scene& scene, scene::Mesh mesh);  // also an area of the static world
// An entity named "occluder": a 40 x 40 quad of `material` facing +Z, spanning [-20, 20]^2 at z = 50
// (over the origin, for shadow tests).
int add_occluder(scene::Scene& scene, int material);

// A point light named "light": a box of half-size `radius` around `origin`.
scene::Light point_light(glm::vec3 origin, glm::vec3 radius, glm::vec3 colour = glm::vec3(1.0f));

// A white point light in the kernel's layout whose S, T and F planes make its box the cube of half-size
// `half_size` about the origin (radius `half_size` on every axis): for light and emissive tree tests that build
// their nodes without a scene.
KLight kernel_point_light_about_origin(float half_size);

}  // namespace cohort::test
