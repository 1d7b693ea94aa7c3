// `cohort play <map>`: a window showing the live path-traced frame, a fly camera, the scenario moving
// and keys to change what is rendered and how (apps/viewer/viewer_actions.h lists them).
#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <optional>

#include <spdlog/spdlog.h>

#include "cohort/balance/balancer.h"
#include "cohort/core/frame_defaults.h"
#include "cohort/core/frame_timeline.h"
#include "cohort/core/image_output.h"
#include "commands.h"
#include "default_map.h"
#include "aux_rays_choice.h"
#include "convergence_choice.h"
#include "workload_choice.h"
#include "play_rate.h"
#include "node_port_options.h"
#include "play_session.h"
#include "viewer/hud.h"
#include "viewer/viewer_actions.h"
#ifdef COHORT_HAVE_VIEWER
#include "viewer/gl_window.h"
#endif

namespace cohort::app {
namespace {

struct PlayArgs {
  SessionOptions session;
  int width = 1280, height = 720;
  float scale = 0.5f;
  int spp = 1;
  int bounces = 1;
  std::string light_sampling = core::light_sampling_name(core::default_frame_params().light_sampling);
  std::string convergence = "auto";  // convergence_choice.h
  int target_fps = -1;       // -1: 30 when only CPU tracers render, else off (workload_choice.h)
  bool workload_given = false;  // --scale or --spp on the command line: they stand unless --target-fps
  std::string mode = "path";
  std::string tone = "aces";
  int frames = 0;            // 0: until the window closes
  std::string screenshot;    // written from the last frame
  std::string window_shot;   // the last frame as the window showed it, HUD included
  std::string trace;         // Chrome trace event file of every frame's timeline
  NodePortArgs node_port;    // rank 0's port for nodes that join
  // How a scale below 1 reaches the window (core/upsample.h). auto: joint-bilateral where the reprojection
  // runs on a GPU (it reconstructs there, about 1 ms at 1080p), else bilinear: on the host the reconstruction
  // costs more than it gives at play's frame rates (docs/denoising.md, "Dynamic resolution").
  std::string upsample = "auto";
};

std::string key_help() {
  std::string out = "\nKeys:\n";
  for (const viewer::KeyHelp& k : viewer::kKeyHelp) {
    std::string keys(k.keys);
    keys.resize(std::max<size_t>(keys.size(), 24), ' ');
    out += "  " + keys + std::string(k.what) + "\n";
  }
  return out;
}

#ifdef COHORT_HAVE_VIEWER

constexpr float kScaleSteps[] = {0.125f, 0.25f, 0.375f, 0.5f, 0.625f, 0.75f, 0.875f, 1.0f};

// The HUD's words for how the scaled frame reaches the window: "JOINT-BILATERAL TO 1280X720".
std::string upsample_label(core::UpsampleMethod method, int window_width, int window_height) {
  std::string name = core::upsample_method_name(method);
  for (char& c : name) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  if (method == core::UpsampleMethod::bilinear) return name + " (GPU STRETCH)";
  return name + " TO " + std::to_string(window_width) + "X" + std::to_string(window_height);
}

float step_scale(float current, int direction) {
  const auto* begin = std::begin(kScaleSteps);
  const auto* end = std::end(kScaleSteps);
  if (direction > 0) {
    const auto* next = std::upper_bound(begin, end, current + 1e-4f);
    return next == end ? end[-1] : *next;
  }
  const auto* at = std::lower_bound(begin, end, current - 1e-4f);
  return at == begin ? *begin : at[-1];
}

template <typename T>
const T& cycle(const std::vector<T>& list, const T& current, int direction) {
  const auto it = std::find(list.begin(), list.end(), current);
  const long n = static_cast<long>(list.size());
  long i = it == list.end() ? 0 : (it - list.begin()) + direction;
  return list[static_cast<size_t>(((i % n) + n) % n)];
}

std::filesystem::path next_screenshot_name(const std::string& map) {
  const char* ext = core::have_image_library() ? ".png" : ".ppm";
  for (int i = 0;; ++i) {
    char name[64];
    std::snprintf(name, sizeof name, "cohort_%s_%03d%s", map.c_str(), i, ext);
    std::error_code ec;
    if (!std::filesystem::exists(name, ec)) return name;
  }
}

// A message shown on the HUD for a few seconds.
struct Notice {
  std::string text;
  std::chrono::steady_clock::time_point until;
};

int run_play(PlayArgs a) {
  using clock = std::chrono::steady_clock;
  a.session.bases = bases_or_test_map(a.session.bases);
  a.session.window_height = a.height;
  a.session.node_port_file = a.node_port.port_file;
  a.session.node_wait_s = a.node_port.first_wait_s;
  std::unique_ptr<PlaySession> session;
  try {
    session = std::make_unique<PlaySession>(a.session);
  } catch (const std::exception& e) {
    spdlog::error("cohort play: cannot start on '{}': {}", a.session.map, e.what());
    if (a.session.bases.empty())
      spdlog::error("  (no --base folder given and {} not found: point --base at a game's base/ folder)", kTestMapBase);
    return kExitFailure;
  }

  std::unique_ptr<viewer::GlWindow> window;
  try {
    window = std::make_unique<viewer::GlWindow>(a.width, a.height, "Cohort - " + session->map_name());
  } catch (const viewer::WindowUnavailable& e) {
    spdlog::error("cohort play: {}", e.what());
    return kExitUnavailable;
  }
  spdlog::info("viewer: OpenGL {}; tracers: {}", window->gl_description(), fmt::join(session->tracer_names(), ", "));

  viewer::FlyCamera camera = session->start_camera();
  FrameSettings settings;
  settings.spp = a.spp;
  settings.max_bounces = a.bounces;
  settings.light_sampling = core::light_sampling_mode(a.light_sampling);
  settings.mode = debug_mode_from_name(a.mode).value_or(K_MODE_PATH);
  settings.tone_curve = a.tone;
  settings.reproject = resolve_convergence(a.convergence, session->any_gpu_tracer(), session->frame_post_place()) == "reproject";
  settings.accumulate = a.convergence != "none";
  const bool reconstructs_on_gpu = settings.reproject && session->frame_post_place() != "host";
  settings.upsample = core::parse_upsample_method(
      a.upsample != "auto" ? a.upsample : reconstructs_on_gpu ? "joint-bilateral" : "bilinear");
  if (session->denoising())
    spdlog::info("{}reprojection and the a-trous filter on {}", settings.reproject ? "" : "(not used: Brigade's blend) ",
                 session->frame_post_place());
  float scale = a.scale;
  // A frame-rate target: spp and render scale follow the measured frame time (core/workload_scaler.h)
  // until the user picks either by hand.
  int target_fps = resolve_target_fps(a.target_fps, session->any_gpu_tracer(), a.workload_given);
  std::optional<core::WorkloadScaler> workload;
  if (target_fps > 0) workload.emplace(workload_options(target_fps), core::WorkloadSetting{settings.spp, scale});
  bool show_hud = true;
  std::vector<Notice> notices;
  auto notify = [&](std::string text) {
    spdlog::info("{}", text);
    notices.push_back({std::move(text), clock::now() + std::chrono::seconds(4)});
  };
  const std::vector<std::string> balancers = balance::balancer_names();

  raster::Image8 frame_image, hud_layer, window_image;
  SessionFrame last;
  bool have_frame = false;
  int frames_done = 0;
  double fps = 0.0;
  int fps_frames = 0;
  clock::time_point fps_start = clock::now(), previous = clock::now();
  double previous_cpu_ms = process_cpu_ms();
  int exit_code = kExitOk;
  std::unique_ptr<core::ChromeTraceWriter> trace;
  if (!a.trace.empty()) trace = std::make_unique<core::ChromeTraceWriter>(a.trace);
  // With --frames, the rate held is printed at the end; a sixth of the run (at least 10 frames) is warm-up.
  PlayRate rate(a.frames > 0 ? std::max<size_t>(10, static_cast<size_t>(a.frames) / 6) : 0);

  while (!window->should_close()) {
    window->poll_events();
    for (viewer::Action action : window->take_actions()) {
      using viewer::Action;
      switch (action) {
        case Action::quit:
          if (window->mouse_captured()) window->set_mouse_captured(false);
          else window->request_close();
          break;
        case Action::toggle_mouse_capture: window->set_mouse_captured(!window->mouse_captured()); break;
        case Action::next_mode: settings.mode = (settings.mode + 1) % K_MODE_COUNT; break;
        case Action::previous_mode: settings.mode = (settings.mode + K_MODE_COUNT - 1) % K_MODE_COUNT; break;
        case Action::set_mode_0: case Action::set_mode_1: case Action::set_mode_2: case Action::set_mode_3:
        case Action::set_mode_4: case Action::set_mode_5: case Action::set_mode_6:
          settings.mode = static_cast<kuint>(static_cast<int>(action) - static_cast<int>(Action::set_mode_0));
          break;
        case Action::next_balancer:
          session->set_balancer(cycle(balancers, session->balancer(), 1));
          notify("balancer " + session->balancer());
          break;
        case Action::spp_up: settings.spp = std::min(settings.spp * 2, 256); break;
        case Action::spp_down: settings.spp = std::max(settings.spp / 2, 1); break;
        case Action::scale_up: scale = step_scale(scale, 1); break;
        case Action::scale_down: scale = step_scale(scale, -1); break;
        default: break;
      }
      const bool manual_workload = action == Action::spp_up || action == Action::spp_down ||
                                   action == Action::scale_up || action == Action::scale_down;
      if (manual_workload && workload) {
        workload.reset();
        target_fps = 0;
        notify("frame-rate target off: spp and scale are yours");
      }
      switch (action) {
        case Action::next_tone_mapper: settings.tone_curve = cycle(tone_curve_names(), settings.tone_curve, 1); break;
        case Action::toggle_scenario_pause:
          if (session->scenario_running()) session->set_scenario_paused(!session->scenario_paused());
          else notify("no scenario on this map");
          break;
        case Action::screenshot:
          if (have_frame) {
            const std::filesystem::path file = next_screenshot_name(session->map_name());
            try {
              core::write_ldr_image(file, last.width, last.height, last.display);
              notify("saved " + file.string());
            } catch (const std::exception& e) {
              notify(std::string("screenshot failed: ") + e.what());
            }
          }
          break;
        case Action::toggle_hud: show_hud = !show_hud; break;
        case Action::speed_up: camera.change_speed(1); break;
        case Action::speed_down: camera.change_speed(-1); break;
        case Action::reset_camera: camera = session->start_camera(); break;
        default: break;
      }
    }

    const clock::time_point now = clock::now();
    const double frame_s = std::chrono::duration<double>(now - previous).count();
    const double dt = std::min(frame_s, 0.25);
    previous = now;
    const double cpu_now_ms = process_cpu_ms();
    const double frame_cpu_ms = cpu_now_ms - previous_cpu_ms;
    previous_cpu_ms = cpu_now_ms;
    if (workload && have_frame) {
      const core::WorkloadSetting chosen = workload->update(1000.0 * frame_s);
      settings.spp = chosen.spp;
      scale = static_cast<float>(chosen.render_scale);
    }
    camera.update(window->take_move_input(), static_cast<float>(dt));

    const int fb_w = std::max(window->framebuffer_width(), 1), fb_h = std::max(window->framebuffer_height(), 1);
    // Below scale 1 the reconstruction renders at the window's size (paths at scale^2 of the pixels, the
    // G-buffer at all); the bilinear baseline renders a smaller frame that the window stretches.
    const bool stretch = settings.upsample == core::UpsampleMethod::bilinear;
    const float frame_scale = stretch ? scale : 1.0f;
    settings.render_scale = scale;
    settings.width = std::max(16, static_cast<int>(std::lround(fb_w * frame_scale)));
    settings.height = std::max(16, static_cast<int>(std::lround(fb_h * frame_scale)));
    try {
      SessionFrame next = session->frame(camera, dt, settings);
      if (!next.ready) continue;  // the pipeline's first frame: it comes back with the next call
      last = std::move(next);
      have_frame = true;
    } catch (const std::exception& e) {
      spdlog::error("cohort play: the frame could not be rendered: {}", e.what());
      exit_code = kExitFailure;
      break;
    }
    frame_image.width = last.width;
    frame_image.height = last.height;
    frame_image.rgba = last.display;

    ++fps_frames;
    const double window_s = std::chrono::duration<double>(clock::now() - fps_start).count();
    if (window_s >= 0.5) {
      fps = fps_frames / window_s;
      fps_frames = 0;
      fps_start = clock::now();
    }

    // The viewer's own serial work, on the core's track of the trace: what the window costs beside the frame.
    std::vector<core::StageSpan> viewer_stages;
    std::optional<core::ScopedStage> hud_stage;
    if (show_hud) {
      hud_stage.emplace(viewer_stages, core::kCoreTrack, "hud");
      viewer::HudState hud;
      hud.fps = fps;
      hud.stats = last.stats;
      hud.mode = debug_mode_names()[settings.mode];
      hud.spp = settings.spp;
      hud.render_scale = scale;
      hud.target_fps = target_fps;
      hud.render_width = static_cast<int>(std::lround(fb_w * scale));
      hud.render_height = static_cast<int>(std::lround(fb_h * scale));
      hud.upsample = upsample_label(settings.upsample, fb_w, fb_h);
      hud.tone_mapper = settings.tone_curve;
      hud.balancer = session->balancer();
      hud.accumulation = settings.reproject
                             ? std::string(session->denoising() ? "REPROJECT+ATROUS ON " : "REPROJECT ON ") +
                                   session->frame_post_place()
                             : settings.accumulate ? "BRIGADE" : "NONE";
      if (!session->oidn_label().empty()) hud.accumulation += " + " + session->oidn_label();
      hud.commit_bytes = last.commit_bytes;
      hud.scenario_running = session->scenario_running();
      hud.scenario_paused = session->scenario_paused();
      hud.camera[0] = camera.position.x;
      hud.camera[1] = camera.position.y;
      hud.camera[2] = camera.position.z;
      hud.yaw = camera.yaw;
      hud.pitch = camera.pitch;
      hud.speed = camera.speed;
      hud.notices = session->warnings();
      std::erase_if(notices, [&](const Notice& n) { return n.until < clock::now(); });
      for (const Notice& n : notices) hud.notices.push_back(n.text);
      if (!window->mouse_captured()) hud.notices.push_back("RIGHT MOUSE OR TAB: LOOK AROUND");
      // The layer is only as large as the HUD: present() blends it over its own corner of the window.
      const int hud_scale = fb_h >= 700 ? 2 : 1;
      const viewer::HudExtent extent = viewer::hud_extent(hud, hud_scale);
      // Rounded up to 64 pixels, so that the texture is not re-allocated whenever a number's width changes.
      auto rounded = [](int n) { return (n + 63) / 64 * 64; };
      const int hud_w = std::clamp(rounded(extent.width), 1, fb_w), hud_h = std::clamp(rounded(extent.height), 1, fb_h);
      if (hud_layer.width != hud_w || hud_layer.height != hud_h) hud_layer.resize(hud_w, hud_h);
      viewer::draw_hud(hud_layer, hud, hud_scale);
    }
    hud_stage.reset();
    ++frames_done;
    rate.frame(1000.0 * frame_s, frame_cpu_ms);
    const bool last_frame = a.frames > 0 && frames_done >= a.frames;
    const bool read_back = last_frame && !a.window_shot.empty();
    {
      core::ScopedStage presenting(viewer_stages, core::kCoreTrack, "present");
      window->present(frame_image, show_hud ? &hud_layer : nullptr, read_back ? &window_image : nullptr);
    }
    if (trace) {
      last.stats.stages.insert(last.stats.stages.end(), viewer_stages.begin(), viewer_stages.end());
      trace->add(last.stats.frame, last.stats.stages);
    }
    if (last_frame) window->request_close();
  }

  if (a.frames > 0)
    std::cout << rate.summary(static_cast<size_t>(frames_done), window->framebuffer_width(),
                              window->framebuffer_height(), settings.width, settings.height, scale, settings.spp,
                              target_fps)
              << "\n";

  if (!a.window_shot.empty() && window_image.width > 0) {
    try {
      core::write_ldr_image(a.window_shot, window_image.width, window_image.height, window_image.rgba);
    } catch (const std::exception& e) {
      spdlog::error("cohort play: {}", e.what());
      return kExitFailure;
    }
  }

  if (!a.screenshot.empty()) {
    if (!have_frame) {
      spdlog::error("cohort play: no frame was rendered, so no screenshot was written");
      return kExitFailure;
    }
    try {
      core::write_ldr_image(a.screenshot, last.width, last.height, last.display);
      std::cout << "wrote " << a.screenshot << " (" << last.width << "x" << last.height << ", after " << frames_done
                << " frames)\n";
    } catch (const std::exception& e) {
      spdlog::error("cohort play: {}", e.what());
      return kExitFailure;
    }
  }
  return exit_code;
}

#endif  // COHORT_HAVE_VIEWER

}  // namespace

void add_play_command(CLI::App& app, int& exit_code) {
  auto* cmd = app.add_subcommand("play", "Open a window and fly through a map rendered live on every tracer");
  cmd->footer(key_help());
  auto a = std::make_shared<PlayArgs>();
  cmd->add_option("map", a->session.map, "a .map path, or a map name looked up under maps/ in the --base folders "
                                         "(e.g. testmap)")->required();
  cmd->add_option("--base", a->session.bases, "game folder with loose files and .pk4 archives (e.g. Doom 3's base/); "
                                              "repeat it (default: assets/testmap)");
  cmd->add_option("--tracers", a->session.tracers, "comma-separated: embree, opencl[:N|:all], cuda[:N|:all], or "
                                                   "all (the default: Embree plus every GPU once); `cohort devices` "
                                                   "lists which device each opencl:N is");
  cmd->add_option("--balancer", a->session.balancer, "row balancer (B cycles)")
      ->capture_default_str()
      ->check(CLI::IsMember(balance::balancer_names()));
  cmd->add_option("--frames-in-flight", a->session.frames_in_flight,
                  "2: hand the next frame's bands out as soon as this one's are, so that each tracer starts it the "
                  "moment its band before is done; where the tracers set the pace this adds a frame of input latency "
                  "(the frame waits in each tracer's queue behind the one before), and one more because the next frame is "
                  "prepared from the input of this one and handed out before the frame before is shown, so that no "
                  "tracer waits for the viewer's post and present (docs/balancing.md)")
      ->capture_default_str()
      ->check(CLI::Range(1, 2));
  add_node_port_options(cmd, a->node_port);
  cmd->add_option("--band-format", a->session.band_format,
                  "what the tracers hand back: RGB half floats (6 bytes a pixel), RGB9E5 (4 bytes a pixel: 9-bit mantissas "
                  "under a shared exponent, dithered so averaging frames keeps no bias) or RGBA floats (16)")
      ->capture_default_str()
      ->check(CLI::IsMember({"rgb16f", "rgb9e5", "rgba32f"}));
  cmd->add_option("--width", a->width, "window width")->capture_default_str()->check(CLI::Range(16, 16384));
  cmd->add_option("--height", a->height, "window height")->capture_default_str()->check(CLI::Range(16, 16384));
  CLI::Option* scale_option = cmd->add_option("--scale", a->scale, "render resolution / window resolution")
      ->capture_default_str()
      ->check(CLI::Range(0.05f, 1.0f));
  CLI::Option* spp_option =
      cmd->add_option("--spp", a->spp, "samples per pixel per frame")->capture_default_str()->check(CLI::Range(1, 256));
  cmd->add_option("--bounces", a->bounces, "indirect bounces")->capture_default_str()->check(CLI::Range(0, 16));
  cmd->add_option("--light-sampling", a->light_sampling,
                  "how each hit picks the map's lights: tree (the light tree), gather (the lights in range, "
                  "found through the tree, each its own shadow ray within a budget of one here; `cohort render "
                  "--light-samples N` sets a larger one), in-range (one light among every light in range, by its "
                  "contribution), dense (a bounded pick for rooms where many lights overlap), auto (in-range or dense "
                  "by the map's light density), all or every (references; see `cohort render --help`)")
      ->capture_default_str()
      ->check(CLI::IsMember(core::light_sampling_names()));
  cmd->add_option("--convergence", a->convergence,
                  "how frames accumulate: reproject (per-pixel history through motion vectors), brigade "
                  "(whole-frame blend), none (each frame as rendered, e.g. for --denoise oidn-cuda) or auto (reproject, on the first CUDA tracer's GPU if any; Brigade's blend when only OpenCL GPUs would wait "
                  "for the host's reprojection); see `cohort render --help`")
      ->capture_default_str()
      ->check(CLI::IsMember({"auto", "brigade", "reproject", "none"}));
  cmd->add_option("--aux-rays", a->session.aux_rays,
                  "where the G-buffer for reprojection comes from: auto (centre with --denoise oidn or oidn-cuda; else first-hit where CUDA GPUs render and no "
                  "OpenCL or mpi tracer does, else centre), centre (a ray of its own through each pixel's "
                  "centre) or first-hit (the first sample's own first surface: no extra ray, about 0.8 ms less a "
                  "1080p frame on an H100; the planes jitter at silhouettes); see `cohort render --help`")
      ->capture_default_str()
      ->check(CLI::IsMember(aux_rays_choices()));
  cmd->add_option("--denoise", a->session.denoise,
                  "the real-time a-trous filter after the reprojection: atrous, none, or auto (atrous where the "
                  "reprojection runs on a CUDA GPU, about 1-3 ms a frame; none on the host's threads, where it "
                  "would set the frame rate); or Open Image Denoise after the accumulation: oidn (CPU) or oidn-cuda "
                  "(an NVIDIA GPU; at 1280x720 on an H100 about 5-7 ms a frame with its guides; the lowest FLIP per frame measured, with "
                  "--convergence none: docs/denoising.md)")
      ->capture_default_str()
      ->check(CLI::IsMember({"auto", "atrous", "none", "oidn", "oidn-cuda"}));
  cmd->add_option("--denoise-quality", a->session.denoise_quality,
                  "Open Image Denoise's filter quality with --denoise oidn or oidn-cuda: high, balanced or fast")
      ->capture_default_str()
      ->check(CLI::IsMember({"high", "balanced", "fast"}));
  cmd->add_option("--history-fix", a->session.history_fix,
                  "with the a-trous filter: a pixel whose history is shorter than this many frames gets a wider "
                  "edge-aware blur first (NRD's HistoryFix; 0: off); see `cohort render --help`")
      ->capture_default_str()
      ->check(CLI::Range(0.0f, 64.0f));
  cmd->add_option("--target-fps", a->target_fps,
                  "hold this frame rate by choosing spp and render scale from the measured frame time (0: off; "
                  "default: 30 when only CPU tracers render and neither --spp nor --scale is given, off with a GPU); "
                  "the spp and scale keys take over")
      ->default_str("auto")
      ->check(CLI::Range(0, 1000));
  cmd->add_option("--upsample", a->upsample,
                  "how a --scale below 1 reaches the window: joint-bilateral (paths for about scale^2 of the "
                  "window's pixels, a moving pattern, the rest reconstructed with weights from the full-resolution "
                  "depth, normal, object id and albedo, textures from the full-resolution albedo), nearest (the nearest "
                  "traced pixel), bilinear (a smaller frame stretched by the GPU) or auto: joint-bilateral where the "
                  "reprojection runs on a CUDA GPU (the reconstruction runs there too), else bilinear (the other two "
                  "trace a G-buffer ray at every window pixel, and the host's reconstruction costs more than it gives "
                  "at play's frame rates); the frame-rate target's scale drives it too. docs/denoising.md")
      ->capture_default_str()
      ->check(CLI::IsMember({"auto", "joint-bilateral", "nearest", "bilinear"}));
  cmd->add_option("--mode", a->mode, "debug mode at start")
      ->capture_default_str()
      ->check(CLI::IsMember(debug_mode_names()));
  cmd->add_option("--tone", a->tone, "tone mapper at start")->capture_default_str()->check(CLI::IsMember(tone_curve_names()));
  cmd->add_flag("!--no-scenario", a->session.scenario, "leave the door, fan, flicker and flashlight still");
  cmd->add_option("--frames", a->frames, "quit after this many frames (0: when the window closes) and print the frame rate held (median and p95 after a warm-up) with the render size and spp it ended on")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--screenshot", a->screenshot, "write the last frame to this image file on exit");
  cmd->add_option("--trace", a->trace, "write every frame's timeline as a Chrome trace event file (open it in "
                                       "ui.perfetto.dev or chrome://tracing); the HUD draws the last frame's");
  cmd->add_option("--window-screenshot", a->window_shot, "with --frames: write what the window showed last (the "
                                                         "frame scaled to the window, HUD included)");
  cmd->callback([a, &exit_code, scale_option, spp_option] {
    a->workload_given = scale_option->count() > 0 || spp_option->count() > 0;
#ifdef COHORT_HAVE_VIEWER
    exit_code = run_play(*a);
#else
    spdlog::error("cohort play: this binary was built without the viewer (GLFW and OpenGL were not found, or "
                  "COHORT_WITH_VIEWER=OFF).\n  Install them (tools/setup.sh installs libglfw3-dev and the OpenGL "
                  "headers), then reconfigure with -DCOHORT_WITH_VIEWER=ON and rebuild;\n  `cohort render {}` "
                  "writes images without a window.",
                  a->session.map);
    exit_code = kExitUnavailable;
#endif
  });
}

}  // namespace cohort::app
