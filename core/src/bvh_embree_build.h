// Builds a binary BVH with Embree's rtcBuildBVH (multithreaded through TBB) and flattens it into the
// kernel's node layout (layout.h, walked by bvh_traverse.h): the two children of an interior node are
// adjacent and stored after it, depth first, so a reverse sweep meets children before parents (refit).
#pragma once

#include <cstdint>
#include <vector>

#include <embree3/rtcore.h>

#include "cohort/kernel/layout.h"

namespace cohort::core::detail {

enum class BuildQuality {
  morton,       // RTC_BUILD_QUALITY_LOW: fastest build, for trees rebuilt every frame
  binned_sah,   // RTC_BUILD_QUALITY_MEDIUM: binned SAH, for trees traced many times
};

struct BuildSettings {
  BuildQuality quality = BuildQuality::binned_sah;
  uint32_t max_leaf_size = 4;
  int threads = 0;   // 0: every hardware thread; otherwise the build runs in a TBB arena this wide
  // Keep Embree's build memory on this thread for the next build: a tree rebuilt every frame then
  // pays no page faults. Off for one-off builds, whose memory is better returned.
  bool keep_memory = false;
};

struct FlatBuild {
  std::vector<KBvhNode> nodes;
  std::vector<uint32_t> order;   // leaf order: order[i] is the primID at leaf position i
};

// `primitives` (primID = the caller's index, geomID unused) is reordered in place. No primitives give
// no nodes. Trees are at most K_BVH_MAX_DEPTH levels deep; throws std::runtime_error when Embree fails.
FlatBuild build_flat_bvh(std::vector<RTCBuildPrimitive>& primitives, const BuildSettings& settings);

}  // namespace cohort::core::detail
