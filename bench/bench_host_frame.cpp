// The core's per-pixel host work per frame (merge of the tracers' bands, the convergence blend, the
// tone map) at a given size, for each band format: what `cohort render` and `cohort play` spend on the
// host besides the tracers. Two simulated tracers (virtual clock) split the rows; the camera stays
// still, so every frame blends into the accumulated image. The reprojection (core/reprojection.h) is
// timed beside the blend on a synthetic G-buffer in which every pixel moves (0.3 pixels a frame, the
// costly case: bilinear history and neighbourhood clamp everywhere), then the a-trous filter over its
// result with the passes `--denoise atrous` picks for the height: with the fixed luminance stop, and
// with the variance guide (core/atrous_filter.h) over a reprojection that keeps the luminance moments
// (its own "reproject+moments" column): from the history's temporal variance (every pixel's history is
// long after 4 frames) and, the worst case of a frame with no history, from the 7x7 spatial estimate,
// without and with the history fix (every pixel's history one frame long: every pixel is fixed).
//
//   bench_host_frame [--width 1920] [--height 1080] [--frames 40] [--json FILE]   (out/bench_host_frame.json)
//                    [--anti-lag SIGMA]   (the reprojection's; 0 turns it off, default ReprojectionOptions')
//                    [--jittered-edges 0|1|2]  (every pixel a silhouette whose surface flips each frame, as
//                    first-hit planes at an edge: a checkerboard of two surfaces inverted every frame; 1 with
//                    ReprojectionOptions::jittered_planes off, 2 on: the footprint taps' worst case)
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cohort/balance/order_statistics.h"
#include "cohort/core/convergence.h"
#include "cohort/core/frame_pipeline.h"
#include "cohort/core/host_threads.h"
#include "cohort/core/renderer.h"
#include "cohort/core/atrous_filter.h"
#include "cohort/core/reprojection.h"
#include "cohort/core/simulated_tracer.h"
#include "cohort/core/tonemap.h"

using namespace cohort;
using namespace cohort::core;

