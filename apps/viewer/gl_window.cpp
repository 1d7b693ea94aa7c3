#include "gl_window.h"

#define GLFW_INCLUDE_GLEXT
#include <GLFW/glfw3.h>

#include <algorithm>
#include <cmath>
#include <mutex>
#include <type_traits>

namespace cohort::viewer {
namespace {

std::string g_last_glfw_error;
std::mutex g_error_mutex;

void record_glfw_error(int code, const char* description) {
  std::lock_guard lock(g_error_mutex);
  g_last_glfw_error = std::to_string(code) + ": " + (description ? description : "?");
}

std::string last_glfw_error() {
  std::lock_guard lock(g_error_mutex);
  return g_last_glfw_error.empty() ? std::string("no error reported") : g_last_glfw_error;
}

const char* const kNoWindowAdvice =
    "\n  `cohort render <map>` renders without a window, or run the viewer under a virtual display:"
    "\n  xvfb-run -a -s \"-screen 0 1280x720x24\" cohort play <map>";

// The handful of GL 2.0+/3.x entry points the core-profile path needs, fetched through GLFW.
struct GlCore {
  PFNGLCREATESHADERPROC CreateShader = nullptr;
  PFNGLSHADERSOURCEPROC ShaderSource = nullptr;
  PFNGLCOMPILESHADERPROC CompileShader = nullptr;
  PFNGLGETSHADERIVPROC GetShaderiv = nullptr;
  PFNGLGETSHADERINFOLOGPROC GetShaderInfoLog = nullptr;
  PFNGLCREATEPROGRAMPROC CreateProgram = nullptr;
  PFNGLATTACHSHADERPROC AttachShader = nullptr;
  PFNGLLINKPROGRAMPROC LinkProgram = nullptr;
  PFNGLGETPROGRAMIVPROC GetProgramiv = nullptr;
  PFNGLGETPROGRAMINFOLOGPROC GetProgramInfoLog = nullptr;
  PFNGLUSEPROGRAMPROC UseProgram = nullptr;
  PFNGLDELETESHADERPROC DeleteShader = nullptr;
  PFNGLDELETEPROGRAMPROC DeleteProgram = nullptr;
  PFNGLGETUNIFORMLOCATIONPROC GetUniformLocation = nullptr;
  PFNGLUNIFORM1IPROC Uniform1i = nullptr;
  PFNGLGENVERTEXARRAYSPROC GenVertexArrays = nullptr;
  PFNGLBINDVERTEXARRAYPROC BindVertexArray = nullptr;
  PFNGLDELETEVERTEXARRAYSPROC DeleteVertexArrays = nullptr;

  bool load() {
    auto get = [](auto& fn, const char* name) {
      fn = reinterpret_cast<std::remove_reference_t<decltype(fn)>>(glfwGetProcAddress(name));
      return fn != nullptr;
    };
    return get(CreateShader, "glCreateShader") && get(ShaderSource, "glShaderSource") &&
           get(CompileShader, "glCompileShader") && get(GetShaderiv, "glGetShaderiv") &&
           get(GetShaderInfoLog, "glGetShaderInfoLog") && get(CreateProgram, "glCreateProgram") &&
           get(AttachShader, "glAttachShader") && get(LinkProgram, "glLinkProgram") &&
           get(GetProgramiv, "glGetProgramiv") && get(GetProgramInfoLog, "glGetProgramInfoLog") &&
           get(UseProgram, "glUseProgram") && get(DeleteShader, "glDeleteShader") &&
           get(DeleteProgram, "glDeleteProgram") && get(GetUniformLocation, "glGetUniformLocation") &&
           get(Uniform1i, "glUniform1i") && get(GenVertexArrays, "glGenVertexArrays") &&
           get(BindVertexArray, "glBindVertexArray") && get(DeleteVertexArrays, "glDeleteVertexArrays");
  }
};

// One oversized triangle covering the screen, generated from gl_VertexID: no vertex buffer needed. Image rows are top
// to bottom, so v runs downward.
const char* const kVertexShader = R"(#version 330 core
out vec2 uv;
void main() {
  vec2 corner = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));
  uv = vec2(corner.x, 1.0 - corner.y);
  gl_Position = vec4(corner * 2.0 - 1.0, 0.0, 1.0);
}
)";
const char* const kFragmentShader = R"(#version 330 core
in vec2 uv;
out vec4 color;
uniform sampler2D image;
void main() { color = texture(image, uv); }
)";

