// The real-time spatial denoiser (issue 17): the edge-aware a-trous filter of the portable kernel
// (kernel/atrous.h), run here over the merged frame on the host's threads. It filters illumination,
// not colour: the frame is divided by the G-buffer's albedo before the passes and multiplied back
// after, so textures stay sharp while the lighting's noise is smoothed (as SVGF does). Runs after the
// merge (and after temporal accumulation), so band boundaries cannot show.
#pragma once

#include "cohort/core/frame_buffer.h"
#include "cohort/core/gbuffer.h"

namespace cohort::core {

struct AtrousOptions {
  int passes = 1;             // steps 1, 2, 4, ...: 1 pass is a 5x5 filter, 4 a 61-pixel one
  int normal_power = 64;      // cosine exponent of the normal stop; a power of two (squared, not pow)
  float depth_sigma = 0.1f;   // relative depth difference per step of tap distance
  float color_sigma = 2.0f;   // relative luminance difference of the illumination
};

// Passes whose footprint is about the same share of the image at any size: 1 up to 360 rows, one more
// per doubling (3 at 1080). Measured on the test map at 192x108 (docs/denoising.md): more passes than
// that blur lighting detail that FLIP sees, and reprojected frames need little spatial help.
int atrous_passes_for_height(int height);

// log2 of the normal stop's power, which must be a power of two (std::invalid_argument otherwise).
int atrous_normal_squarings(int power);

class AtrousFilter {
 public:
  explicit AtrousFilter(AtrousOptions options = {}) : options_(options) {}
  // `frame` and `gbuffer` have one size; `out` is resized to it.
  void apply(const FrameBuffer& frame, const GBuffer& gbuffer, FrameBuffer& out);

 private:
  AtrousOptions options_;
  FrameBuffer ping_, pong_;
};

}  // namespace cohort::core
