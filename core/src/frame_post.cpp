#include "cohort/core/frame_post.h"

#include <stdexcept>
#include <string>

namespace cohort::core {

void FramePost::process_packed(const BandBuffer& packed, const std::vector<DeviceBandRows>& on_device,
                               const PathPattern& traced) {
  if (!on_device.empty())
    throw std::invalid_argument("FramePost::process_packed: bands on a GPU reached the post-processing on " + where());
  const int width = packed.width(), height = packed.height();
  if (unpacked_frame_.width != width || unpacked_frame_.height != height) unpacked_frame_.resize(width, height);
  packed.copy_rows_to(unpacked_frame_, 0, height);
  if (packed.has_aux()) {
    if (unpacked_gbuffer_.width != width || unpacked_gbuffer_.height != height) unpacked_gbuffer_.resize(width, height);
    packed.copy_aux_rows_to(unpacked_gbuffer_, 0, height);
  } else {
    unpacked_gbuffer_ = GBuffer{};  // the blend alone reads none; the other steps refuse an empty one
  }
  process(unpacked_frame_, unpacked_gbuffer_, traced);
}

FramePostOptions with_history_moments(FramePostOptions options) {
  options.reprojection.luminance_moments =
      options.reproject && options.atrous && atrous_guide_uses_variance(options.atrous_options.guide);
  return options;
}

void check_post_options(const FramePostOptions& options) {
  if (options.blend && (options.reproject || options.atrous))
    throw std::invalid_argument("frame post: Brigade's blend takes the place of the reprojection and comes without "
                                "the a-trous filter; ask for one of them");
}

void check_traced_pattern(const FramePostOptions& options, const PathPattern& traced) {
  if (traced.sparse() && options.atrous && !options.reproject)
    throw std::invalid_argument("frame post: a sparse frame (" + std::to_string(traced.pixels) +
                                " of 16 pixels traced) reached a filter without history, which takes blended frames; "
                                "reconstruct it first");
  if (traced.sparse() && options.upsample == UpsampleMethod::bilinear)
    throw std::invalid_argument("frame post: bilinear upsampling stretches a small frame, not a sparse one");
}

HostFramePost::HostFramePost(FramePostOptions options)
    : options_(with_history_moments(options)), reprojection_(options_.reprojection), atrous_(options_.atrous_options) {
  check_post_options(options_);
}

void HostFramePost::process(const FrameBuffer& fresh, const GBuffer& gbuffer, const PathPattern& traced) {
  check_traced_pattern(options_, traced);
  const FrameBuffer* current = &fresh;
  if (traced.sparse()) {
    upsampler_.upsample(fresh, gbuffer, traced, options_.upsample, reconstructed_);
    current = &reconstructed_;
  }
  if (options_.reproject) {
    reprojection_.accumulate(*current, gbuffer);
    current = &reprojection_.image();
  }
  if (options_.blend) {
    blended_.blend(*current, blend_factor_);
    current = &blended_.image();
  }
  if (options_.atrous) {
    AtrousHistory history;
    if (options_.reproject) history.length = reprojection_.history_length().data();
    if (options_.reprojection.luminance_moments) history.moments = reprojection_.luminance_moments().data();
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

void HostFramePost::reset() {
  reprojection_.reset();
  blended_ = AdaptiveConvergence{};  // its image too: the next frame starts it over
}

}  // namespace cohort::core