struct Texture {
  GLuint id = 0;
  int width = 0, height = 0;

  void upload(const raster::Image8& image, GLint filter) {
    if (id == 0) glGenTextures(1, &id);
    glBindTexture(GL_TEXTURE_2D, id);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    if (image.width != width || image.height != height) {
      width = image.width;
      height = image.height;
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, filter);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, filter);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
      glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, width, height, 0, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
    }
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, image.rgba.data());
  }
};

}  // namespace

struct GlWindow::Impl {
  GLFWwindow* window = nullptr;
  bool core_profile = false;
  GlCore gl;
  GLuint program = 0, vao = 0;
  Texture frame, hud;
  std::vector<Action> actions;
  double last_x = 0, last_y = 0, dx = 0, dy = 0;
  bool have_last = false;
  GlWindow* owner = nullptr;

  // Shaders and programs report failure the same way: a status query, then an info log.
  template <typename GetStatus, typename GetLog>
  static void require(GLuint object, GLenum status, GetStatus get_status, GetLog get_log, const char* step) {
    GLint ok = 0;
    get_status(object, status, &ok);
    if (ok) return;
    char log[1024] = {};
    get_log(object, sizeof(log), nullptr, log);
    throw WindowUnavailable(std::string("viewer shader failed to ") + step + ": " + log);
  }

  void build_program() {
    auto compile = [&](GLenum type, const char* source) {
      GLuint s = gl.CreateShader(type);
      gl.ShaderSource(s, 1, &source, nullptr);
      gl.CompileShader(s);
      require(s, GL_COMPILE_STATUS, gl.GetShaderiv, gl.GetShaderInfoLog, "compile");
      return s;
    };
    GLuint vs = compile(GL_VERTEX_SHADER, kVertexShader), fs = compile(GL_FRAGMENT_SHADER, kFragmentShader);
    program = gl.CreateProgram();
    gl.AttachShader(program, vs);
    gl.AttachShader(program, fs);
    gl.LinkProgram(program);
    gl.DeleteShader(vs);
    gl.DeleteShader(fs);
    require(program, GL_LINK_STATUS, gl.GetProgramiv, gl.GetProgramInfoLog, "link");
    gl.UseProgram(program);
    gl.Uniform1i(gl.GetUniformLocation(program, "image"), 0);
    gl.GenVertexArrays(1, &vao);
  }

  void draw_quad(const Texture& tex) {
    glBindTexture(GL_TEXTURE_2D, tex.id);
    if (core_profile) {
      gl.UseProgram(program);
      gl.BindVertexArray(vao);
      glDrawArrays(GL_TRIANGLES, 0, 3);
      return;
    }
    glEnable(GL_TEXTURE_2D);
    glBegin(GL_QUADS);
    glTexCoord2f(0, 1); glVertex2f(-1, -1);
    glTexCoord2f(1, 1); glVertex2f(1, -1);
    glTexCoord2f(1, 0); glVertex2f(1, 1);
    glTexCoord2f(0, 0); glVertex2f(-1, 1);
    glEnd();
  }
};

namespace {

Action* action_for_key(int key, int mods, Action& out) {
  const bool shift = (mods & GLFW_MOD_SHIFT) != 0;
  switch (key) {
    case GLFW_KEY_ESCAPE: out = Action::quit; break;
    case GLFW_KEY_TAB: out = Action::toggle_mouse_capture; break;
    case GLFW_KEY_M: out = shift ? Action::previous_mode : Action::next_mode; break;
    case GLFW_KEY_1: out = Action::set_mode_0; break;
    case GLFW_KEY_2: out = Action::set_mode_1; break;
    case GLFW_KEY_3: out = Action::set_mode_2; break;
    case GLFW_KEY_4: out = Action::set_mode_3; break;
    case GLFW_KEY_5: out = Action::set_mode_4; break;
    case GLFW_KEY_6: out = Action::set_mode_5; break;
    case GLFW_KEY_7: out = Action::set_mode_6; break;
    case GLFW_KEY_B: out = Action::next_balancer; break;
    case GLFW_KEY_RIGHT_BRACKET: out = Action::spp_up; break;
    case GLFW_KEY_LEFT_BRACKET: out = Action::spp_down; break;
    case GLFW_KEY_PERIOD: out = Action::scale_up; break;
    case GLFW_KEY_COMMA: out = Action::scale_down; break;
    case GLFW_KEY_T: out = Action::next_tone_mapper; break;
    case GLFW_KEY_P: out = Action::toggle_scenario_pause; break;
    case GLFW_KEY_F12: out = Action::screenshot; break;
    case GLFW_KEY_H: out = Action::toggle_hud; break;
    case GLFW_KEY_R: out = Action::reset_camera; break;
    case GLFW_KEY_EQUAL: case GLFW_KEY_KP_ADD: out = Action::speed_up; break;
    case GLFW_KEY_MINUS: case GLFW_KEY_KP_SUBTRACT: out = Action::speed_down; break;
    default: return nullptr;
  }
  return &out;
}

}  // namespace

