// A scripted session on the test map, driven through the RenderWorld API exactly as a game would:
// the door `door_main` slides open, the fan `fan_spin` spins, the light `light_flicker` flickers, and
// a flashlight (a projected light added at the first frame) follows the camera along its path, and every
// map entity with an MD5 animation (the walkers) plays it while walking a circle. Every
// frame is a pure function of its index, so a recording and a live run give the same calls.
#pragma once

#include <stdexcept>
#include <memory>
#include <string>
#include <vector>

#include "cohort/scene/render_world.h"

namespace cohort::scene {

struct ScenarioOptions {
  double frames_per_second = 60.0;
  float fov_x = 90.0f;
  float aspect = 16.0f / 9.0f;       // fov_y follows from fov_x and this
  std::string door = "door_main";
  std::string fan = "fan_spin";
  std::string flicker = "light_flicker";
  std::string flashlight_shader = "lights/testmap_round";  // used when the scene defines it
  float eye_height = 68.0f;          // above player_start, the engine's standing eye height
  float walk_radius = 40.0f;         // animated characters walk a circle of this radius, turning left,
  float walk_speed = 40.0f;          // at this many units a second, starting where the map puts them
};

// The scene lacks an entity or light the scenario drives; the message lists every missing name.
class ScenarioError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class Scenario {
 public:
  // Checks the names at once (ScenarioError) and remembers the seeded defs' start poses.
  Scenario(RenderWorldApi& world, ScenarioOptions options = {});

  // Make frame `index`'s calls, RenderScene included; the caller ends the frame.
  void frame(int index);

  // The camera at time t (seconds): position and axis (forward, left, up columns).
  RenderView camera(double seconds) const;
  int flashlight_handle() const { return flashlight_; }
  // Entity handles of the characters the scenario animates.
  std::vector<int> walker_handles() const;
  // A walker's def at time t: its animation's pose (joints) and its place on the circle.
  RenderEntity walker(size_t index, double seconds) const;

 private:
  RenderWorldApi& world_;
  ScenarioOptions options_;
  int door_ = -1, fan_ = -1, flicker_ = -1, flashlight_ = -1;
  RenderEntity door_closed_, fan_rest_;
  RenderLight flicker_base_;
  float door_travel_ = 96.0f;
  struct Walker {
    int handle = -1;
    RenderEntity start;
    std::shared_ptr<const Md5Anim> anim;
  };
  std::vector<Walker> walkers_;
};

// Runs frames [0, frames) and ends each one.
void run_scenario(RenderWorldApi& world, int frames, const ScenarioOptions& options = {});

// The flicker factor (0.2..1) of `light_flicker` at time t: a fixed table stepped ten times a second,
// like the engine's flicker tables.
float flicker_factor(double seconds);

}  // namespace cohort::scene
