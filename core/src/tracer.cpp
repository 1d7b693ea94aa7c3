#include "cohort/core/tracer.h"

#include <algorithm>

namespace cohort::core {

BandResult Tracer::render_band(const BandJob& job, FrameBuffer& target) {
  const int width = static_cast<int>(job.camera.width), height = static_cast<int>(job.camera.height);
  if (target.width != width || target.height != height) target.resize(width, height);
  BandBuffer band(width, height, BandFormat::rgba32f);
  BandResult result = render_band(job, band);
  const int begin = std::clamp(static_cast<int>(job.params.row_begin), 0, height);
  const int end = std::clamp(static_cast<int>(job.params.row_end), begin, height);
  band.copy_rows_to(target, begin, end);
  return result;
}

}  // namespace cohort::core