GlWindow::GlWindow(int width, int height, const std::string& title) : impl_(std::make_unique<Impl>()) {
  impl_->owner = this;
  glfwSetErrorCallback(record_glfw_error);
  if (!glfwInit())
    throw WindowUnavailable("cannot open a window: GLFW could not start (" + last_glfw_error() + ")" + kNoWindowAdvice);

  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  impl_->window = glfwCreateWindow(width, height, title.c_str(), nullptr, nullptr);
  impl_->core_profile = impl_->window != nullptr;
  if (!impl_->window) {
    glfwDefaultWindowHints();
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 2);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 1);
    impl_->window = glfwCreateWindow(width, height, title.c_str(), nullptr, nullptr);
  }
  if (!impl_->window) {
    const std::string why = last_glfw_error();
    glfwTerminate();
    throw WindowUnavailable("cannot open a window with OpenGL 3.3 core or 2.1 (" + why + ")" + kNoWindowAdvice);
  }
  glfwMakeContextCurrent(impl_->window);
  glfwSwapInterval(0);  // the frame rate shown is the renderer's, not the monitor's
  if (impl_->core_profile) {
    if (!impl_->gl.load()) {
      glfwDestroyWindow(impl_->window);
      glfwTerminate();
      throw WindowUnavailable("the OpenGL 3.3 context lacks shader entry points");
    }
    impl_->build_program();
  }
  const char* version = reinterpret_cast<const char*>(glGetString(GL_VERSION));
  const char* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  gl_description_ = std::string(impl_->core_profile ? "core " : "compatibility ") + (version ? version : "?") +
                    " on " + (renderer ? renderer : "?");

  glfwSetWindowUserPointer(impl_->window, impl_.get());
  glfwSetKeyCallback(impl_->window, [](GLFWwindow* w, int key, int, int action, int mods) {
    if (action != GLFW_PRESS && action != GLFW_REPEAT) return;
    auto* impl = static_cast<Impl*>(glfwGetWindowUserPointer(w));
    Action a{};
    // Repeats only for the speed keys; a held toggle key should not flicker.
    if (!action_for_key(key, mods, a)) return;
    if (action == GLFW_REPEAT && a != Action::speed_up && a != Action::speed_down) return;
    impl->actions.push_back(a);
  });
  glfwSetMouseButtonCallback(impl_->window, [](GLFWwindow* w, int button, int action, int) {
    auto* impl = static_cast<Impl*>(glfwGetWindowUserPointer(w));
    if (button == GLFW_MOUSE_BUTTON_RIGHT && action == GLFW_PRESS)
      impl->actions.push_back(Action::toggle_mouse_capture);
  });
  glfwSetCursorPosCallback(impl_->window, [](GLFWwindow* w, double x, double y) {
    auto* impl = static_cast<Impl*>(glfwGetWindowUserPointer(w));
    if (impl->have_last && impl->owner->captured_) {
      impl->dx += x - impl->last_x;
      impl->dy += y - impl->last_y;
    }
    impl->last_x = x;
    impl->last_y = y;
    impl->have_last = true;
  });
}

GlWindow::~GlWindow() {
  if (!impl_->window) return;
  glfwMakeContextCurrent(impl_->window);
  for (GLuint t : {impl_->frame.id, impl_->hud.id})
    if (t) glDeleteTextures(1, &t);
  if (impl_->core_profile) {
    impl_->gl.DeleteVertexArrays(1, &impl_->vao);
    impl_->gl.DeleteProgram(impl_->program);
  }
  glfwDestroyWindow(impl_->window);
  glfwTerminate();
}

