// Writing frames. With OpenImageIO: any format it knows by extension (.png, .exr, .jpg, .tif, ...).
// Without it (the build that travels to the GPU machine): .ppm (8-bit) and .pfm (float HDR) only,
// which any image tool converts on a machine that has one (e.g. `oiiotool frame.pfm -o frame.exr`).
#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

#include "cohort/core/frame_buffer.h"

namespace cohort::core {

// RGBA8, rows top to bottom. Throws std::runtime_error naming the file on failure.
void write_ldr_image(const std::filesystem::path& file, int width, int height, const std::vector<uint8_t>& rgba);
// Linear HDR RGB(A) float. Throws std::runtime_error naming the file on failure.
void write_hdr_image(const std::filesystem::path& file, const FrameBuffer& frame);
// Reads a .pfm written by write_hdr_image (for tests and the GPU machine's results).
FrameBuffer read_pfm(const std::filesystem::path& file);
bool have_image_library();

}  // namespace cohort::core
