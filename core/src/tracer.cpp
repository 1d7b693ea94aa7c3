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

BandResult Tracer::render_band_in_pieces(const BandJob& job, BandBuffer& target, const std::vector<int>& cuts,
                                         const std::function<void(size_t)>& ready) {
  BandResult total;
  bool complete_work = true;
  for (size_t i = 0; i + 1 < cuts.size(); ++i) {
    if (cuts[i + 1] <= cuts[i]) {  // an empty piece has nothing to render
      ready(i);
      continue;
    }
    BandJob piece = job;
    piece.keep_on_device = -1;
    piece.params.row_begin = static_cast<kuint>(cuts[i]);
    piece.params.row_end = static_cast<kuint>(cuts[i + 1]);
    BandResult part = render_band(piece, target);
    total.device_ms += part.device_ms;
    complete_work = complete_work && part.row_work.size() == static_cast<size_t>(cuts[i + 1] - cuts[i]);
    if (complete_work) total.row_work.insert(total.row_work.end(), part.row_work.begin(), part.row_work.end());
    ready(i);
  }
  if (!complete_work) total.row_work.clear();
  return total;
}

}  // namespace cohort::core
