#include "cohort/core/frame_post.h"

#include <stdexcept>

namespace cohort::core {

void FramePost::process_packed(const BandBuffer& packed, const std::vector<DeviceBandRows>& on_device) {
  if (!on_device.empty())
    throw std::invalid_argument("FramePost::process_packed: bands on a GPU reached the post-processing on " + where());
  if (!packed.has_aux())
    throw std::invalid_argument("FramePost::process_packed: the packed frame has no aux planes (render with aux outputs)");
  const int width = packed.width(), height = packed.height();
  if (unpacked_frame_.width != width || unpacked_frame_.height != height) unpacked_frame_.resize(width, height);
  packed.copy_rows_to(unpacked_frame_, 0, height);
  if (unpacked_gbuffer_.width != width || unpacked_gbuffer_.height != height) unpacked_gbuffer_.resize(width, height);
  packed.copy_aux_rows_to(unpacked_gbuffer_, 0, height);
  process(unpacked_frame_, unpacked_gbuffer_);
}

FramePostOptions with_history_moments(FramePostOptions options) {
  options.reprojection.luminance_moments =
      options.reproject && options.atrous && atrous_guide_uses_variance(options.atrous_options.guide);
  return options;
}

HostFramePost::HostFramePost(FramePostOptions options)
    : options_(with_history_moments(options)), reprojection_(options_.reprojection), atrous_(options_.atrous_options) {}

void HostFramePost::process(const FrameBuffer& fresh, const GBuffer& gbuffer) {
  const FrameBuffer* current = &fresh;
  if (options_.reproject) {
    reprojection_.accumulate(fresh, gbuffer);
    current = &reprojection_.image();
  }
  if (options_.atrous) {
    AtrousHistory history;
    if (options_.reprojection.luminance_moments) {
      history.moments = reprojection_.luminance_moments().data();
      history.length = reprojection_.history_length().data();
    }
    atrous_.apply(*current, gbuffer, filtered_, history);
    current = &filtered_;
  }
  if (current == &fresh) {  // neither step: keep a copy, the caller's frame may change under us
    copy_ = fresh;
    current = &copy_;
  }
  shown_ = current;
}

double HostFramePost::mean_history_length() const {
  return options_.reproject ? reprojection_.mean_history_length() : 1.0;
}

void HostFramePost::reset() { reprojection_.reset(); }

}  // namespace cohort::core
