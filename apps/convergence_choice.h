// `--convergence auto`: which accumulation a run uses when the user did not say.
//
// Reprojection looks far better in motion (docs/denoising.md) but runs on the host: on nvidia-h100-x1
// (16 cores) it costs 31 ms a frame at 1920x1080 and 12 ms at 1280x720, plus the tracers' auxiliary
// planes, against a GPU frame of 5-17 ms, so with a GPU tracer it would set the frame rate (measured:
// 49.9 against 16.7 ms per frame on the large map, 22.0 against 4.8 ms on the test map;
// docs/denoising.md, "Cost on the GPU machine"). CPU tracers take far longer per frame than the
// reprojection, so there it is nearly free.
#pragma once

#include <string>

namespace cohort::app {

// "reproject" or "brigade" for a requested mode of auto, reproject or brigade.
inline std::string resolve_convergence(const std::string& requested, bool any_gpu_tracer) {
  if (requested != "auto") return requested;
  return any_gpu_tracer ? "brigade" : "reproject";
}

}  // namespace cohort::app
