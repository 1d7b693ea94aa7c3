// `--convergence auto`: which accumulation a run uses when the user did not say.
//
// Reprojection looks far better in motion (docs/denoising.md). Its per-pixel work runs where the frame's
// post-processing runs (core/frame_post.h): on the host it costs 18-31 ms a frame at 1920x1080 on
// nvidia-h100-x1's 16 cores, longer than a GPU's frame (22.5 against 13.7 ms per frame with Brigade's
// blend on the large map); on the GPU it is hidden behind the next frame's render (16.4 ms per frame,
// the tracer's auxiliary planes being the difference; docs/denoising.md, "Cost on the GPU machine").
// So: reproject when only CPU tracers render (their frame is far longer than the host's reprojection)
// or when the post-processing runs on a GPU; Brigade's blend when GPU tracers would wait for the host.
#pragma once

#include <string>

namespace cohort::app {

// "reproject" or "brigade" for a requested mode of auto, reproject or brigade; `post_place` is where the
// frame's post-processing runs ("host", "cuda:N").
inline std::string resolve_convergence(const std::string& requested, bool any_gpu_tracer, const std::string& post_place) {
  if (requested != "auto") return requested;
  return !any_gpu_tracer || post_place != "host" ? "reproject" : "brigade";
}

}  // namespace cohort::app
