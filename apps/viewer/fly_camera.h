// A free-flying camera: the player's controls over a position and Doom 3 view angles (core/view.h).
// It produces the kernels' KCamera and the RenderWorld's RenderView, so the viewer can hand either to
// the core.
#pragma once

#include <glm/glm.hpp>

#include "cohort/core/view.h"
#include "cohort/scene/render_world.h"
#include "cohort/kernel/layout.h"

namespace cohort::viewer {

// What the player asks for this frame; -1..1 per axis, mouse deltas in pixels.
struct MoveInput {
  float forward = 0.0f;  // W/S
  float right = 0.0f;    // D/A
  float up = 0.0f;       // E,Space / Q,Ctrl (world Z, like noclip)
  bool fast = false;     // Shift
  float look_dx = 0.0f;  // mouse x: right turns right
  float look_dy = 0.0f;  // mouse y: down looks down
};

struct FlyCamera {
  glm::vec3 position{0.0f};
  float yaw = 0.0f;            // degrees
  float pitch = 0.0f;          // degrees, positive looks down, clamped to +-89
  float fov_x = 90.0f;         // degrees
  float speed = 200.0f;        // units per second (Doom 3 walks at 140)
  float fast_factor = 4.0f;
  float mouse_degrees_per_pixel = 0.15f;

  glm::vec3 forward() const;
  glm::vec3 right() const;
  glm::vec3 up() const;

  void update(const MoveInput& input, float seconds);
  // +/- keys: each step scales speed by 1.25, kept within sane bounds.
  void change_speed(int steps);

  // Vertical fov that keeps pixels square for this aspect (width / height).
  float fov_y(float aspect) const;
  KCamera to_kcamera(int width, int height) const;
  scene::RenderView to_render_view(int width, int height, int time_ms) const;
  // Take position and angles from a view (axis columns: forward, left, up); roll is dropped.
  static FlyCamera from_render_view(const scene::RenderView& view);
};

}  // namespace cohort::viewer