bool GlWindow::should_close() const { return glfwWindowShouldClose(impl_->window); }
void GlWindow::request_close() { glfwSetWindowShouldClose(impl_->window, GLFW_TRUE); }
void GlWindow::poll_events() { glfwPollEvents(); }

std::vector<Action> GlWindow::take_actions() {
  std::vector<Action> out;
  out.swap(impl_->actions);
  return out;
}

MoveInput GlWindow::take_move_input() {
  GLFWwindow* w = impl_->window;
  auto held = [w](int key) { return glfwGetKey(w, key) == GLFW_PRESS; };
  MoveInput in;
  in.forward = static_cast<float>(held(GLFW_KEY_W)) - static_cast<float>(held(GLFW_KEY_S));
  in.right = static_cast<float>(held(GLFW_KEY_D)) - static_cast<float>(held(GLFW_KEY_A));
  in.up = static_cast<float>(held(GLFW_KEY_E) || held(GLFW_KEY_SPACE)) -
          static_cast<float>(held(GLFW_KEY_Q) || held(GLFW_KEY_LEFT_CONTROL) || held(GLFW_KEY_RIGHT_CONTROL));
  in.fast = held(GLFW_KEY_LEFT_SHIFT) || held(GLFW_KEY_RIGHT_SHIFT);
  in.look_dx = static_cast<float>(impl_->dx);
  in.look_dy = static_cast<float>(impl_->dy);
  impl_->dx = impl_->dy = 0;
  return in;
}

void GlWindow::set_mouse_captured(bool captured) {
  captured_ = captured;
  glfwSetInputMode(impl_->window, GLFW_CURSOR, captured ? GLFW_CURSOR_DISABLED : GLFW_CURSOR_NORMAL);
  impl_->have_last = false;
  impl_->dx = impl_->dy = 0;
}

int GlWindow::framebuffer_width() const {
  int w = 0, h = 0;
  glfwGetFramebufferSize(impl_->window, &w, &h);
  return w;
}

int GlWindow::framebuffer_height() const {
  int w = 0, h = 0;
  glfwGetFramebufferSize(impl_->window, &w, &h);
  return h;
}

void GlWindow::present(const raster::Image8& frame, const raster::Image8* hud, raster::Image8* read_back) {
  glfwMakeContextCurrent(impl_->window);
  const int fb_w = framebuffer_width(), fb_h = framebuffer_height();
  glViewport(0, 0, fb_w, fb_h);
  glActiveTexture(GL_TEXTURE0);
  if (frame.width > 0 && frame.height > 0) {
    // The opaque frame covers every pixel, so no clear first (a full-window pass under software GL).
    glDisable(GL_BLEND);
    impl_->frame.upload(frame, GL_LINEAR);
    impl_->draw_quad(impl_->frame);
  } else {
    glClearColor(0.05f, 0.05f, 0.06f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT);
  }
  if (hud && hud->width > 0 && hud->height > 0) {
    // Pixel for pixel at the top-left corner: the viewport maps the full-screen quad onto the layer's
    // rectangle, so only the HUD's own pixels are blended.
    const int hud_w = std::min(hud->width, fb_w), hud_h = std::min(hud->height, fb_h);
    glViewport(0, fb_h - hud_h, hud_w, hud_h);
    glEnable(GL_BLEND);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    impl_->hud.upload(*hud, GL_NEAREST);
    impl_->draw_quad(impl_->hud);
    glDisable(GL_BLEND);
    glViewport(0, 0, fb_w, fb_h);
  }
  if (read_back) {
    const int w = fb_w, h = fb_h;
    read_back->resize(w, h);
    std::vector<uint8_t> bottom_up(static_cast<size_t>(w) * h * 4);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, bottom_up.data());
    const size_t row = static_cast<size_t>(w) * 4;
    for (int y = 0; y < h; ++y)
      std::copy_n(bottom_up.data() + (h - 1 - y) * row, row, read_back->rgba.data() + y * row);
    for (size_t i = 3; i < read_back->rgba.size(); i += 4) read_back->rgba[i] = 255;
  }
  glfwSwapBuffers(impl_->window);
}

void GlWindow::set_title(const std::string& title) { glfwSetWindowTitle(impl_->window, title.c_str()); }

}  // namespace cohort::viewer