namespace {

float anti_lag_sigma = -1.0f;  // --anti-lag; < 0: the default of ReprojectionOptions
int jittered_edges = 0;        // --jittered-edges

double stage_ms(const FrameStats& stats, const std::string& stage) {
  double ms = 0.0;
  for (const StageSpan& s : stats.stages)
    if (s.track == kCoreTrack && s.stage == stage) ms += s.ms;
  return ms;
}

nlohmann::json run(BandFormat format, int width, int height, int frames) {
  std::vector<std::unique_ptr<Tracer>> tracers;
  for (uint64_t tag : {1u, 2u}) {
    SimulatedTracerOptions o;
    o.name = "sim" + std::to_string(tag);
    o.seed = tag;
    tracers.push_back(std::make_unique<SimulatedTracer>(std::make_shared<SpinSceneCostModel>(3), o));
  }
  RendererOptions options;
  options.use_reported_time = true;
  options.band_format = format;
  Renderer renderer(std::move(tracers), options);
  FramePipeline pipeline(renderer);
  AdaptiveConvergence convergence;
  ToneMapOptions tone_options;
  ReprojectionOptions reprojection_options;
  if (anti_lag_sigma >= 0.0f) reprojection_options.anti_lag_sigma = anti_lag_sigma;
  reprojection_options.jittered_planes = jittered_edges == 2;
  TemporalReprojection reprojection(reprojection_options);
  ReprojectionOptions moment_options = reprojection_options;
  moment_options.luminance_moments = true;
  TemporalReprojection reprojection_with_moments(moment_options);
  AtrousOptions fixed_options, variance_options;
  fixed_options.passes = variance_options.passes = atrous_passes_for_height(height);
  fixed_options.guide = AtrousGuide::fixed;
  variance_options.guide = AtrousGuide::variance_of_mean;  // the default; SVGF's "variance" costs the same
  AtrousOptions fix_options = variance_options, no_fix_options = variance_options;
  no_fix_options.history_fix_frames = 0.0f;
  if (fix_options.history_fix_frames <= 0.0f) fix_options.history_fix_frames = 6.0f;
  AtrousFilter atrous(fixed_options), guided(variance_options), guided_no_fix(no_fix_options), guided_fix(fix_options);
  // The history fix's worst case: every pixel's history one frame long, so every pixel is fixed.
  const std::vector<float> one_frame(static_cast<size_t>(width) * static_cast<size_t>(height), 1.0f);
  FrameBuffer filtered;
  GBuffer moving;
  moving.resize(width, height);
  for (size_t p = 0; p < moving.pixels(); ++p) {
    moving.depth[p] = moving.prev_depth[p] = 100.0f;
    moving.normal[3 * p + 2] = 1.0f;
    moving.id[p] = 0;
    moving.motion[2 * p] = 0.3f;
    for (int k = 0; k < 3; ++k) moving.albedo[3 * p + k] = 0.5f;
  }
  std::vector<double> merge, blend, tone, reproject, denoise, reproject_moments, guided_ms, spatial_ms, fix_ms;
  auto finish = [&](FramePipeline::Delivered done) {
    if (jittered_edges > 0)
      for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
          const size_t p = static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x);
          const bool near = ((x + y + static_cast<int>(done.stats.frame)) & 1) != 0;
          moving.id[p] = near ? 1u : 0u;
          moving.depth[p] = moving.prev_depth[p] = near ? 50.0f : 100.0f;
        }
    ScopedStage blending(done.stats.stages, kCoreTrack, "convergence");
    convergence.accumulate(done.job.camera, pipeline.image());
    blending.finish();
    ScopedStage reprojecting(done.stats.stages, kCoreTrack, "reproject");
    reprojection.accumulate(pipeline.image(), moving);
    reprojecting.finish();
    ScopedStage filtering(done.stats.stages, kCoreTrack, "atrous");
    atrous.apply(reprojection.image(), moving, filtered);
    filtering.finish();
    ScopedStage with_moments(done.stats.stages, kCoreTrack, "reproject+moments");
    reprojection_with_moments.accumulate(pipeline.image(), moving);
    with_moments.finish();
    ScopedStage guiding(done.stats.stages, kCoreTrack, "atrous variance");
    guided.apply(reprojection_with_moments.image(), moving, filtered,
                 AtrousHistory{reprojection_with_moments.luminance_moments().data(),
                               reprojection_with_moments.history_length().data()});
    guiding.finish();
    ScopedStage spatial(done.stats.stages, kCoreTrack, "atrous variance spatial");
    guided_no_fix.apply(reprojection_with_moments.image(), moving, filtered, AtrousHistory{nullptr, one_frame.data()});
    spatial.finish();
    ScopedStage fixing(done.stats.stages, kCoreTrack, "atrous variance spatial+fix");
    guided_fix.apply(reprojection_with_moments.image(), moving, filtered, AtrousHistory{nullptr, one_frame.data()});
    fixing.finish();
    ScopedStage mapping(done.stats.stages, kCoreTrack, "tone map");
    const std::vector<uint8_t> display = tone_map(convergence.image(), tone_options);
    mapping.finish();
    if (done.stats.frame < 5) return;  // warm-up: first-touch page faults, thread start
    merge.push_back(stage_ms(done.stats, "merge"));
    blend.push_back(stage_ms(done.stats, "convergence"));
    tone.push_back(stage_ms(done.stats, "tone map"));
    reproject.push_back(stage_ms(done.stats, "reproject"));
    denoise.push_back(stage_ms(done.stats, "atrous"));
    reproject_moments.push_back(stage_ms(done.stats, "reproject+moments"));
    guided_ms.push_back(stage_ms(done.stats, "atrous variance"));
    spatial_ms.push_back(stage_ms(done.stats, "atrous variance spatial"));
    fix_ms.push_back(stage_ms(done.stats, "atrous variance spatial+fix"));
  };
  for (int f = 0; f < frames; ++f) {
    BandJob job;
    job.camera = spin_camera(width, height, 0.0);
    job.params.frame_index = static_cast<kuint>(f);
    if (auto done = pipeline.push(job)) finish(std::move(*done));
  }
  if (auto done = pipeline.drain()) finish(std::move(*done));
  const double m = median(merge), c = median(blend), t = median(tone);
  return {{"band_format", to_string(format)}, {"band_bytes_per_pixel", bytes_per_pixel(format)},
          {"merge_ms", m}, {"convergence_ms", c}, {"tone_map_ms", t}, {"host_ms", m + c + t},
          {"reproject_ms", median(reproject)}, {"atrous_passes", atrous_passes_for_height(height)},
          {"atrous_ms", median(denoise)}, {"reproject_moments_ms", median(reproject_moments)},
          {"atrous_variance_ms", median(guided_ms)}, {"atrous_variance_spatial_ms", median(spatial_ms)},
          {"atrous_variance_spatial_history_fix_ms", median(fix_ms)}};
}

}  // namespace

