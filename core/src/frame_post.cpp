#include "cohort/core/frame_post.h"

namespace cohort::core {

HostFramePost::HostFramePost(FramePostOptions options)
    : options_(options), reprojection_(options.reprojection), atrous_(options.atrous_options) {}

void HostFramePost::process(const FrameBuffer& fresh, const GBuffer& gbuffer) {
  const FrameBuffer* current = &fresh;
  if (options_.reproject) {
    reprojection_.accumulate(fresh, gbuffer);
    current = &reprojection_.image();
  }
  if (options_.atrous) {
    atrous_.apply(*current, gbuffer, filtered_);
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
