#include "embree_raw.h"

#include <algorithm>
#include <atomic>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "embree_kernel.h"

namespace cohort::tracers::embree_raw {

namespace {

constexpr size_t kStream = 256;

RTCRay to_rtc(const EmbreeRay& r) {
  return embree_kernel::make_ray(v3(r.org[0], r.org[1], r.org[2]), v3(r.dir[0], r.dir[1], r.dir[2]), r.tmax, r.mask);
}

uint64_t trace_single(RTCScene top, embree_kernel::FilterContext& fc, const EmbreeRay* rays, size_t n, bool occlusion) {
  uint64_t count = 0;
  for (size_t i = 0; i < n; ++i) {
    if (occlusion) {
      RTCRay ray = to_rtc(rays[i]);
      rtcOccluded1(top, &fc.base, &ray);
      count += ray.tfar < 0.0f;
    } else {
      RTCRayHit rh;
      rh.ray = to_rtc(rays[i]);
      rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
      rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
      rtcIntersect1(top, &fc.base, &rh);
      count += rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
    }
  }
  return count;
}

void fill_lane(RTCRay8& p, int k, const EmbreeRay& r) {
  p.org_x[k] = r.org[0]; p.org_y[k] = r.org[1]; p.org_z[k] = r.org[2];
  p.dir_x[k] = r.dir[0]; p.dir_y[k] = r.dir[1]; p.dir_z[k] = r.dir[2];
  p.tnear[k] = 0.0f;
  p.tfar[k] = r.tmax;
  p.mask[k] = r.mask;
  p.time[k] = 0.0f;
  p.id[k] = static_cast<unsigned>(k);
  p.flags[k] = 0u;
}

uint64_t trace_packets(RTCScene top, embree_kernel::FilterContext& fc, const EmbreeRay* rays, size_t n, bool occlusion) {
  uint64_t count = 0;
  for (size_t first = 0; first < n; first += 8) {
    alignas(32) int valid[8];
    alignas(32) RTCRayHit8 rh;
    for (int k = 0; k < 8; ++k) {
      valid[k] = first + k < n ? -1 : 0;
      fill_lane(rh.ray, k, rays[std::min(first + k, n - 1)]);
      rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
      rh.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
    }
    if (occlusion) {
      rtcOccluded8(valid, top, &fc.base, &rh.ray);
      for (int k = 0; k < 8; ++k) count += valid[k] && rh.ray.tfar[k] < 0.0f;
    } else {
      rtcIntersect8(valid, top, &fc.base, &rh);
      for (int k = 0; k < 8; ++k) count += valid[k] && rh.hit.geomID[k] != RTC_INVALID_GEOMETRY_ID;
    }
  }
  return count;
}

uint64_t trace_stream(RTCScene top, embree_kernel::FilterContext& fc, const EmbreeRay* rays, size_t n, bool occlusion) {
  uint64_t count = 0;
  RTCRayHit stream[kStream];
  for (size_t first = 0; first < n; first += kStream) {
    const size_t m = std::min(kStream, n - first);
    for (size_t i = 0; i < m; ++i) {
      stream[i].ray = to_rtc(rays[first + i]);
      stream[i].hit.geomID = RTC_INVALID_GEOMETRY_ID;
      stream[i].hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    }
    if (occlusion) {
      // rtcOccluded1M takes RTCRay records; RTCRayHit's ray part comes first, so stride over the pairs.
      rtcOccluded1M(top, &fc.base, &stream[0].ray, static_cast<unsigned>(m), sizeof(RTCRayHit));
      for (size_t i = 0; i < m; ++i) count += stream[i].ray.tfar < 0.0f;
    } else {
      rtcIntersect1M(top, &fc.base, stream, static_cast<unsigned>(m), sizeof(RTCRayHit));
      for (size_t i = 0; i < m; ++i) count += stream[i].hit.geomID != RTC_INVALID_GEOMETRY_ID;
    }
  }
  return count;
}

}  // namespace

uint64_t trace(RTCScene top, const KSceneView& scene, const embree_kernel::SplitBlas* split,
               const std::vector<EmbreeRay>& rays, bool occlusion, EmbreeRayApi api, bool coherent) {
  if (rays.empty()) return 0;
  std::atomic<uint64_t> total{0};
  tbb::parallel_for(tbb::blocked_range<size_t>(0, rays.size(), 4 * kStream), [&](const tbb::blocked_range<size_t>& r) {
    embree_kernel::FilterContext fc = embree_kernel::filter_context(&scene, split, occlusion, coherent);
    const EmbreeRay* first = rays.data() + r.begin();
    const size_t n = r.size();
    uint64_t count = 0;
    switch (api) {
      case EmbreeRayApi::single: count = trace_single(top, fc, first, n, occlusion); break;
      case EmbreeRayApi::packet8: count = trace_packets(top, fc, first, n, occlusion); break;
      case EmbreeRayApi::stream: count = trace_stream(top, fc, first, n, occlusion); break;
    }
    total += count;
  });
  return total.load();
}

}  // namespace cohort::tracers::embree_raw
