// Dynamic resolution (docs/denoising.md, "Dynamic resolution"): a render scale below 1 traces paths at
// only some pixels (kernel/path_pattern.h) while every pixel keeps its G-buffer, and the portable
// reconstruction (kernel/upsample.h) fills the frame with joint-bilateral weights from that full-resolution
// guide, here on the host's threads. The bilinear stretch of a frame rendered at the lower size (what a
// GPU's GL_LINEAR does) is kept as the baseline the reconstruction is measured against.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "cohort/core/frame_buffer.h"
#include "cohort/core/gbuffer.h"

namespace cohort::core {

// joint_bilateral and nearest reconstruct a sparse frame at the output size (nearest: the nearest traced
// pixel, no guide); bilinear renders a frame of scale * width x scale * height and stretches it.
enum class UpsampleMethod { joint_bilateral, nearest, bilinear };

// "joint-bilateral", "nearest" or "bilinear" (std::invalid_argument otherwise, naming the word).
UpsampleMethod parse_upsample_method(const std::string& name);
const char* upsample_method_name(UpsampleMethod method);

// Which pixels of a frame trace paths (KFrameParams.path_pixels and path_phase; 0 pixels: all).
struct PathPattern {
  uint32_t pixels = 0;  // of each 4x4 block
  uint32_t phase = 0;
  bool sparse() const { return pixels != 0 && pixels < 16; }
};
inline constexpr PathPattern kEveryPixel{};

// The pattern for a render scale (traces about scale^2 of the pixels, at least 1 of 16) at frame
// `frame`: the phase advances by `pixels` a frame, so consecutive frames trace different pixels.
PathPattern path_pattern_for_scale(double scale, uint64_t frame);
// The render scale a pattern stands for: sqrt(pixels / 16).
double path_pattern_scale(const PathPattern& pattern);

// Fills `out` (resized to the frame's size) from the pattern's traced pixels of `sparse` guided by
// `gbuffer` (same size; std::invalid_argument otherwise), on the host's threads. method: joint_bilateral
// or nearest. Keeps its scratch plane (the traced pixels' illumination) between frames.
class SparseUpsampler {
 public:
  void upsample(const FrameBuffer& sparse, const GBuffer& gbuffer, PathPattern pattern, UpsampleMethod method,
                FrameBuffer& out);

 private:
  std::vector<float> illumination_;
};

// The same with a scratch plane of its own (tests, one-off frames).
void upsample_sparse(const FrameBuffer& sparse, const GBuffer& gbuffer, PathPattern pattern, UpsampleMethod method,
                     FrameBuffer& out);

// `low` stretched to width x height with bilinear filtering between pixel centres, edges clamped (as
// OpenGL's GL_LINEAR with GL_CLAMP_TO_EDGE).
void stretch_bilinear(const FrameBuffer& low, int width, int height, FrameBuffer& out);

}  // namespace cohort::core
