// Cube maps as idTech 4 loads them (Image_files.cpp R_LoadCubeImages): six files named by a common
// name and a suffix per face, stored in GL face order +X, -X, +Y, -Y, +Z, -Z.
#pragma once

#include <cstdint>

#include "cohort/scene/scene.h"

namespace cohort::scene {

// `cubeMap` names faces _px _nx _py _ny _pz _nz, used as stored; `cameraCubeMap` names them
// _forward _back _left _right _up _down, ordinary camera views turned into GL faces on load.
enum class CubeMapKind : uint8_t { None, Axis, Camera };

// The file-name suffix of GL face `face` (0..5) for a cube map of that kind ("_px", "_forward", ...).
const char* cube_face_suffix(CubeMapKind kind, int face);

// A `cameraCubeMap` image turned into GL face `face`, as the engine does: forward transposed; back
// transposed and flipped both ways; left flipped vertically; right flipped horizontally; up and down
// transposed. `image` must be square.
Image camera_image_to_cube_face(const Image& image, int face);

// `texgen wobbleSky degrees speed rotate` (speeds in turns per minute) at `seconds`: the axes X', Y', Z'
// (the matrix's columns) a cube lookup reads the direction against, (d.X', d.Y', d.Z'), as the engine's
// R_WobbleskyTexGen builds them. `texgen skybox` is the identity.
glm::mat3 wobble_sky_axes(float degrees, float speed, float rotate, float seconds);

}  // namespace cohort::scene
