// The real-time spatial denoiser (issue 17): the edge-aware a-trous filter of the portable kernel
// (kernel/atrous.h), run here over the merged frame on the host's threads. It filters illumination,
// not colour: the frame is divided by the G-buffer's albedo before the passes and multiplied back
// after, so textures stay sharp while the lighting's noise is smoothed (as SVGF does). Runs after the
// merge (and after temporal accumulation), so band boundaries cannot show.
// Luminance stops (AtrousGuide): `variance`, SVGF's (kernel/svgf.h): each pixel's luminance variance,
// from the reprojected history's temporal moments where it is at least `short_history` frames long and
// from its neighbourhood elsewhere, sets how far luminance may differ, and is filtered along with the
// colour; `variance_of_mean` (the default), the same over the history length: the noise the accumulated
// frame still has, so converged pixels are left alone; `fixed`, the relative difference of luminance with
// one scale everywhere (kernel/atrous.h).
#pragma once

#include <string>
#include <vector>

#include "cohort/core/frame_buffer.h"
#include "cohort/core/gbuffer.h"

struct KHistoryFixParams;  // kernel/svgf.h

namespace cohort::core {

// variance: SVGF's, the luminance variance of one frame's sample; variance_of_mean: that over the history
// length, the variance of the accumulated mean the filter sees (converged pixels are left alone).
enum class AtrousGuide { variance, variance_of_mean, fixed };

struct AtrousOptions {
  int passes = 1;             // steps 1, 2, 4, ...: 1 pass is a 5x5 filter, 4 a 61-pixel one
  int normal_power = 64;      // cosine exponent of the normal stop; a power of two (squared, not pow)
  float depth_sigma = 0.1f;   // relative depth difference per step of tap distance
  float color_sigma = 2.0f;   // fixed guide: relative luminance difference of the illumination
  AtrousGuide guide = AtrousGuide::variance_of_mean;  // measured best on the test map (docs/denoising.md)
  float variance_sigma = 4.0f;  // variance guide: luminance difference in standard deviations (SVGF's 4: against
                                // 1,024-spp references, better than 2 on every sequence measured, docs/denoising.md)
  // Variance guides: frames of history below which variance is estimated spatially (SVGF: 4). 2: on one H100
  // the 1080p post 0.1 ms cheaper (the 7x7 estimate was most of a frame's pixels, whose history averages
  // ~4 frames) for 1.5 % more mean FLIP at 720p (docs/denoising.md).
  float short_history = 2.0f;
  // History fix (kernel/svgf.h's k_svgf_history_fix_pixel, NRD's HistoryFix): before the passes, a pixel whose
  // reprojected history is shorter than this many frames gets an extra edge-aware blur, taps
  // `history_fix_stride` pixels apart at a one-frame history and closer as it grows; 0: off. Needs the history
  // (AtrousHistory::length). Off by default (docs/denoising.md): `--history-fix 6` brings the test map's door 4
  // frames after it stops to 0.098 at 320x180 (0.118 without; issue 17 asks <= 0.1) and the frame's mean FLIP
  // down 1.8-3.9 %, but at 640x360 no setting reaches 0.1 without the moving door's FLIP 12 % worse, the
  // camera path's mean FLIP gets 0.8-2.2 % worse at 192x108, and on an H100 it costs 0.33-0.35 ms at 1080p.
  float history_fix_frames = 0.0f;
  // 0: history_fix_stride_for_height (1 at 180 rows, 2 at 360, 4 at 720, 6 at 1080).
  float history_fix_stride = 0.0f;
  float history_fix_sigma_scale = 4.0f;  // the fix's luminance stop: the passes' sigma times this
  // Histories shorter than this are left to the passes (a length is the kept history plus the new frame: 1 is a
  // fresh sample, just above 1 one whose history the anti-lag nearly dropped). 1.5 spared the moving door at 320x180 (every figure better than without the fix) but cost the door after
  // it stops at 640x360 (0.1024 -> 0.1045) and the camera path (docs/denoising.md); 0: every short history.
  float history_fix_min_length = 0.0f;
  // Firefly clamp before the passes (kernel/firefly.h): a pixel brighter than this many times its brightest
  // neighbour is scaled down to that; 0: off. Off by default: 3 took the test map's door 4 frames after it
  // stops from 0.116 to 0.097 at 320x180, but at 640x360 it made it a little worse (0.111 -> 0.114), the mean
  // FLIP unchanged at both (docs/denoising.md, "Fireflies").
  float firefly_factor = 0.0f;
};

// "variance", "variance-of-mean" or "fixed" (std::invalid_argument otherwise, naming the word).
AtrousGuide parse_atrous_guide(const std::string& name);
const char* atrous_guide_name(AtrousGuide guide);
// Whether the guide reads a variance (and the history's luminance moments when reprojecting).
bool atrous_guide_uses_variance(AtrousGuide guide);

// The reprojected history: the variance guide reads its luminance moments (TemporalReprojection with
// luminance moments, two floats a pixel) and lengths, the history fix its lengths; null moments: the
// variance is estimated spatially; null length: no history (and no history fix).
struct AtrousHistory {
  const float* moments = nullptr;
  const float* length = nullptr;
};

// 1 pass up to 360 rows, 2 up to 540, 3 up to 1440 (720p and 1080p), one more per doubling beyond. Up to 360
// rows (the CPU's sizes) a second pass would cost the host more than issue 17's 20 ms at 640x360 allow and
// blurs lighting detail at 192x108; at 720p a third pass lowers the mean FLIP by 3.5-4 % (nvidia-h100-x1,
// scenario and spin-slow against 1,024-spp references) for about 0.1 ms; at 1080p a fourth would break the
// 1.5 ms budget (docs/denoising.md, "A third pass at 720p").
int atrous_passes_for_height(int height);

// The history fix's stride at a one-frame history for a frame of this height (history_fix_stride 0): one pixel
// per 180 rows, rounded. The door after it stops was best at stride 1 at 180 rows and 2-3 at 360 (its lip
// grows with the image); 720 and 1080 rows follow the rule unmeasured.
int history_fix_stride_for_height(int height);

// The history fix's parameters for a frame of this size (guided: the variance guide's planes, variance in alpha).
KHistoryFixParams history_fix_params(const AtrousOptions& options, int width, int height, bool guided);

// log2 of the normal stop's power, which must be a power of two (std::invalid_argument otherwise).
int atrous_normal_squarings(int power);

class AtrousFilter {
 public:
  explicit AtrousFilter(AtrousOptions options = {}) : options_(options) {}
  // `frame` and `gbuffer` have one size; `out` is resized to it. `history` (the same size) is read by the
  // variance guide only.
  void apply(const FrameBuffer& frame, const GBuffer& gbuffer, FrameBuffer& out, const AtrousHistory& history = {});
  // Variance guide: the illumination's luminance variance per pixel the first pass started from.
  const std::vector<float>& estimated_variance() const { return estimated_variance_; }
  const AtrousOptions& options() const { return options_; }

 private:
  AtrousOptions options_;
  FrameBuffer ping_, pong_;
  std::vector<float> estimated_variance_, geometry_;  // geometry: normal and depth packed (kernel/atrous.h)
};

}  // namespace cohort::core