int main(int argc, char** argv) {
  int width = 1920, height = 1080, frames = 40;
  std::string json_path = "out/bench_host_frame.json";
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string arg = argv[i];
    if (arg == "--width") width = std::stoi(argv[i + 1]);
    else if (arg == "--height") height = std::stoi(argv[i + 1]);
    else if (arg == "--frames") frames = std::max(6, std::stoi(argv[i + 1]));
    else if (arg == "--json") json_path = argv[i + 1];
    else if (arg == "--anti-lag") anti_lag_sigma = std::stof(argv[i + 1]);
    else if (arg == "--jittered-edges") jittered_edges = std::clamp(std::stoi(argv[i + 1]), 0, 2);
    else {
      std::fprintf(stderr, "bench_host_frame: unknown option %s\n", arg.c_str());
      return 2;
    }
  }
  std::printf("host work per frame at %dx%d, %u host threads, median of %d frames\n", width, height,
              HostThreads::shared().threads(), frames - 5);
  std::printf("%-8s %10s %10s %14s %12s %10s %13s %10s %15s %13s %13s %13s\n", "band", "bytes/px", "merge ms",
              "convergence ms", "tone map ms", "host ms", "reproject ms", "atrous ms", "+moments ms", "variance ms",
              "spatial ms", "+fix ms");
  nlohmann::json results = nlohmann::json::array();
  for (BandFormat format : {BandFormat::rgba32f, BandFormat::rgb16f, BandFormat::rgb9e5}) {
    const nlohmann::json r = run(format, width, height, frames);
    std::printf("%-8s %10zu %10.2f %14.2f %12.2f %10.2f %13.2f %10.2f %15.2f %13.2f %13.2f %13.2f\n", to_string(format),
                bytes_per_pixel(format), r["merge_ms"].get<double>(), r["convergence_ms"].get<double>(),
                r["tone_map_ms"].get<double>(), r["host_ms"].get<double>(), r["reproject_ms"].get<double>(),
                r["atrous_ms"].get<double>(), r["reproject_moments_ms"].get<double>(),
                r["atrous_variance_ms"].get<double>(), r["atrous_variance_spatial_ms"].get<double>(),
                r["atrous_variance_spatial_history_fix_ms"].get<double>());
    results.push_back(r);
  }
  const std::filesystem::path path(json_path);
  if (path.has_parent_path()) std::filesystem::create_directories(path.parent_path());
  std::ofstream(path) << nlohmann::json{{"width", width}, {"height", height}, {"host_threads", HostThreads::shared().threads()},
                                        {"results", results}}.dump(2)
                      << "\n";
  std::printf("wrote %s\n", json_path.c_str());
  return 0;
}
