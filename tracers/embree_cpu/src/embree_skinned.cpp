#include "embree_skinned.h"

namespace cohort::tracers::embree_skinned {

bool is_skinned(const commit::TracerScene& scene, uint32_t blas) {
  for (const KSkin& skin : scene.skins)
    if (skin.blas == blas) return true;
  return false;
}

void prepare(RTCScene blas_scene, RTCGeometry geometry) {
  // Embree honours a geometry's build quality only in a scene of low build quality (its two-level
  // structure); the geometry's own BVH is then built once and refit when its vertex buffer changes.
  rtcSetSceneFlags(blas_scene, RTC_SCENE_FLAG_DYNAMIC);
  rtcSetSceneBuildQuality(blas_scene, RTC_BUILD_QUALITY_LOW);
  rtcSetGeometryBuildQuality(geometry, RTC_BUILD_QUALITY_REFIT);
}

void refit(const commit::TracerScene& scene, const std::vector<uint32_t>& posed_skins,
           const std::vector<RTCScene>& blas_scenes) {
  for (uint32_t index : posed_skins) {
    const uint32_t blas = scene.skins.at(index).blas;
    if (blas >= blas_scenes.size() || !blas_scenes[blas]) continue;
    RTCGeometry geometry = rtcGetGeometry(blas_scenes[blas], 0);
    if (!geometry) continue;
    rtcUpdateGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0);
    rtcCommitGeometry(geometry);
    rtcCommitScene(blas_scenes[blas]);
  }
}

}  // namespace cohort::tracers::embree_skinned
