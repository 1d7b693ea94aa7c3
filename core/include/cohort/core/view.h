// Doom 3's view conventions, the only ones Cohort uses: Z is up; yaw 0 looks down +X and turns toward
// +Y; positive pitch looks down (idAngles, as the engine's player view). Angles are in degrees. A view
// axis holds forward, left and up as its columns (idAngles::ToMat3, RenderView::axis).
#pragma once

#include <glm/glm.hpp>

#include "cohort/kernel/layout.h"
#include "cohort/scene/render_world.h"
#include "cohort/scene/scene.h"

namespace cohort::core {

// The player's eye above the player start's origin (the engine's pm_normalviewheight).
constexpr float kPlayerEyeHeight = 68.0f;
constexpr float kDefaultFovX = 90.0f;

struct ViewAngles {
  float yaw = 0.0f;
  float pitch = 0.0f;  // positive looks down
};

// Forward, left, up for yaw and pitch (roll 0). Left is level (no Z) so the horizon stays flat.
glm::mat3 view_axis(const ViewAngles& angles);
// Yaw in [0, 360) and pitch of an axis's forward column; roll is dropped.
ViewAngles view_angles(const glm::mat3& axis);

// The kernels' camera. Pixels are square: the vertical field follows fov_x and the image's aspect.
KCamera make_camera(const glm::vec3& origin, const ViewAngles& angles, float fov_x_degrees, int width, int height);
// For a RenderView (scripted cameras, recorded streams): its axis as given (normalised), its fov_x.
KCamera make_camera(const scene::RenderView& view, int width, int height);

// Where the map's player stands at eye height, looking along the player start's yaw.
glm::vec3 player_eye(const scene::Scene& scene);

}  // namespace cohort::core
