// A frame's auxiliary planes (kernel/aux_outputs.h) after the merge, one float plane per quantity, for
// the reprojection (core/reprojection.h) and the denoiser's guides. Empty unless the frame asked for
// them (KFrameParams::aux_outputs).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>


namespace cohort::core {

struct GBuffer {
  int width = 0, height = 0;
  std::vector<float> depth;       // view depth of the first opaque hit; 0 on a miss
  std::vector<float> prev_depth;  // the same point's depth in the previous frame's camera
  std::vector<float> motion;      // 2 per pixel: offset in pixels to the point's previous position
  std::vector<float> normal;      // 3 per pixel, world space
  std::vector<float> albedo;      // 3 per pixel, [0, 1]
  std::vector<uint32_t> id;       // entity + 1 (0: world), K_NONE on a miss

  size_t pixels() const { return static_cast<size_t>(width) * static_cast<size_t>(height); }
  bool empty() const { return pixels() == 0; }
  void resize(int w, int h) {
    width = w;
    height = h;
    const size_t n = pixels();
    depth.assign(n, 0.0f);
    prev_depth.assign(n, 0.0f);
    motion.assign(2 * n, 0.0f);
    normal.assign(3 * n, 0.0f);
    albedo.assign(3 * n, 0.0f);
    id.assign(n, 0xFFFFFFFFu);
  }
  void clear() { resize(0, 0); }
};

}  // namespace cohort::core
