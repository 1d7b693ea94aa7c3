#include "play_session.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <vector>

#include <spdlog/spdlog.h>

#include "cohort/commit/commit_buffer.h"
#include "cohort/core/atrous_filter.h"
#include "cohort/core/band_buffer.h"
#include "cohort/core/convergence.h"
#include "cohort/core/frame_post.h"
#include "cohort/core/frame_defaults.h"
#include "cohort/core/frame_pipeline.h"
#include "cohort/core/frame_timeline.h"
#include "cohort/core/gpu_scene.h"
#include "cohort/core/oidn_denoiser.h"
#include "cohort/core/renderer.h"
#include "cohort/core/tonemap.h"
#include "cohort/core/view.h"
#include "cohort/core/world_sync.h"
#include "cohort/scene/map_loader.h"
#include "cohort/scene/render_world.h"
#include "cohort/scene/scenario.h"
#include "cohort/tracers/tracer_registry.h"
#include "aux_rays_choice.h"

namespace cohort::app {
namespace {

constexpr double kScenarioFramesPerSecond = 60.0;

scene::Scene load_scene(const SessionOptions& options) {
  scene::Vfs vfs;
  for (const std::string& base : options.bases) vfs.add_search_path(base);
  scene::LoadReport report;
  scene::Scene loaded = scene::load_map(vfs, options.map, &report);
  for (size_t i = 0; i < loaded.warnings.size() && i < 10; ++i) spdlog::warn("{}", loaded.warnings[i]);
  if (loaded.warnings.size() > 10)
    spdlog::warn("... {} more warnings (`cohort info {}` lists them)", loaded.warnings.size() - 10, options.map);
  return loaded;
}

}  // namespace

const std::vector<std::string>& debug_mode_names() {
  static const std::vector<std::string> names = {"path", "direct", "albedo", "normals", "specular", "bvh", "triangles"};
  return names;
}

std::optional<kuint> debug_mode_from_name(const std::string& name) {
  const auto& names = debug_mode_names();
  for (size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return static_cast<kuint>(i);
  return std::nullopt;
}

const std::vector<std::string>& tone_curve_names() {
  static const std::vector<std::string> names = {"aces", "reinhard", "uncharted2", "gamma"};
  return names;
}

struct PlaySession::State {
  explicit State(scene::Scene loaded) : world(std::move(loaded)) {}

  scene::RenderWorld world;
  std::unique_ptr<core::WorldSync> sync;
  std::unique_ptr<scene::Scenario> scenario;
  std::unique_ptr<core::Renderer> renderer;
  std::unique_ptr<core::FramePipeline> pipeline;  // after the renderer: it finishes the frame in flight first
  kuint aux_mode = K_AUX_CENTRE_RAY;  // KFrameParams.aux_outputs when a frame wants the G-buffer
  // A frame prepared (scenario advanced, world synced, its commits submitted) and its job.
  struct Prepared {
    core::BandJob job;
    std::vector<core::StageSpan> stages;  // the core's stages before the Renderer's own
    size_t commit_bytes = 0;
    bool animating = false;
  };
  Prepared prepare(const viewer::FlyCamera& camera, double seconds, const FrameSettings& settings, bool paused);
  // Denoises `image` where OIDN is on, tone-maps it into `out`.
  void show(const core::FrameBuffer& image, const core::GBuffer& gbuffer, const FrameSettings& settings,
            SessionFrame& out);
  // The next frame, prepared and announced as soon as the frame before it was handed out (the input of
  // the call that handed that one out), pushed by the next call; none while the announcement at hand-out
  // is off: COHORT_EARLY_ANNOUNCE=0, or no tracer takes jobs ahead (only remote tracers do), where it would
  // add a frame between input and image for nothing.
  std::optional<Prepared> next;
  bool announce_at_hand_out = false;
  // What the frame in flight was prepared with, for when it comes back.
  struct InFlight {
    size_t commit_bytes = 0;
    bool animating = false;
  } in_flight;
  core::AdaptiveConvergence convergence;
  std::unique_ptr<core::FramePost> reprojection;  // on the first CUDA tracer's GPU, else the host
  KCamera previous_camera{};   // of the frame handed out last, for motion vectors
  std::vector<float> moving_mask;
  core::FrameBuffer upsampled;  // the reconstructed frame at a render scale below 1
  double scenario_seconds = 0.0;
  uint64_t frame_index = 0;
  kuint last_mode = K_MODE_PATH;
  std::string map_name;
  bool any_gpu_tracer = false;
  std::string post_place;
  bool denoising = false;
  std::unique_ptr<core::OidnDenoiser> oidn;  // --denoise oidn / oidn-cuda
  std::string oidn_label;
  core::FrameBuffer denoised;
};

PlaySession::PlaySession(const SessionOptions& options) {
  state_ = std::make_unique<State>(load_scene(options));
  State& s = *state_;
  s.map_name = s.world.scene().name.empty() ? options.map : s.world.scene().name;
  s.sync = std::make_unique<core::WorldSync>(s.world);
  auto initial_scene = s.sync->snapshot();

  const std::string list = options.tracers.empty() ? std::string("all") : options.tracers;
  std::vector<std::unique_ptr<core::Tracer>> tracers;
  // parse_tracer_list expands "all" and ":all" by probing devices; a device that then fails to open
  // is dropped with a warning and the others carry on.
  std::vector<tracers::TracerSpec> started;
  const std::vector<tracers::TracerSpec> specs = tracers::parse_tracer_list(list);
  // Before the remote tracers start MPI: the port's accept thread needs MPI_THREAD_MULTIPLE.
  if (!options.node_port_file.empty()) tracers::open_node_port(options.node_port_file, options.node_wait_s, specs);
  for (const tracers::TracerSpec& spec : specs) {
    try {
      tracers.push_back(tracers::make_tracer(spec));
      started.push_back(spec);
    } catch (const std::exception& e) {
      warnings_.push_back("tracer " + spec.text + " did not start: " + e.what());
      spdlog::warn("{}; carrying on with the others", warnings_.back());
    }
  }
  if (tracers.empty())
    throw std::runtime_error("no tracer could start (asked for: " + list + "); see the warnings above");

  for (const auto& tracer : tracers) s.any_gpu_tracer = s.any_gpu_tracer || tracer->renders_on_gpu();
  core::RendererOptions renderer_options;
  renderer_options.balancer = options.balancer;
  renderer_options.band_format = core::band_format_from_string(options.band_format);
  renderer_options.benched_commit_every = 8;  // as `cohort render`'s default
  renderer_options.frames_in_flight = options.frames_in_flight;
  s.renderer = std::make_unique<core::Renderer>(std::move(tracers), renderer_options);
  // Also with two frames in flight: the pipeline then hands the next frame out as soon as the frame before
  // is merged, so that no tracer waits for that frame's post, HUD and present (docs/balancing.md, "The next
  // frame handed out as soon as a slot frees"); the next frame's camera is this call's input.
  s.announce_at_hand_out = core::FramePipeline::announces_at_hand_out() &&
                           (s.renderer->takes_jobs_ahead() || options.frames_in_flight == 2);
  s.renderer->submit_commit(commit::CommitBuffer::full(initial_scene, 0));
  s.pipeline = std::make_unique<core::FramePipeline>(*s.renderer);
  s.post_place = tracers::auto_frame_post_place(started);
  core::FramePostOptions post_options;
  s.aux_mode = resolve_aux_rays(options.aux_rays, options.denoise, started);
  const bool oidn = options.denoise == "oidn" || options.denoise == "oidn-cuda";
  if (options.denoise != "auto" && options.denoise != "atrous" && options.denoise != "none" && !oidn)
    throw std::invalid_argument("--denoise '" + options.denoise + "': choose auto, atrous, none, oidn or oidn-cuda");
  if (oidn) {
    s.oidn = core::OidnDenoiser::open(core::parse_oidn_device(options.denoise == "oidn-cuda" ? "cuda" : "cpu"),
                                      core::parse_oidn_quality(options.denoise_quality));
    s.oidn_label = std::string("oidn on ") + core::oidn_device_name(s.oidn->device());
    spdlog::info("denoising with Open Image Denoise ({} device, {} quality, {})", core::oidn_device_name(s.oidn->device()),
                 options.denoise_quality, s.oidn->library_path());
  }
  post_options.atrous = options.denoise == "atrous" || (options.denoise == "auto" && s.post_place != "host");
  post_options.atrous_options.passes = core::atrous_passes_for_height(options.window_height);
  post_options.atrous_options.history_fix_frames = options.history_fix;
  // (Frames with sparse paths keep centre rays, on which these taps only blur silhouettes a little.)
  post_options.reprojection.jittered_planes = s.aux_mode == K_AUX_PATH_FIRST_HIT;
  s.denoising = post_options.atrous;
  s.reprojection = tracers::make_frame_post(s.post_place, core::with_history_moments(post_options));

  if (options.scenario) {
    try {
      s.scenario = std::make_unique<scene::Scenario>(s.world);
    } catch (const scene::ScenarioError& e) {
      warnings_.push_back(std::string("scenario off: ") + e.what());
      spdlog::warn("{}", warnings_.back());
    }
  }
}

PlaySession::~PlaySession() {
  // A frame announced at the last hand-out is handed out and waited for: remote tracers may have sent its
  // job ahead to their nodes, and a job ahead is answered within the band that adopts it.
  State& s = *state_;
  if (!s.next) return;
  try {
    s.pipeline->push(s.next->job, std::move(s.next->stages));
    s.pipeline->drain();
  } catch (const std::exception& e) {
    spdlog::warn("cohort play: the frame announced last failed while closing: {}", e.what());
  }
}

viewer::FlyCamera PlaySession::start_camera() const {
  const scene::Scene& scene = state_->world.scene();
  viewer::FlyCamera cam;
  cam.position = core::player_eye(scene);
  cam.yaw = scene.player_yaw;
  return cam;
}

PlaySession::State::Prepared PlaySession::State::prepare(const viewer::FlyCamera& camera, double seconds,
                                                        const FrameSettings& settings, bool paused) {
  State& s = *this;
  const bool animating = s.scenario && !paused;
  if (animating) s.scenario_seconds += seconds;
  const scene::RenderView view =
      camera.to_render_view(settings.width, settings.height, static_cast<int>(std::lround(s.scenario_seconds * 1000)));
  if (s.scenario) {
    s.scenario->frame(static_cast<int>(std::lround(s.scenario_seconds * kScenarioFramesPerSecond)));
    // The scenario carries its flashlight along its own scripted path; in the viewer it is held by
    // whoever flies the camera. Same offsets as the scenario: at the right hip, pointing ahead.
    const int flashlight = s.scenario->flashlight_handle();
    if (const scene::RenderLight* def = s.world.LightDef(flashlight)) {
      scene::RenderLight held = *def;
      held.origin = view.origin - view.axis[1] * 8.0f - view.axis[2] * 12.0f;
      held.axis = view.axis;
      s.world.UpdateLightDef(flashlight, held);
    }
  }
  s.world.RenderScene(view);
  s.world.EndFrame();

  ++s.frame_index;
  Prepared prepared;
  prepared.animating = animating;
  core::ScopedStage syncing(prepared.stages, core::kCoreTrack, "world sync");
  const commit::CommitBuffer commit = s.sync->sync(s.world.TakeChanges(), s.frame_index);
  s.renderer->submit_commit(commit, [&s] { return s.sync->snapshot(); });
  syncing.finish();
  prepared.commit_bytes = commit.bytes();

  core::BandJob& job = prepared.job;
  job.camera = camera.to_kcamera(settings.width, settings.height);
  KFrameParams& p = job.params;
  p = core::default_frame_params();
  p.frame_index = static_cast<kuint>(s.frame_index);
  p.spp = static_cast<kuint>(settings.spp);
  p.max_bounces = static_cast<kuint>(settings.max_bounces);
  p.light_sampling = settings.light_sampling;
  p.mode = settings.mode;
  const bool sparse = settings.render_scale < 1.0 && settings.upsample != core::UpsampleMethod::bilinear;
  if (sparse) {
    const core::PathPattern pattern = core::path_pattern_for_scale(settings.render_scale, s.frame_index);
    p.path_pixels = pattern.pixels;
    p.path_phase = pattern.phase;
  }
  if (settings.reproject || sparse || s.oidn) {  // OIDN takes the albedo and normal planes as its guides
    p.aux_outputs = s.aux_mode;
    job.previous_camera = s.previous_camera;
  }
  s.previous_camera = job.camera;
  return prepared;
}

SessionFrame PlaySession::frame(const viewer::FlyCamera& camera, double seconds, const FrameSettings& settings) {
  State& s = *state_;
  // With the announcement at hand-out, the frame handed out now was prepared by the call before, from
  // that call's input, and this call's input prepares the next one as soon as this one is handed out,
  // before the frame before is blended and shown: remote tracers' nodes start on it while this one
  // renders (docs/cluster.md, "The next frame announced at hand-out"). The price is a frame more between
  // input and image. The first call prepares its own frame (at the scenario's start) and the next.
  std::optional<State::Prepared> current = std::move(s.next);
  s.next.reset();
  if (!current) current = s.prepare(camera, s.announce_at_hand_out ? 0.0 : seconds, settings, paused_);
  const core::FramePipeline::PrepareNext prepare_next = [&]() -> std::optional<core::BandJob> {
    s.next = s.prepare(camera, seconds, settings, paused_);
    return s.next->job;
  };
  // The pipeline hands this frame out and gives back the one before it, which is blended and tone-mapped
  // while this one renders.
  const State::InFlight prepared = s.in_flight;
  std::optional<core::FramePipeline::Delivered> done = s.pipeline->push(
      current->job, std::move(current->stages), s.announce_at_hand_out ? prepare_next : core::FramePipeline::PrepareNext());
  s.in_flight = {current->commit_bytes, current->animating};
  SessionFrame out;
  if (!done) return out;
  out.ready = true;
  out.stats = std::move(done->stats);
  out.commit_bytes = prepared.commit_bytes;
  const core::FrameBuffer* merged = &s.pipeline->image();
  const core::GBuffer& gbuffer = s.pipeline->gbuffer();
  const core::PathPattern pattern{done->job.params.path_pixels, done->job.params.path_phase};
  // The reprojection reconstructs a sparse frame itself (joint-bilateral, FramePostOptions' default), where
  // it runs; the other methods (baselines picked in the HUD) run here first.
  const bool reprojects = settings.reproject && done->job.params.aux_outputs != 0u && !gbuffer.empty();
  const bool post_reconstructs = reprojects && settings.upsample == core::UpsampleMethod::joint_bilateral;
  if (pattern.sparse() && !post_reconstructs && !gbuffer.empty()) {
    core::ScopedStage upsampling(out.stats.stages, core::kCoreTrack, "upsample");
    core::upsample_sparse(*merged, gbuffer, pattern, settings.upsample, s.upsampled);
    merged = &s.upsampled;
  }
  const core::FrameBuffer& hdr = *merged;
  const kuint mode = done->job.params.mode;

  if (mode != s.last_mode) {  // another view of the scene entirely
    s.convergence.reset();
    s.reprojection->reset();
  }
  s.last_mode = mode;
  if (reprojects) {
    // Per-pixel history: moving objects carry their own motion, so no mask is needed.
    core::ScopedStage blending(out.stats.stages, core::kCoreTrack, "convergence");
    s.reprojection->process(hdr, gbuffer, post_reconstructs ? pattern : core::kEveryPixel);
    out.stats.convergence_f = 1.0 / std::max(s.reprojection->mean_history_length(), 1.0);
    blending.finish();
    s.show(s.reprojection->image(), gbuffer, settings, out);
    return out;
  }
  // Without per-pixel object ids every pixel counts as possibly moving while the door, fan and
  // flicker animate; pause the scenario (P) to let the image converge.
  const std::vector<float>* mask = nullptr;
  if (prepared.animating) {
    s.moving_mask.assign(static_cast<size_t>(hdr.width) * hdr.height, 1.0f);
    mask = &s.moving_mask;
  }
  if (!settings.accumulate) {
    out.stats.convergence_f = 1.0;
    s.show(hdr, gbuffer, settings, out);
    return out;
  }
  core::ScopedStage blending(out.stats.stages, core::kCoreTrack, "convergence");
  out.stats.convergence_f = s.convergence.accumulate(done->job.camera, hdr, mask);
  blending.finish();
  s.show(s.convergence.image(), gbuffer, settings, out);
  return out;
}

void PlaySession::State::show(const core::FrameBuffer& image, const core::GBuffer& gbuffer,
                              const FrameSettings& settings, SessionFrame& out) {
  const core::FrameBuffer* shown = &image;
  if (oidn) {
    core::ScopedStage denoising_stage(out.stats.stages, core::kCoreTrack, "denoise");
    core::DenoiseGuides guides;
    if (!gbuffer.empty() && gbuffer.width == image.width && gbuffer.height == image.height) {
      guides.albedo = &gbuffer.albedo;
      guides.normal = &gbuffer.normal;
      guides.clean = aux_mode == K_AUX_CENTRE_RAY;
    }
    oidn->denoise(image, denoised, guides);
    shown = &denoised;
  }
  core::ToneMapOptions tm;
  tm.curve = core::parse_tone_curve(settings.tone_curve);
  core::ScopedStage tone_mapping(out.stats.stages, core::kCoreTrack, "tone map");
  out.display = core::tone_map(*shown, tm);
  tone_mapping.finish();
  out.width = shown->width;
  out.height = shown->height;
}

void PlaySession::set_balancer(const std::string& name) { state_->renderer->set_balancer(name); }
const std::string& PlaySession::balancer() const { return state_->renderer->balancer_name(); }
bool PlaySession::scenario_running() const { return state_->scenario != nullptr; }
const std::string& PlaySession::map_name() const { return state_->map_name; }

bool PlaySession::any_gpu_tracer() const { return state_->any_gpu_tracer; }
const std::string& PlaySession::frame_post_place() const { return state_->post_place; }

bool PlaySession::denoising() const { return state_->denoising; }
const std::string& PlaySession::oidn_label() const { return state_->oidn_label; }

std::vector<std::string> PlaySession::tracer_names() const {
  std::vector<std::string> names;
  for (int i = 0; i < state_->renderer->tracer_count(); ++i) names.push_back(state_->renderer->tracer_name(i));
  return names;
}

}  // namespace cohort::app
