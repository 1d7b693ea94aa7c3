// What a key press asks the viewer to do, kept apart from GLFW so the bindings can be listed in the
// help text and the README from one table, and the play loop can be driven without a window.
#pragma once

#include <string_view>

namespace cohort::viewer {

enum class Action {
  quit,
  toggle_mouse_capture,
  next_mode,
  previous_mode,
  set_mode_0, set_mode_1, set_mode_2, set_mode_3, set_mode_4, set_mode_5, set_mode_6,
  next_balancer,
  spp_up,
  spp_down,
  scale_up,
  scale_down,
  next_tone_mapper,
  toggle_scenario_pause,
  screenshot,
  toggle_hud,
  speed_up,
  speed_down,
  reset_camera,
};

struct KeyHelp {
  std::string_view keys;
  std::string_view what;
};

// Every binding, movement included, for `cohort play --help` and the README.
inline constexpr KeyHelp kKeyHelp[] = {
    {"W A S D", "fly forward / left / back / right"},
    {"E or Space, Q or Ctrl", "fly up / down"},
    {"Shift", "fly 4x faster while held"},
    {"+ / -", "flying speed up / down (x1.25)"},
    {"Right mouse or Tab", "capture the mouse to look around (again to release)"},
    {"1 .. 7", "debug mode: path, direct, albedo, normals, specular, BVH cost, triangles"},
    {"M / Shift+M", "next / previous debug mode"},
    {"B", "next balancer"},
    {"] / [", "samples per pixel up / down"},
    {". / ,", "render scale up / down (paths for scale^2 of the pixels, upsampled to the window: --upsample)"},
    {"T", "next tone mapper"},
    {"P", "pause / resume the scenario (door, fan, flicker)"},
    {"R", "put the camera back at the start"},
    {"H", "hide / show the HUD"},
    {"F12", "screenshot (PNG in the current folder)"},
    {"Esc", "release the mouse, or quit when it is free"},
};

}  // namespace cohort::viewer
