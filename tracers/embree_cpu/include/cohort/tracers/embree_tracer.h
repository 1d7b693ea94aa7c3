// The CPU tracer: Embree 3 two-level scene (one geometry per BLAS, one instance per KInstance) and the
// shared integrator (kernel/include/cohort/kernel/integrator.h), multithreaded over the rows of its band.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "cohort/tracers/tracer_base.h"

namespace cohort::tracers {

class EmbreeTracer : public TracerBase {
 public:
  explicit EmbreeTracer(int threads = 0);  // 0: all hardware threads
  ~EmbreeTracer() override;
  EmbreeTracer(const EmbreeTracer&) = delete;
  EmbreeTracer& operator=(const EmbreeTracer&) = delete;

  std::string name() const override { return "embree"; }
  using core::Tracer::render_band;
  core::BandResult render_band(const core::BandJob& job, core::BandBuffer& target) override;

  // Raw closest-hit throughput: traces exactly the band's camera rays (same jitter as the integrator,
  // params.spp per pixel) with rtcIntersect1 and nothing else. Returns the number of rays that hit.
  uint64_t trace_camera_rays_only(const core::BandJob& job);
  // Camera, bounce and shadow rays traced by render_band since construction.
  uint64_t rays_traced() const;

 private:
  void upload(const commit::ChangeSet& changes) override;

  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace cohort::tracers
