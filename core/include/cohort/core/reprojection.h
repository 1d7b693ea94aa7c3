// Temporal accumulation with reprojection (issue 17), the per-pixel successor of Brigade's whole-frame
// blend (core/convergence.h). Each pixel keeps its own history and history length. A new frame's pixel
// finds its history where its surface was in the previous frame (the motion vectors of the frame's
// G-buffer, kernel/aux_outputs.h), fetched bilinearly from the four history pixels around that point;
// a tap counts only if it saw the same object (id), at the depth the point had then (prev_depth, within
// depth_tolerance) and with a similar normal, so surfaces a moving object uncovers start afresh
// (disocclusion). Where the pixel moved, the history is clamped to the fresh frame's 3x3 neighbourhood
// box in YCoCg (mean +- clamp_sigma standard deviations), which bounds the ghosting of lighting that
// reprojection cannot follow; a pixel that did not move keeps its history untouched, so a still view
// is exactly the running average of its frames (up to max_history). Where the pixel moved, an anti-lag
// also shortens the history when the 5x5 mean luma around the reprojected point has drifted from the
// fresh frame's by more than that mean's noise explains (stale lighting the 1-spp clamp box is too wide
// to catch). Blend: C = H + (S - H) / n, n the
// history length (capped at max_history). Samples that are not finite (NaN, Inf) never enter the
// history: the pixel keeps its history (or shows its neighbourhood's mean when it has none).
// With jittered_planes (a G-buffer from each pixel's jittered sample, whose surface flips frame to frame at
// silhouettes), a tap of another surface also counts where that surface is still in the pixel's 3x3
// neighbourhood, moved with it, and the pixel's own surface has under half the bilinear weight.
// With luminance_moments, the history also keeps the first and second moments of the illumination's
// luminance (colour over albedo), blended like the colour, for the a-trous filter's variance guide.
// The per-pixel arithmetic is the portable kernel's (kernel/reproject.h); this class runs it on the host's
// threads and keeps the history.
#pragma once

#include <cstdint>
#include <vector>

#include "cohort/core/frame_buffer.h"
#include "cohort/core/gbuffer.h"
#include "cohort/kernel/reproject.h"

namespace cohort::core {

struct ReprojectionOptions {
  int max_history = 64;           // frames; 1/max_history is the least blend weight of a new frame
  float depth_tolerance = 0.05f;  // relative depth difference above which a history tap is another surface
  float normal_cos = 0.8f;        // least cosine between the normals of a pixel and its history tap
  // Neighbourhood box half-width in standard deviations (moving pixels). Wide, since the anti-lag below
  // catches stale lighting: where a pixel's 3x3 fresh samples all missed its rare bright paths (skewed
  // 1-spp noise) a narrow box pulls the history below its mean, and the frame loses light (1.5: 2.8 %
  // darker than the reference, 6: 1.7 %, and lower FLIP on the scenario and spin-slow at 720p and
  // 320x180; docs/denoising.md, "The clamp's width").
  float clamp_sigma = 6.0f;
  float still_motion = 0.01f;     // pixels: motion below this counts as no motion (no clamp)
  // Moving pixels: history whose 5x5 mean luma is off the fresh frame's by more than anti_lag_sigma
  // standard errors of that mean (plus anti_lag_relative of it) is shortened in proportion (kernel/reproject.h's
  // k_reproject_anti_lag); 0 turns it off.
  float anti_lag_sigma = 0.75f;
  float anti_lag_relative = 0.0f;
  bool luminance_moments = false; // also keep M1, M2 of the illumination's luminance (SVGF's variance)
  // The G-buffer comes from each pixel's jittered sample (--aux-rays first-hit): at a silhouette, history
  // taps of the other surface the pixel covers count too (kernel/reproject.h's k_reproject_footprint_tap).
  bool jittered_planes = false;
};

// The portable kernel's parameters (kernel/reproject.h) for a width x height frame, from the options:
// one translation for the host's reprojection and the GPU post-processing's.
KReprojectParams reproject_params(const ReprojectionOptions& options, int width, int height, bool have_history);

class TemporalReprojection {
 public:
  explicit TemporalReprojection(ReprojectionOptions options = {}) : options_(options) {}

  // Blends `fresh` (the merged frame) into the history through `gbuffer` (the same frame's auxiliary
  // planes, same size). A size change restarts the history.
  void accumulate(const FrameBuffer& fresh, const GBuffer& gbuffer);
  const FrameBuffer& image() const { return image_; }
  // Per pixel, the number of frames its colour is worth.
  const std::vector<float>& history_length() const { return length_; }
  // Per pixel, the illumination luminance's first and second moments (M1, M2), with luminance_moments.
  const std::vector<float>& luminance_moments() const { return moments_; }
  const ReprojectionOptions& options() const { return options_; }
  // Mean history length over the frame (a scalar for stats: 1 = nothing reused).
  double mean_history_length() const;
  void reset();

 private:
  ReprojectionOptions options_;
  FrameBuffer image_, next_image_;
  std::vector<float> length_, next_length_;
  std::vector<float> moments_, next_moments_;
  // The previous frame's surfaces, to test history taps against.
  std::vector<float> depth_, normal_, next_depth_, next_normal_;
  std::vector<uint32_t> id_, next_id_;
  // The fresh frame in YCoCg, w = 1 where its sample is finite (scratch; kernel/reproject.h).
  std::vector<float> ycocgw_;
};

}  // namespace cohort::core
