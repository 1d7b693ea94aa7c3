// The CPU tracer: Embree 3 two-level scene (one geometry per BLAS, one instance per KInstance) and the
// shared integrator (kernel/include/cohort/kernel/integrator.h), over tiles of its band spread across
// the cores by TBB. Each tile traces its camera rays ahead in coherent packets; the paths then go on
// from those hits as a wavefront, their shadow and bounce rays in packets too (or path by path).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "cohort/tracers/tracer_base.h"

namespace cohort::tracers {

// A ray as the integrator asked for it (origin, direction, tmax, K_RAY_* mask), for the benchmarks.
struct EmbreeRay {
  float org[3];
  float dir[3];
  float tmax;
  uint32_t mask;
};

// The rays of one render_band by class. camera: camera rays and their continuations through
// transparent layers; bounce: every other closest-hit ray; shadow: occlusion rays.
struct EmbreeRaySet {
  std::vector<EmbreeRay> camera, shadow, bounce;
};

// How trace_raw hands rays to Embree: rtcIntersect1/rtcOccluded1 one by one, rtcIntersect8/rtcOccluded8
// on consecutive groups of 8, or rtcIntersect1M/rtcOccluded1M on consecutive streams of 256.
enum class EmbreeRayApi { single, packet8, stream };

class EmbreeTracer : public TracerBase {
 public:
  explicit EmbreeTracer(int threads = 0);  // 0: all hardware threads
  ~EmbreeTracer() override;
  EmbreeTracer(const EmbreeTracer&) = delete;
  EmbreeTracer& operator=(const EmbreeTracer&) = delete;

  std::string name() const override { return "embree"; }
  using core::Tracer::render_band;
  core::BandResult render_band(const core::BandJob& job, core::BandBuffer& target) override;

  // Renders the band once on the calling thread (no image) and returns every ray the integrator traced.
  EmbreeRaySet record_rays(const core::BandJob& job);
  // Traces the rays on the applied scene with the same filter functions as the integrator, nothing
  // else: closest hits (occlusion = false) or occlusion. coherent sets RTC_INTERSECT_CONTEXT_FLAG_COHERENT.
  // Returns how many hit (or were occluded).
  uint64_t trace_raw(const std::vector<EmbreeRay>& rays, bool occlusion, EmbreeRayApi api, bool coherent);
  // Which build of the shading code runs: the one for x86-64-v3 (AVX2, FMA) where the CPU has it, the
  // default, or the baseline x86-64 one. Returns whether the x86-64-v3 build is now in use.
  bool prefer_x86_64_v3(bool prefer);
  // How tiles are rendered (embree_tiles.h): as wavefronts, shadow and bounce rays in packets (on, the
  // default, unless COHORT_EMBREE_WAVEFRONT=0), or path by path, those rays one by one. Same image.
  void set_wavefront(bool on);
  bool wavefront() const;
  // The wavefront's rays per packet, 8 or 16: by default 16 where Embree traces 16-ray packets natively
  // (AVX-512), else 8. Same image either way.
  void set_wave_packet_width(int rays);
  int wave_packet_width() const;
  // A BLAS whose own materials let rays pass (alpha tests, pass-through, noShadows, ...) on some of its
  // triangles only is two Embree geometries, and only the second has the filter function, so that hits on
  // the rest end Embree's search without calling back (on unless COHORT_EMBREE_SPLIT_FILTERS=0; where the
  // device has ray masks, and not for skinned BLASes or BLASes an instance overrides with such a material).
  // Same image. Switching rebuilds the applied scene's BLASes.
  void set_split_filters(bool on);
  bool split_filters() const;
  // BLASes of the applied scene that are two geometries.
  size_t blases_split() const;
  // Camera, bounce and shadow rays traced by render_band since construction.
  uint64_t rays_traced() const;

 private:
  void upload(const commit::ChangeSet& changes) override;

  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace cohort::tracers
