// The viewer's window: GLFW + OpenGL. Each frame the RGBA8 image is uploaded into a texture with
// glTexSubImage2D and drawn as a full-screen quad, with the HUD layer blended over its own corner. Tries an
// OpenGL 3.3 core context first and falls back to a 2.1 compatibility context (software GL such as
// Mesa under Xvfb may offer only that).
#pragma once

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "raster/image.h"
#include "fly_camera.h"
#include "viewer_actions.h"

namespace cohort::viewer {

// No display, no GL context: the message says what to do instead.
class WindowUnavailable : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class GlWindow {
 public:
  // Throws WindowUnavailable.
  GlWindow(int width, int height, const std::string& title);
  ~GlWindow();
  GlWindow(const GlWindow&) = delete;
  GlWindow& operator=(const GlWindow&) = delete;

  bool should_close() const;
  void request_close();
  // Handle window events; key presses become actions.
  void poll_events();
  std::vector<Action> take_actions();
  // Movement keys held now and the mouse motion since the last call (zero unless the mouse is captured).
  MoveInput take_move_input();
  void set_mouse_captured(bool captured);
  bool mouse_captured() const { return captured_; }

  int framebuffer_width() const;
  int framebuffer_height() const;
  // Upload the frame (stretched over the window) and the HUD layer (null: none; drawn pixel for pixel
  // at the window's top-left corner, cut to the window), swap.
  // With read_back, what was drawn is read back into it first (rows top to bottom).
  void present(const raster::Image8& frame, const raster::Image8* hud, raster::Image8* read_back = nullptr);
  void set_title(const std::string& title);
  // e.g. "OpenGL 3.3 core (Mesa llvmpipe)".
  const std::string& gl_description() const { return gl_description_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  bool captured_ = false;
  std::string gl_description_;
};

}  // namespace cohort::viewer
