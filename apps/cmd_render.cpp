// `cohort render`: headless frames on one or more tracers (rows split by the balancer), written as
// tone-mapped LDR and linear HDR images plus a JSON of per-frame stats.
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <optional>

#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "cohort/commit/commit_buffer.h"
#include "cohort/core/band_buffer.h"
#include "cohort/core/frame_stats.h"
#include "cohort/core/frame_timeline.h"
#include "cohort/core/gpu_scene.h"
#include "cohort/core/convergence.h"
#include "cohort/core/frame_post.h"
#include "cohort/core/oidn_denoiser.h"
#include "cohort/core/upsample.h"
#include "cohort/core/frame_defaults.h"
#include "cohort/core/frame_pipeline.h"
#include "cohort/core/view.h"
#include "cohort/core/light_sampling.h"
#include "cohort/core/world_sync.h"
#include "cohort/scene/map_loader.h"
#include "cohort/scene/render_world_stream.h"
#include "cohort/tracers/tracer_registry.h"
#include <limits>
#include "cohort/core/image_output.h"
#include "cohort/core/renderer.h"
#include "cohort/core/tonemap.h"
#include "commands.h"
#include "camera_path.h"
#include "aux_rays_choice.h"
#include "convergence_choice.h"
#include "default_map.h"
#include "id_plane_output.h"
#include "node_port_options.h"
#include "progress_bar.h"
#include "render_scene_source.h"

