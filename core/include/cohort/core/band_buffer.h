// What a tracer renders its band into: a frame-sized target in the format the frame's consumer takes.
// RGB16F (half floats, 6 bytes a pixel) keeps an 11-bit mantissa over the whole HDR range (to 65504),
// finer than the noise of a frame and than what the tone mapper shows, and moves 2.7 times fewer bytes
// than RGBA32F through device transfers and the merge, which converts it to the float frame. RGBA32F
// keeps values exact (tests that read them back). RGB9E5 (4 bytes a pixel, kernel/band_pack.h: 9-bit
// mantissas under a shared exponent, rounded stochastically so that averaging frames keeps no bias)
// moves a third fewer bytes than RGB16F, for links where the bytes are the cost (remote nodes, a slow bus). Rows are contiguous, top to bottom, so a band is
// one block of memory that a GPU tracer copies straight into place.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "cohort/core/frame_buffer.h"
#include "cohort/core/gbuffer.h"
#include "cohort/kernel/layout.h"

namespace cohort::core {

enum class BandFormat { rgba32f, rgb16f, rgb9e5 };

// A band a GPU tracer left in its device memory instead of copying it into its target
// (BandJob::keep_on_device): its rows as the target would hold them (the target's format, row_begin
// first) and its aux texels. Valid until that tracer's next job but one that keeps its band (it
// alternates two buffers, as the Renderer alternates targets by frame parity).
struct DeviceBand {
  int cuda_device = -1;            // -1: none, the rows are in the target
  const void* colour = nullptr;
  const KAuxTexel* aux = nullptr;  // null when the frame has no aux outputs
};

// Rows [row_begin, row_end) of a packed frame that lie on a GPU (Renderer::packed_device_rows).
struct DeviceBandRows {
  int row_begin = 0, row_end = 0;
  DeviceBand band;
};
const char* to_string(BandFormat format);
// The format named `name` ("rgba32f", "rgb16f", "rgb9e5"); throws std::invalid_argument naming the choices.
BandFormat band_format_from_string(const std::string& name);
size_t bytes_per_pixel(BandFormat format);
// Bulk conversions between RGBA floats and RGB9E5 words (kernel/band_pack.h; alpha dropped, read back as
// 1): pixel i's dither from (first_pixel + i, frame), first_pixel counted over the whole frame.
void rgba32f_to_rgb9e5(const float* rgba, uint32_t* packed, size_t pixels, uint32_t first_pixel, uint32_t frame);
void rgb9e5_to_rgba32f(const uint32_t* packed, float* rgba, size_t pixels);

class BandBuffer {
 public:
  BandBuffer() = default;
  BandBuffer(int width, int height, BandFormat format) { resize(width, height, format); }
  // Keeps the storage when nothing changes; otherwise reallocates and clears.
  void resize(int width, int height, BandFormat format);

  int width() const { return width_; }
  int height() const { return height_; }
  BandFormat format() const { return format_; }
  size_t row_bytes() const { return static_cast<size_t>(width_) * bytes_per_pixel(format_); }
  // Row y's bytes in the buffer's format: width RGBA floats, RGB halves or RGB9E5 words.
  void* row(int y) { return storage_.data() + static_cast<size_t>(y) * row_bytes(); }
  const void* row(int y) const { return storage_.data() + static_cast<size_t>(y) * row_bytes(); }
  void* data() { return storage_.data(); }
  size_t bytes() const { return storage_.size(); }

  // Writes `pixels` RGBA float pixels at (x, y) onwards, converted to the buffer's format. `frame` seeds
  // RGB9E5's dither (the frame's index, so that successive frames round each pixel independently).
  void store(int y, int x, const float* rgba, size_t pixels, uint32_t frame = 0);
  // Reads rows [row_begin, row_end) into the same rows of `out` (which must have this size) as RGBA floats.
  void copy_rows_to(FrameBuffer& out, int row_begin, int row_end) const;
  // Copies rows [row_begin, row_end) of `from` (same size and format) into the same rows here as they are,
  // aux texels too where both have them: a packed merge, no conversion.
  void copy_rows_from(const BandBuffer& from, int row_begin, int row_end);

  // Auxiliary planes (kernel/aux_outputs.h), kept only for frames that ask for them: 32 bytes a pixel
  // (KAuxTexel: depths, motion and id as 32-bit values, normal and albedo as half floats). Off frees them.
  void enable_aux(bool on);
  bool has_aux() const { return !aux_.empty(); }
  // Writes `pixels` aux records at (x, y) onwards.
  void store_aux(int y, int x, const KAux* aux, size_t pixels);
  // Row y's packed aux texels (a GPU tracer copies its band's straight into place), and the whole block.
  KAuxTexel* aux_row(int y) { return aux_.data() + static_cast<size_t>(y) * static_cast<size_t>(width_); }
  void* aux_data() { return aux_.data(); }
  size_t aux_bytes() const { return aux_.size() * sizeof(KAuxTexel); }
  // Reads rows [row_begin, row_end) into the same rows of `out` (which must have this size).
  void copy_aux_rows_to(GBuffer& out, int row_begin, int row_end) const;

 private:
  int width_ = 0, height_ = 0;
  BandFormat format_ = BandFormat::rgba32f;
  std::vector<unsigned char> storage_;
  using AuxTexel = KAuxTexel;
  std::vector<AuxTexel> aux_;
};

}  // namespace cohort::core
