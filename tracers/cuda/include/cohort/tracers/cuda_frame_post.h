// The frame's post-processing (core/frame_post.h: reprojection, then the a-trous filter) on an NVIDIA
// GPU, with the portable kernel's per-pixel code (kernel/reproject.h, kernel/atrous.h) compiled as CUDA.
// The history stays on the device; each frame uploads the merged frame and its G-buffer planes and
// downloads the shown image, from page-locked host memory where it can register it.
#pragma once

#include <memory>

#include "cohort/core/frame_post.h"

namespace cohort::tracers {

// Throws std::runtime_error naming the device when it cannot be used.
std::unique_ptr<core::FramePost> make_cuda_frame_post(int device, const core::FramePostOptions& options);

}  // namespace cohort::tracers