namespace cohort::app {

namespace {

struct RenderArgs {
  std::string map;
  std::string tracers = "all";
  NodePortArgs node_port;  // rank 0's port for nodes that join
  std::string balancer = "whole-cost";  // benches a tracer that would slow the frame (docs/balancing.md)
  std::string mode = "path";
  std::string out = "render_out";
  int width = core::kDefaultWidth, height = core::kDefaultHeight, spp = 4, frames = 1, bounces = 1, light_samples = 1,
      emissive_samples = 1;
  std::string light_sampling = core::light_sampling_name(core::default_frame_params().light_sampling);
  float fov = core::kDefaultFovX, exposure = 1.0f, firefly_clamp = 5.0f, spec_boost = 2.0f, soft_shadow_scale = 0.2f,
        shadow_rr = core::default_frame_params().shadow_rr;
  float yaw_step = 0.0f;
  double time = 0.0, time_step_ms = 1000.0 / 60.0;  // material time of frame 0 and per frame (60 Hz game tics)
  std::string camera_path;    // spin/orbit[-slow|-fast]; empty: fixed camera (plus --yaw-step)
  std::string write = "all";  // images of every frame, or only the last
  std::vector<float> camera;  // x y z yaw pitch
  std::vector<std::string> bases;
  bool no_convergence = false;
  std::string convergence = "auto";  // convergence_choice.h
  std::string replay;
  std::string trace;
  std::string denoise = "none";
  std::string aux_rays = "auto";
  std::string denoise_quality = "high";
  int atrous_passes = 0;  // 0: from the image height (core/atrous_filter.h)
  std::string atrous_guide = core::atrous_guide_name(core::AtrousOptions{}.guide);
  float atrous_sigma = 0.0f;  // 0: the guide's default
  float atrous_short_history = core::AtrousOptions{}.short_history;
  float history_fix = core::AtrousOptions{}.history_fix_frames;
  float history_fix_stride = core::AtrousOptions{}.history_fix_stride;
  float history_fix_sigma = core::AtrousOptions{}.history_fix_sigma_scale;
  float history_fix_min = core::AtrousOptions{}.history_fix_min_length;
  float atrous_firefly = core::AtrousOptions{}.firefly_factor;
  float anti_lag = -1.0f;     // < 0: ReprojectionOptions' default
  float reproject_clamp = -1.0f;  // < 0: ReprojectionOptions' default
  std::string post_on = "auto";
  std::string band_format = "rgb9e5";
  bool frames_given = false;
  bool write_ids = false;  // the G-buffer's id plane of every written frame, and which entities moved
  bool bands_through_host = false;  // A/B: CUDA bands go down and back up even where the post could take them on the GPU
  int benched_commit_every = 8;     // RendererOptions::benched_commit_every
  int frames_in_flight = 1;         // RendererOptions::frames_in_flight
  double render_scale = 1.0;  // dynamic resolution (core/upsample.h)
  std::string upsample = "joint-bilateral";
};

// ACES and gamma 2.2 after --exposure (a factor), encoded exactly: the bytes `cohort render` has
// always written.
core::ToneMapOptions written_frame_tone_map(float exposure) {
  core::ToneMapOptions tm;
  tm.curve = core::ToneCurve::aces;
  tm.exposure_ev = std::log2(static_cast<double>(exposure));  // exp2 of it gives the float back exactly
  tm.srgb = false;
  tm.exact_encoding = true;
  return tm;
}

const std::map<std::string, uint32_t>& modes() {
  static const std::map<std::string, uint32_t> m = {
      {"path", K_MODE_PATH},         {"direct", K_MODE_DIRECT}, {"albedo", K_MODE_ALBEDO}, {"normals", K_MODE_NORMALS},
      {"specular", K_MODE_SPECULAR}, {"bvh", K_MODE_BVH},       {"triangles", K_MODE_TRIANGLES}};
  return m;
}

int run_render(const RenderArgs& a) {
  if (a.map.empty() && a.replay.empty()) throw std::invalid_argument("name a map or scene pack (or --replay FILE)");
  RenderScene scene = a.replay.empty() ? load_render_scene(a.map, bases_or_test_map(a.bases)) : RenderScene{};
  // Parsed once: "all" probes the devices.
  const std::vector<tracers::TracerSpec> specs = tracers::parse_tracer_list(a.tracers);
  // Before the remote tracers start MPI: the port's accept thread needs MPI_THREAD_MULTIPLE.
  if (!a.node_port.port_file.empty()) tracers::open_node_port(a.node_port.port_file, a.node_port.first_wait_s, specs);
  std::vector<std::unique_ptr<core::Tracer>> tracers = tracers::make_tracers(specs);
  bool any_gpu_tracer = false;
  for (const auto& tracer : tracers) any_gpu_tracer = any_gpu_tracer || tracer->renders_on_gpu();
  const std::string post_place = a.post_on == "auto" ? tracers::auto_frame_post_place(specs) : a.post_on;
  const std::string convergence_mode = resolve_convergence(a.convergence, any_gpu_tracer, post_place);
  core::RendererOptions options;
  options.balancer = a.balancer;
  options.benched_commit_every = a.benched_commit_every;
  options.frames_in_flight = a.frames_in_flight;
  options.band_format = core::band_format_from_string(a.band_format);
  options.frame_timeout = std::chrono::milliseconds(600000);
  core::Renderer renderer(std::move(tracers), options);
  // Dynamic resolution: sparse paths over the full-size G-buffer, reconstructed after the merge; or, for
  // the bilinear baseline, a smaller frame stretched before it is written.
  const core::UpsampleMethod upsample = core::parse_upsample_method(a.upsample);
  const bool scaled = a.render_scale < 1.0;
  const bool sparse = scaled && upsample != core::UpsampleMethod::bilinear;
  const bool stretched = scaled && upsample == core::UpsampleMethod::bilinear;
  const int render_width = stretched ? std::max(1, int(std::lround(a.width * a.render_scale))) : a.width;
  const int render_height = stretched ? std::max(1, int(std::lround(a.height * a.render_scale))) : a.height;
  if (scaled)
    spdlog::info("render scale {:.2f}: {}", a.render_scale,
                 sparse ? fmt::format("paths at {} of each 16 pixels, {} reconstruction from the G-buffer",
                                      core::path_pattern_for_scale(a.render_scale, 0).pixels, a.upsample)
                        : fmt::format("{}x{} stretched bilinearly to {}x{}", render_width, render_height, a.width,
                                      a.height));

  // --replay: a recorded delta stream drives a RenderWorld over the map; WorldSync turns each frame's
  // changes into commit records and the recorded view into the camera.
  std::unique_ptr<scene::Player> player;
  std::unique_ptr<scene::RenderWorld> world;
  std::unique_ptr<core::WorldSync> sync;
  int frames = a.frames;
  if (!a.replay.empty()) {
    player = std::make_unique<scene::Player>(a.replay);
    scene::Vfs vfs;
    for (const std::string& base : bases_or_test_map(a.bases)) vfs.add_search_path(base);
    world = std::make_unique<scene::RenderWorld>(scene::load_map(vfs, a.map.empty() ? player->header().map_name : a.map));
    core::WorldSyncOptions sync_options;
    sync_options.width = uint32_t(render_width);
    sync_options.height = uint32_t(render_height);
    sync = std::make_unique<core::WorldSync>(*world, sync_options);
    renderer.submit_commit(commit::CommitBuffer::full(sync->snapshot(), 0));
    frames = a.frames_given ? a.frames : std::numeric_limits<int>::max();
  } else if (scene.world) {
    // A map: its materials' registers (time, tables) are evaluated at each frame's time, and only the
    // materials that changed travel (core/world_sync.h).
    core::WorldSyncOptions sync_options;
    sync_options.width = uint32_t(render_width);
    sync_options.height = uint32_t(render_height);
    sync = std::make_unique<core::WorldSync>(*scene.world, sync_options);
    sync->set_time(a.time);
    renderer.submit_commit(commit::CommitBuffer::full(sync->snapshot(), 0));
  } else {
    if (a.time != 0.0 || a.frames > 1)
      spdlog::info("{}: a scene pack's materials are fixed when it is packed; render the map to animate them", a.map);
    renderer.submit_commit(commit::CommitBuffer::full(scene.tracer_scene, 1));
  }

  // What --light-sampling auto becomes on this scene (each tracer resolves it too, and logs it): for stats.json.
  const float light_density = core::light_density(sync ? *sync->snapshot() : *scene.tracer_scene);
  const std::string light_sampling_used =
      core::light_sampling_name(core::resolve_light_sampling(core::light_sampling_mode(a.light_sampling), light_density));

  glm::vec3 eye = scene.player_start + glm::vec3(0.0f, 0.0f, core::kPlayerEyeHeight);
  core::ViewAngles angles{scene.player_yaw, 0.0f};
  if (!a.camera.empty()) {
    eye = glm::vec3(a.camera[0], a.camera[1], a.camera[2]);
    angles = {a.camera[3], a.camera[4]};
  }
  std::filesystem::create_directories(a.out);
  const bool oiio = core::have_image_library();
  nlohmann::json stats_json = nlohmann::json::array();
  core::AdaptiveConvergence convergence;
  const bool reproject = convergence_mode == "reproject" && !a.no_convergence;
  KCamera previous_camera{};  // none yet: the first frame is its own previous
  const std::optional<CameraPath> path =
      a.camera_path.empty() ? std::nullopt : std::optional<CameraPath>(parse_camera_path(a.camera_path));
  ProgressBar progress(player ? 0 : a.frames, std::cerr, stderr_is_terminal());
  std::unique_ptr<core::ChromeTraceWriter> trace;
  if (!a.trace.empty()) trace = std::make_unique<core::ChromeTraceWriter>(a.trace);
  // The denoiser filters what is shown and written, never the accumulated history.
  std::unique_ptr<core::OidnDenoiser> denoiser;
  core::FrameBuffer denoised;
  const bool atrous = a.denoise == "atrous";
  // KFrameParams.aux_outputs of frames with planes
  const kuint aux_mode = resolve_aux_rays(a.aux_rays, a.denoise, specs);
  // Reprojection and the a-trous filter run together, on the host or on a GPU (core/frame_post.h).
  std::unique_ptr<core::FramePost> post;
  if (reproject || atrous) {
    core::FramePostOptions post_options;
    post_options.reproject = reproject;
    post_options.atrous = atrous;
    if (a.anti_lag >= 0.0f) post_options.reprojection.anti_lag_sigma = a.anti_lag;
    if (a.reproject_clamp >= 0.0f) post_options.reprojection.clamp_sigma = a.reproject_clamp;
    // Sparse-path frames keep centre rays (one fixed ray a pixel), whatever --aux-rays says.
    post_options.reprojection.jittered_planes = aux_mode == K_AUX_PATH_FIRST_HIT && !sparse;
    post_options.upsample = upsample;
    post_options.atrous_options.passes =
        a.atrous_passes > 0 ? a.atrous_passes : core::atrous_passes_for_height(render_height);
    core::AtrousOptions& ao = post_options.atrous_options;
    ao.guide = core::parse_atrous_guide(a.atrous_guide);
    if (a.atrous_sigma > 0.0f)
      (core::atrous_guide_uses_variance(ao.guide) ? ao.variance_sigma : ao.color_sigma) = a.atrous_sigma;
    ao.short_history = a.atrous_short_history;
    ao.history_fix_frames = a.history_fix;
    ao.history_fix_stride = a.history_fix_stride;
    ao.history_fix_sigma_scale = a.history_fix_sigma;
    ao.history_fix_min_length = a.history_fix_min;
    ao.firefly_factor = a.atrous_firefly;
    post = tracers::make_frame_post(post_place, post_options);
    spdlog::info("{}{}{} on {}", reproject ? "reprojection" : "", reproject && atrous ? " and " : "",
                 atrous ? "the a-trous filter (" + std::to_string(ao.passes) + " passes, " + a.atrous_guide + " guide)"
                        : std::string(),
                 post->where());
  }
  // Brigade's blend where a GPU's post would run (the host still picks f from the camera, core/convergence.h):
  // the bands then stay on the GPUs or cross packed, and the host neither merges nor blends them.
  const bool blend_on_gpu = !reproject && !atrous && !a.no_convergence && post_place != "host" &&
                            a.denoise == "none" && !a.write_ids;
  if (blend_on_gpu) {
    core::FramePostOptions blend_options;
    blend_options.reproject = false;
    blend_options.blend = true;
    blend_options.upsample = upsample;
    post = tracers::make_frame_post(post_place, blend_options);
    spdlog::info("Brigade's blend on {}", post->where());
  }
  // A reprojecting or blending post takes the fresh frame (and reconstructs sparse ones, where it runs); a
  // filter alone takes the frame Brigade's blend on the host shows.
  const bool post_takes_fresh = reproject || blend_on_gpu;
  // On a GPU it takes the bands as the tracers packed them: half the bytes cross the bus and the host skips
  // its conversions (the float frame and G-buffer are not made).
  const bool packed = post && post_takes_fresh && post->where() != "host" && a.denoise != "oidn" &&
                      a.denoise != "oidn-cuda" && !a.write_ids;
  // Sparse frames are filled where the post runs: inside the reprojecting or blending post, or for Brigade's
  // blend on the host (which takes full frames) by a post of its own with neither step, on the same place.
  std::unique_ptr<core::FramePost> reconstruction;
  if (sparse && !reproject && !blend_on_gpu) {
    core::FramePostOptions only_reconstruct;
    only_reconstruct.reproject = false;
    only_reconstruct.upsample = upsample;
    reconstruction = tracers::make_frame_post(post_place, only_reconstruct);
  }
  if (sparse) spdlog::info("sparse frames reconstructed on {}", (reconstruction ? reconstruction : post)->where());
  renderer.set_packed_merge(packed);
  if (packed && !a.bands_through_host) renderer.set_device_bands(post->cuda_device());
  if (a.denoise != "none" && !atrous) {
    denoiser = core::OidnDenoiser::open(core::parse_oidn_device(a.denoise == "oidn-cuda" ? "cuda" : "cpu"),
                                         core::parse_oidn_quality(a.denoise_quality));
    spdlog::info("denoising with Open Image Denoise ({} device, {})", core::oidn_device_name(denoiser->device()),
                 denoiser->library_path());
  }
  int rendered = 0;
  core::FrameBuffer upsampled;
  // The overlapped pipeline (core/frame_pipeline.h): frame f+1 is synced and handed out while frame f
  // renders; f is then blended, tone-mapped and written while f+1 renders.
  core::FramePipeline pipeline(renderer);
  std::map<uint64_t, core::TimelineClock::time_point> started;  // frames in the pipeline: when their world sync began
  core::TimelineClock::time_point previous_delivery{};
  // --write-ids: per frame in the pipeline, the entities whose placement changed since the previous frame.
  MovedEntities moved_entities;
  std::map<uint64_t, std::vector<std::string>> moved_by_frame;
  auto finish = [&](core::FramePipeline::Delivered done) {
    core::FrameStats& stats = done.stats;
    const int f = static_cast<int>(stats.frame);
    const core::FrameBuffer* merged = &pipeline.image();
    const core::PathPattern traced{done.job.params.path_pixels, done.job.params.path_phase};
    if (reconstruction && !pipeline.gbuffer().empty()) {
      core::ScopedStage upsampling(stats.stages, core::kCoreTrack, "upsample");
      reconstruction->process(*merged, pipeline.gbuffer(), traced);
      merged = &reconstruction->image();
    }
    const core::FrameBuffer& frame = *merged;
    // Adaptive convergence: a still camera accumulates every frame; motion raises f (see convergence.h).
    // Reprojection (--convergence reproject): per-pixel history through the frame's motion vectors.
    const core::GBuffer& gbuffer = pipeline.gbuffer();
    if (blend_on_gpu) {
      stats.convergence_f = convergence.next_factor(done.job.camera);
      post->set_blend_factor(stats.convergence_f);
    } else if (!reproject && !a.no_convergence) {
      core::ScopedStage blending(stats.stages, core::kCoreTrack, "convergence");
      stats.convergence_f = convergence.accumulate(done.job.camera, frame);
    }
    const core::FrameBuffer* shown_image = a.no_convergence ? &frame : &convergence.image();
    const bool post_runs = post && (packed || !gbuffer.empty() || blend_on_gpu);
    if (post_runs) {
      // One stage: on a GPU the two steps share one upload and one download.
      core::ScopedStage posting(stats.stages, core::kCoreTrack,
                                !atrous ? "convergence" : reproject ? "convergence+denoise" : "denoise");
      if (packed) post->process_packed(renderer.packed_frame(), renderer.packed_device_rows(), traced);
      else post->process(post_takes_fresh ? frame : *shown_image, gbuffer, post_takes_fresh ? traced : core::kEveryPixel);
      // On a GPU its own clock tells the bus from the passes (a track of its own in the timeline).
      if (const core::FramePostDeviceTimes t = post->device_times(); t.measured) {
        core::append_spans_ending_at(stats.stages, "post on " + post->where(), core::timeline_now_ms(),
                                     {{"upload", t.upload_ms}, {"passes", t.passes_ms}, {"download", t.download_ms}});
      }
      if (reproject) stats.convergence_f = 1.0 / std::max(post->mean_history_length(), 1.0);
    }
    const bool writes_frame = !(a.write == "last" && f + 1 < a.frames && !player);
    if (post_runs) shown_image = &post->image();
    // OIDN filters what the reprojection (or the blend) shows; the a-trous filter runs inside the post.
    if (denoiser && writes_frame) {
      core::ScopedStage denoising(stats.stages, core::kCoreTrack, "denoise");
      core::DenoiseGuides guides;
      if (!gbuffer.empty()) {  // the aux planes guide the filter where the frame has them
        guides.albedo = &gbuffer.albedo;
        guides.normal = &gbuffer.normal;
        guides.clean = aux_mode == K_AUX_CENTRE_RAY;
      }
      denoiser->denoise(*shown_image, denoised, guides);
      shown_image = &denoised;
    }
    if (stretched) {
      core::ScopedStage upsampling(stats.stages, core::kCoreTrack, "upsample");
      core::stretch_bilinear(*shown_image, a.width, a.height, upsampled);
      shown_image = &upsampled;
    }
    const core::FrameBuffer& shown = *shown_image;
    ++rendered;
    if (writes_frame) {
      char stem[32];
      std::snprintf(stem, sizeof stem, "frame_%04d", f);
      std::filesystem::path base = std::filesystem::path(a.out) / stem;
      core::ScopedStage tone_mapping(stats.stages, core::kCoreTrack, "tone map");
      const std::vector<uint8_t> display = core::tone_map(shown, written_frame_tone_map(a.exposure));
      tone_mapping.finish();
      core::ScopedStage writing(stats.stages, core::kCoreTrack, "output");
      core::write_ldr_image(base.string() + (oiio ? ".png" : ".ppm"), shown.width, shown.height, display);
      core::write_hdr_image(base.string() + (oiio ? ".exr" : ".pfm"), shown);
      if (a.write_ids && !gbuffer.empty()) {
        std::snprintf(stem, sizeof stem, "ids_%04d.pgm", f);
        write_id_plane_pgm((std::filesystem::path(a.out) / stem).string(), gbuffer.width, gbuffer.height, gbuffer.id);
      }
    }
    const auto now = core::TimelineClock::now();
    const auto frame_start = started.at(stats.frame);
    started.erase(stats.frame);
    stats.end_to_end_ms = std::chrono::duration<double, std::milli>(now - frame_start).count();
    stats.interval_ms = previous_delivery == core::TimelineClock::time_point{}
                            ? stats.end_to_end_ms
                            : std::chrono::duration<double, std::milli>(now - previous_delivery).count();
    previous_delivery = now;
    stats.stages.push_back({core::kCoreTrack, "frame", core::timeline_ms(frame_start), stats.end_to_end_ms});
    if (trace) trace->add(stats.frame, stats.stages);
    progress.frame_done(stats.interval_ms);
    spdlog::debug("frame {}: {:.1f} ms ({} tracers, idle {:.1f}%)", f, stats.frame_ms, stats.tracers.size(),
                  stats.idle_percent);
    stats_json.push_back(nlohmann::json(stats));
    if (a.write_ids) {
      auto moved = moved_by_frame.find(stats.frame);
      stats_json.back()["moved_entities"] = moved == moved_by_frame.end() ? std::vector<std::string>() : moved->second;
      if (moved != moved_by_frame.end()) moved_by_frame.erase(moved);
    }
  };
  // Frame f's preparation: its world sync (commits submitted) and its job; nothing when a replay has ended.
  struct Prepared {
    core::BandJob job;
    std::vector<core::StageSpan> stages;  // the core's stages before the Renderer's own
  };
  auto prepare = [&](int f) -> std::optional<Prepared> {
    const auto frame_start = core::TimelineClock::now();
    std::vector<core::StageSpan> stages;  // the core's stages before the Renderer's own
    core::BandJob job;
    if (player) {
      if (!player->play_frame(*world)) return std::nullopt;
      if (a.write_ids) moved_by_frame[uint64_t(f)] = moved_entities.update(*world);
      core::ScopedStage syncing(stages, core::kCoreTrack, "world sync");
      renderer.submit_commit(sync->sync(world->TakeChanges(), uint64_t(f) + 1), [&] { return sync->snapshot(); });
      syncing.finish();
      job.camera = sync->master().camera;
    } else {
      if (sync && f > 0) {  // a map: its animated materials at this frame's time
        sync->set_time(a.time + double(f) * a.time_step_ms * 0.001);
        core::ScopedStage syncing(stages, core::kCoreTrack, "world sync");
        renderer.submit_commit(sync->sync(scene.world->TakeChanges(), uint64_t(f)), [&] { return sync->snapshot(); });
      }
      if (path) {
        const CameraPose pose = camera_path_pose(*path, eye, angles.yaw, f);
        job.camera = core::make_camera(pose.origin, {pose.yaw, angles.pitch}, a.fov, render_width, render_height);
      } else {
        job.camera = core::make_camera(eye, {angles.yaw + a.yaw_step * float(f), angles.pitch}, a.fov, render_width,
                                       render_height);
      }
    }
    KFrameParams& p = job.params;
    p = core::default_frame_params();
    p.frame_index = static_cast<kuint>(f);
    p.spp = static_cast<kuint>(a.spp);
    p.max_bounces = static_cast<kuint>(a.bounces);
    p.light_samples = static_cast<kuint>(a.light_samples);
    p.light_sampling = core::light_sampling_mode(a.light_sampling);
    p.emissive_samples = static_cast<kuint>(a.emissive_samples);
    p.firefly_clamp = a.firefly_clamp;
    p.spec_boost = a.spec_boost;
    p.mode = modes().at(a.mode);
    p.soft_shadow_scale = a.soft_shadow_scale;
    p.shadow_rr = a.shadow_rr;
    if (sparse) {
      const core::PathPattern pattern = core::path_pattern_for_scale(a.render_scale, uint64_t(f));
      p.path_pixels = pattern.pixels;
      p.path_phase = pattern.phase;
    }
    // Open Image Denoise takes the albedo and normal planes as its guides.
    if (reproject || atrous || denoiser || sparse || a.write_ids) {
      p.aux_outputs = aux_mode;
      job.previous_camera = previous_camera;
      previous_camera = job.camera;
    }
    started[uint64_t(f)] = frame_start;
    return Prepared{job, std::move(stages)};
  };
  // The next frame is prepared, and announced, as soon as a frame is handed out, before the frame before
  // it is merged, blended and written (FramePipeline::push with prepare_next): a remote tracer's node
  // starts on it then (docs/cluster.md). COHORT_EARLY_ANNOUNCE=0 prepares it after, as before (for
  // comparison).
  const bool early_announce = core::FramePipeline::announces_at_hand_out();
  std::optional<Prepared> next = frames > 0 ? prepare(0) : std::nullopt;
  for (int f = 0; next; ++f) {
    Prepared current = std::move(*next);
    next.reset();
    const core::FramePipeline::PrepareNext prepare_next = [&, f]() -> std::optional<core::BandJob> {
      if (f + 1 < frames) next = prepare(f + 1);
      return next ? std::optional<core::BandJob>(next->job) : std::nullopt;
    };
    std::optional<core::FramePipeline::Delivered> done =
        pipeline.push(current.job, std::move(current.stages), early_announce ? prepare_next : nullptr);
    if (done) finish(std::move(*done));
    if (!early_announce) prepare_next();
  }
  if (std::optional<core::FramePipeline::Delivered> done = pipeline.drain()) finish(std::move(*done));
  progress.finish();
  nlohmann::json report = {{"map", a.map},       {"scene", scene.name},     {"tracers", a.tracers},
                           {"balancer", a.balancer}, {"frames_in_flight", a.frames_in_flight}, {"width", a.width},     {"height", a.height},
                           {"spp", a.spp},       {"bounces", a.bounces},
                           {"light_sampling", a.light_sampling}, {"light_sampling_used", light_sampling_used},
                           {"light_density", light_density}, {"light_samples", a.light_samples},    {"mode", a.mode},
                           {"camera_path", a.camera_path}, {"denoise", a.denoise},
                           {"render_scale", a.render_scale}, {"upsample", a.upsample},
                           {"convergence", a.no_convergence ? "none" : convergence_mode}, {"frames", stats_json}};
  // What the tracers' rows take a frame (colour only; aux planes, when asked for, add 32 bytes a pixel).
  report["band_format"] = a.band_format;
  report["band_bytes_per_frame"] = size_t(render_width) * size_t(render_height) *
                                   core::bytes_per_pixel(core::band_format_from_string(a.band_format));
  if (a.write_ids) {
    const scene::RenderWorld* ids_world = world ? world.get() : scene.world.get();
    report["entity_ids"] = ids_world ? entity_plane_ids(*ids_world) : std::map<std::string, uint32_t>();
  }
  std::ofstream(std::filesystem::path(a.out) / "stats.json") << report.dump(2) << "\n";
  std::cout << "wrote " << rendered << " frame(s) and stats.json to " << a.out << "\n";
  return kExitOk;
}

}  // namespace

void add_render_command(CLI::App& app, int& exit_code) {
  auto* cmd = app.add_subcommand("render", "Render frames headless on the chosen tracers and write images and a "
                                           "JSON of per-frame stats");
  auto a = std::make_shared<RenderArgs>();
  cmd->add_option("map", a->map, "scene pack, or map: a .map path, a game path or a bare name "
                                 "(with --replay: defaults to the map the stream names)");
  cmd->add_option("--replay", a->replay, "a recorded delta stream (docs/delta-stream.md, `cohort record-scenario`): "
                                         "render its frames, camera and changes as recorded");
  cmd->add_option("--base", a->bases, "extra game folder(s) to search (loose files and .pk4s)");
  cmd->add_option("--trace", a->trace,
                  "write every frame's timeline (world sync, each tracer's apply and render, merge, convergence, "
                  "tone map, output) as a Chrome trace event file: open it in ui.perfetto.dev or chrome://tracing");
  cmd->add_option("--tracers", a->tracers,
                  "comma-separated: embree, opencl[:N|:all], cuda[:N|:all], or all (Embree on the CPU plus every GPU once); "
                  "`cohort devices` lists which device each opencl:N is")
      ->capture_default_str();
  add_node_port_options(cmd, a->node_port);
  cmd->add_option("--balancer", a->balancer, "row balancer when there are several tracers")->capture_default_str();
  cmd->add_option("--band-format", a->band_format,
                  "what the tracers hand back: RGB half floats (6 bytes a pixel), RGB9E5 (4 bytes a pixel: 9-bit mantissas "
                  "under a shared exponent, dithered so averaging frames keeps no bias) or RGBA floats (16)")
      ->capture_default_str()
      ->check(CLI::IsMember({"rgb16f", "rgb9e5", "rgba32f"}));
  cmd->add_option("--width", a->width, "image width")->capture_default_str()->check(CLI::PositiveNumber);
  cmd->add_option("--height", a->height, "image height")->capture_default_str()->check(CLI::PositiveNumber);
  cmd->add_option("--spp", a->spp, "samples per pixel per frame")->capture_default_str()->check(CLI::PositiveNumber);
  cmd->add_option("--time", a->time, "game time of frame 0 in seconds, for the materials' registers (time, "
                                     "tables: flicker, scrolling, pulsing); maps only, scene packs are fixed")
      ->capture_default_str();
  cmd->add_option("--time-step", a->time_step_ms, "game time between frames in ms (0 freezes the materials)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  auto* frames_option =
      cmd->add_option("--frames", a->frames, "frames to render (with --replay: at most this many; default all)")
          ->capture_default_str()
          ->check(CLI::PositiveNumber);
  cmd->add_option("--bounces", a->bounces, "indirect bounces")->capture_default_str()->check(CLI::NonNegativeNumber);
  cmd->add_option("--light-sampling", a->light_sampling,
                  "how each hit picks the map's lights: tree (among the lights whose volume holds the point, "
                  "through the light tree: cost independent of the light count), all (reference: a pick by "
                  "contribution over every light), every (reference: every light, one shadow ray each), gather (a "
                  "shadow ray for each light whose volume holds the point, found through the light tree, while "
                  "there are at most --light-samples of them; beyond that at most --light-samples rays (16 at "
                  "most), the brightest lights first, unbiased), in-range (one light per sample, picked by its "
                  "unshadowed contribution among every light whose volume holds the point, found through the tree "
                  "without its descent: cost grows with the lights in range, not the map's), dense (for rooms where "
                  "many lights reach a point: a descent of the tree by a guess of each subtree's contribution to 8 "
                  "lights, then in-range among them; bounded cost, more noise) or auto (in-range or dense, by how "
                  "many lights' volumes hold each light's centre on average: dense above 16; logged, and in "
                  "stats.json as light_sampling_used)")
      ->capture_default_str()
      ->check(CLI::IsMember(core::light_sampling_names()));
  cmd->add_option("--light-samples", a->light_samples,
                  "lights sampled per hit with --light-sampling tree, in-range, dense, auto or all, most shadow rays per hit with "
                  "gather (0: every light, as --light-sampling every)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--emissive-samples", a->emissive_samples,
                  "emissive triangles sampled per hit, combined with the bounce by multiple importance sampling "
                  "(0: emissive surfaces are found by bounce rays only)")
      ->capture_default_str()
      ->check(CLI::Range(0, 1));
  cmd->add_option("--mode", a->mode, "path, direct, albedo, normals, specular, bvh, triangles")
      ->capture_default_str()
      ->check(CLI::IsMember({"path", "direct", "albedo", "normals", "specular", "bvh", "triangles"}));
  cmd->add_option("--fov", a->fov, "horizontal field of view in degrees")->capture_default_str();
  cmd->add_option("--camera", a->camera, "x y z yaw pitch: Doom 3 angles in degrees, positive pitch looks down (default: the player start at eye height)")->expected(5);
  cmd->add_option("--camera-path", a->camera_path, "scripted camera from the start: spin or orbit, -slow (default) or "
                                                   "-fast, e.g. orbit-fast")
      ->check(camera_path_error);
  cmd->add_option("--aux-rays", a->aux_rays,
                  "where the G-buffer for reprojection and denoising comes from: auto (centre with --denoise oidn "
                  "or oidn-cuda, whose guides are then clean; else first-hit where CUDA GPUs "
                  "render and no OpenCL or mpi tracer does, else centre), centre (a ray of its own through "
                  "each pixel's centre: steady planes) or first-hit (the first sample's own first surface: no "
                  "extra ray, about 0.8 ms less a 1080p frame on an H100, but the planes jitter as the samples "
                  "do; the reprojection then keeps silhouettes' history from the neighbours' surfaces; frames with "
                  "sparse paths keep centre rays; "
                  "docs/denoising.md)")
      ->capture_default_str()
      ->check(CLI::IsMember(aux_rays_choices()));
  cmd->add_option("--denoise", a->denoise,
                  "denoise the shown frame: none, atrous (the real-time edge-aware a-trous filter of the portable "
                  "kernel, every frame), oidn (Intel Open Image Denoise on the CPU) or oidn-cuda (on an NVIDIA GPU: "
                  "5-7 ms a 1280x720 frame on an H100 with its guides, the lowest FLIP measured there with "
                  "--no-convergence); OIDN takes the albedo and normal planes as guides (clean ones from centre "
                  "rays, --aux-rays auto); tools/fetch_oidn.sh installs the library")
      ->capture_default_str()
      ->check(CLI::IsMember({"none", "atrous", "oidn", "oidn-cuda"}));
  cmd->add_option("--atrous-passes", a->atrous_passes,
                  "passes of --denoise atrous (steps 1, 2, 4, ...: 1 pass is a 5x5 filter, 3 a 29-pixel one); "
                  "0 picks them from the image height (1 up to 360 rows, 2 up to 540, 3 at 720 and 1080)")
      ->capture_default_str()
      ->check(CLI::Range(0, 6));
  cmd->add_option("--atrous-guide", a->atrous_guide,
                  "luminance stop of --denoise atrous: variance (SVGF: each pixel's luminance variance from the "
                  "reprojected history's moments, or its neighbourhood while the history is short), "
                  "variance-of-mean (that over the history length: the noise the accumulated frame still has) or "
                  "fixed (one relative scale everywhere)")
      ->capture_default_str()
      ->check(CLI::IsMember({"variance", "variance-of-mean", "fixed"}));
  cmd->add_option("--atrous-sigma", a->atrous_sigma,
                  "luminance stop's scale of --denoise atrous: standard deviations with the variance guide "
                  "(default 4), relative difference with the fixed one (default 2); 0 keeps the default")
      ->capture_default_str()
      ->check(CLI::Range(0.0f, 1000.0f));
  cmd->add_option("--atrous-short-history", a->atrous_short_history,
                  "variance guides of --denoise atrous: a history shorter than this many frames has its variance "
                  "estimated from its 7x7 neighbourhood instead of its own temporal moments (SVGF: 4; cheaper: 2)")
      ->capture_default_str()
      ->check(CLI::Range(0.0f, 1000.0f));
  cmd->add_option("--history-fix", a->history_fix,
                  "--denoise atrous after the reprojection: a pixel whose history is shorter than this many frames "
                  "gets a wider edge-aware blur before the passes (NRD's HistoryFix; 0: off)")
      ->capture_default_str()
      ->check(CLI::Range(0.0f, 64.0f));
  cmd->add_option("--history-fix-stride", a->history_fix_stride,
                  "pixels between the history fix's taps at a one-frame history (fewer as the history grows); 0: "
                  "from the image height (1 at 180 rows, 2 at 360, 4 at 720)")
      ->capture_default_str()
      ->check(CLI::Range(0.0f, 32.0f));
  cmd->add_option("--atrous-firefly", a->atrous_firefly,
                  "before the a-trous passes, a pixel brighter than this many times its brightest neighbour is scaled "
                  "down to that (a lone 1-spp firefly; the history keeps its light); 0: off")
      ->capture_default_str()
      ->check(CLI::Range(0.0f, 1000.0f));
  cmd->add_option("--history-fix-min", a->history_fix_min,
                  "the history fix leaves histories shorter than this many frames to the passes (1: a fresh "
                  "sample; 1.5 also those the anti-lag cut to under half a frame; 0: fixes every short history)")
      ->capture_default_str()
      ->check(CLI::Range(0.0f, 64.0f));
  cmd->add_option("--history-fix-sigma", a->history_fix_sigma,
                  "the history fix's luminance stop as a multiple of the passes' (--atrous-sigma)")
      ->capture_default_str()
      ->check(CLI::Range(0.0f, 1000.0f));
  cmd->add_option("--anti-lag", a->anti_lag,
                  "reprojection's anti-lag: a moving pixel's history whose 5x5 mean luma is off the fresh frame's by "
                  "more than this many standard errors of that mean is shortened in proportion (stale lighting: a "
                  "flashlight, a flicker, a door letting light in); 0 turns it off; default " +
                      std::to_string(core::ReprojectionOptions{}.anti_lag_sigma).substr(0, 4))
      ->check(CLI::Range(0.0f, 1000.0f));
  cmd->add_option("--reproject-clamp", a->reproject_clamp,
                  "reprojection's neighbourhood clamp: a moving pixel's history is held within the fresh 3x3 "
                  "samples' mean +- this many standard deviations (YCoCg); larger ghosts more, smaller loses the "
                  "light of rare bright samples; default " +
                      std::to_string(core::ReprojectionOptions{}.clamp_sigma).substr(0, 4))
      ->check(CLI::Range(0.0f, 1000.0f));
  cmd->add_option("--post-on", a->post_on,
                  "where reprojection and the a-trous filter run: host (the CPU's threads), cuda:N (a GPU; the "
                  "frame and its G-buffer cross the bus each frame) or auto (the first CUDA tracer's GPU, else the "
                  "host)")
      ->capture_default_str();
  cmd->add_option("--benched-commit-every", a->benched_commit_every,
                  "a tracer the balancer benches (no rows) applies the world's changes every N frames, coalesced, "
                  "instead of every frame (1: every frame); it catches up before it renders again")
      ->capture_default_str()
      ->check(CLI::Range(1, 1000));
  cmd->add_option("--frames-in-flight", a->frames_in_flight,
                  "2: hand frame N+1's bands out as soon as N's are, so that each tracer starts N+1 the moment its "
                  "band of N is done instead of waiting for the slowest band and the core's turnaround; the "
                  "balancer then divides each frame by the costs of the frame two before, and each frame comes up to a "
                  "frame later (docs/balancing.md, \"Two frames in flight\")")
      ->capture_default_str()
      ->check(CLI::Range(1, 2));
  cmd->add_flag("--bands-through-host", a->bands_through_host,
               "with the post-processing on a CUDA GPU, copy CUDA tracers' bands down to the host and back up "
               "like any other (by default they stay on the GPUs: device to device, or over NVLink from a peer)");
  cmd->add_option("--denoise-quality", a->denoise_quality,
                  "Open Image Denoise's filter quality: high, balanced or fast (on the CPU several times quicker; "
                  "on an H100 at 720p, colour alone, 4.1 ms fast against 4.7 high, where copies and packing take half the time)")
      ->capture_default_str()
      ->check(CLI::IsMember({"high", "balanced", "fast"}));
  cmd->add_option("--convergence", a->convergence,
                  "how frames accumulate: reproject (per-pixel history through motion vectors, with disocclusion "
                  "tests and neighbourhood clamping; the tracers also write depth, normal, albedo, id and motion) "
                  "or brigade (whole-frame blend, f from camera motion; the paper's); auto: reproject, except when "
                  "GPU tracers render and the reprojection would run on the host (no CUDA GPU for --post-on), "
                  "where it would set the frame rate (docs/denoising.md)")
      ->capture_default_str()
      ->check(CLI::IsMember({"auto", "brigade", "reproject"}));
  cmd->add_flag("--write-ids", a->write_ids,
                "also write each frame's id plane as ids_NNNN.pgm (16-bit: 0 the world, entity handle + 1, 65535 a "
                "miss; the tracers' auxiliary outputs) and, in stats.json, the map entities' ids and per frame of "
                "a --replay the entities that moved since the previous frame (bench/quality/bench_quality.py)");
  cmd->add_flag("--no-convergence", a->no_convergence,
                 "write each frame as rendered instead of blending frames with adaptive convergence");
  cmd->add_option("--write", a->write, "images of every frame, or only the last (stats.json always has every frame)")
      ->capture_default_str()
      ->check(CLI::IsMember({"all", "last"}));
  cmd->add_option("--yaw-step", a->yaw_step, "degrees the camera turns per frame")->capture_default_str();
  cmd->add_option("--exposure", a->exposure, "exposure before the tone curve")->capture_default_str();
  cmd->add_option("--firefly-clamp", a->firefly_clamp, "max indirect contribution (0: off)")->capture_default_str();
  cmd->add_option("--spec-boost", a->spec_boost, "specular boost of light interactions")->capture_default_str();
  cmd->add_option("--shadow-rr", a->shadow_rr,
                  "Russian roulette on shadow rays: a light sample adding less than this to the pixel traces its "
                  "ray with probability contribution / this (unbiased: such samples count threshold / contribution "
                  "times; 0: every sample's ray is traced)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--soft-shadows", a->soft_shadow_scale, "scale of the lights' soft-shadow extent")
      ->capture_default_str();
  cmd->add_option("--render-scale", a->render_scale,
                  "dynamic resolution: trace paths for about scale^2 of the pixels (a pattern that moves every "
                  "frame; every pixel still gets its G-buffer) and reconstruct the rest with --upsample")
      ->capture_default_str()
      ->check(CLI::Range(0.05, 1.0));
  cmd->add_option("--upsample", a->upsample,
                  "reconstruction at --render-scale below 1: joint-bilateral (weights from the full-resolution "
                  "depth, normal, object id and albedo; illumination times each pixel's albedo), nearest (the nearest "
                  "traced pixel), or bilinear (render a scale * width x scale * height frame and stretch it, as "
                  "`play` did with GL_LINEAR)")
      ->capture_default_str()
      ->check(CLI::IsMember({"joint-bilateral", "nearest", "bilinear"}));
  cmd->add_option("--out", a->out, "output folder")->capture_default_str();
  cmd->callback([a, frames_option, &exit_code] {
    a->frames_given = frames_option->count() > 0;
    exit_code = run_render(*a);
  });
}

}  // namespace cohort::app
