// What happens to a merged frame before it is shown: dynamic resolution's reconstruction of a sparse frame
// (core/upsample.h), temporal reprojection (core/reprojection.h) and the a-trous spatial filter
// (core/atrous_filter.h), on the host's threads or on a GPU (tracers/cuda's CudaFramePost, made by name in
// tracers/registry). Both run the portable kernel's per-pixel code (kernel/upsample.h, kernel/reproject.h,
// kernel/atrous.h), so where they run changes the cost, not the picture.
#pragma once

#include <memory>
#include <string>

#include "cohort/core/atrous_filter.h"
#include "cohort/core/band_buffer.h"
#include "cohort/core/convergence.h"
#include "cohort/core/frame_buffer.h"
#include "cohort/core/gbuffer.h"
#include "cohort/core/reprojection.h"
#include "cohort/core/upsample.h"

namespace cohort::core {

struct FramePostOptions {
  bool reproject = true;  // false: the fresh frame goes straight to the filter (or is shown as it is)
  ReprojectionOptions reprojection;
  bool atrous = false;
  AtrousOptions atrous_options;
  // How a sparse frame (a render scale below 1) is filled before the reprojection: joint_bilateral or nearest.
  UpsampleMethod upsample = UpsampleMethod::joint_bilateral;
  // Brigade's blend of whole frames (core/convergence.h) instead of the reprojection, with the factor the
  // caller sets each frame (FramePost::set_blend_factor): where the post runs on a GPU, the bands then need
  // not be merged nor blended on the host. Not with reproject or atrous.
  bool blend = false;
};

// The options with the reprojection's luminance moments switched on exactly when the variance-guided
// a-trous filter reads them (every place calls this, so they agree).
FramePostOptions with_history_moments(FramePostOptions options);

// Throws std::invalid_argument unless a post with these options can take frames traced as `traced`: a
// filter without reprojection takes blended frames, so it refuses sparse ones.
void check_traced_pattern(const FramePostOptions& options, const PathPattern& traced);

// Throws std::invalid_argument for options no post takes (the blend with the reprojection or the filter).
void check_post_options(const FramePostOptions& options);

// A GPU place's own clock for the last frame (CUDA events), to tell the bus from the passes.
struct FramePostDeviceTimes {
  bool measured = false;  // false on the host
  double upload_ms = 0.0, passes_ms = 0.0, download_ms = 0.0;
};

class FramePost {
 public:
  virtual ~FramePost() = default;
  // Takes the merged frame and its G-buffer (same size); a size change restarts the history. `traced`: the
  // pixels that traced paths (kEveryPixel, or dynamic resolution's sparse pattern, which the post
  // reconstructs from the G-buffer first, where it runs). A post with neither step only reconstructs.
  virtual void process(const FrameBuffer& fresh, const GBuffer& gbuffer, const PathPattern& traced) = 0;
  // The same from the Renderer's packed merge (Renderer::set_packed_merge): the frame in its band format
  // with its aux texels. Here: unpacked on the host, then process(); a GPU place unpacks on the device.
  // `on_device` lists rows that GPU tracers left on their devices (Renderer::packed_device_rows): their
  // rows in `packed` are stale. Only a place on a CUDA device (cuda_device() >= 0) takes them.
  virtual void process_packed(const BandBuffer& packed, const std::vector<DeviceBandRows>& on_device,
                              const PathPattern& traced);
  // The CUDA device the passes run on, -1 on the host.
  virtual int cuda_device() const { return -1; }
  // The frame to show: reprojected, then filtered, as the options ask.
  virtual const FrameBuffer& image() const = 0;
  // Mean history length over the frame (1 = nothing reused; 1 when not reprojecting).
  virtual double mean_history_length() const = 0;
  virtual void reset() = 0;
  // Where it runs, for logs and stats: "host", "cuda:0".
  virtual std::string where() const = 0;
  virtual FramePostDeviceTimes device_times() const { return {}; }
  // The blend's factor for the next frame (options.blend): f from AdaptiveConvergence::next_factor; 1 (or
  // more) starts the accumulation over from that frame.
  void set_blend_factor(double f) { blend_factor_ = f; }

 protected:
  double blend_factor_ = 1.0;

 private:
  FrameBuffer unpacked_frame_;
  GBuffer unpacked_gbuffer_;
};

class HostFramePost final : public FramePost {
 public:
  explicit HostFramePost(FramePostOptions options);
  void process(const FrameBuffer& fresh, const GBuffer& gbuffer, const PathPattern& traced) override;
  const FrameBuffer& image() const override { return *shown_; }
  double mean_history_length() const override;
  void reset() override;
  std::string where() const override { return "host"; }

 private:
  FramePostOptions options_;
  TemporalReprojection reprojection_;
  AtrousFilter atrous_;
  SparseUpsampler upsampler_;
  FrameBuffer reconstructed_, filtered_, copy_;
  AdaptiveConvergence blended_;  // Brigade's blend, with the factor the caller sets
  const FrameBuffer* shown_ = &copy_;
};

}  // namespace cohort::core
