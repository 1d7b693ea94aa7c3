#include "cohort/core/atrous_filter.h"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "cohort/core/host_threads.h"
#include "cohort/kernel/atrous.h"

namespace cohort::core {

namespace {

constexpr size_t kRowsPerTask = 8;
}  // namespace

int atrous_normal_squarings(int power) {
  int squarings = 0;
  while ((1 << squarings) < power && squarings < 30) ++squarings;
  if (power < 1 || (1 << squarings) != power)
    throw std::invalid_argument("AtrousFilter: the normal stop's power must be a power of two (1, 2, 4, ... 64), got " +
                                std::to_string(power));
  return squarings;
}


int atrous_passes_for_height(int height) {
  int passes = 1;
  for (int rows = 360; rows < height && passes < 5; rows *= 2) ++passes;
  return passes;
}

void AtrousFilter::apply(const FrameBuffer& frame, const GBuffer& gbuffer, FrameBuffer& out) {
  if (gbuffer.width != frame.width || gbuffer.height != frame.height)
    throw std::invalid_argument("AtrousFilter: the G-buffer's size differs from the frame's");
  const int width = frame.width, height = frame.height;
  const size_t pixels = static_cast<size_t>(width) * static_cast<size_t>(height);
  for (FrameBuffer* b : {&ping_, &pong_, &out})
    if (b->width != width || b->height != height) b->resize(width, height);
  HostThreads& threads = HostThreads::shared();
  threads.for_ranges(pixels, 16384, [&](size_t begin, size_t end) {
    for (size_t p = begin; p < end; ++p)
      k_atrous_modulate(frame.rgba.data(), gbuffer.albedo.data(), ping_.rgba.data(), static_cast<kint>(p), 0);
  });
  KAtrousParams params{};
  params.width = width;
  params.height = height;
  params.normal_squarings = atrous_normal_squarings(options_.normal_power);
  params.depth_sigma = options_.depth_sigma;
  params.color_sigma = options_.color_sigma;
  FrameBuffer* from = &ping_;
  FrameBuffer* to = &pong_;
  for (int pass = 0; pass < std::max(options_.passes, 0); ++pass) {
    params.step = 1 << pass;
    threads.for_ranges(static_cast<size_t>(height), kRowsPerTask, [&](size_t row_begin, size_t row_end) {
      for (int y = static_cast<int>(row_begin); y < static_cast<int>(row_end); ++y)
        for (int x = 0; x < width; ++x)
          k_atrous_pixel(from->rgba.data(), to->rgba.data(), gbuffer.depth.data(), gbuffer.normal.data(), &params, x, y);
    });
    std::swap(from, to);
  }
  threads.for_ranges(pixels, 16384, [&](size_t begin, size_t end) {
    for (size_t p = begin; p < end; ++p)
      k_atrous_modulate(from->rgba.data(), gbuffer.albedo.data(), out.rgba.data(), static_cast<kint>(p), 1);
  });
}

}  // namespace cohort::core
