#include "cohort/tracers/embree_tracer.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include "embree_filters.h"
#include "embree_kernel.h"
#include "embree_raw.h"
#include "embree_skinned.h"
#include "embree_tiles.h"

namespace cohort::tracers {

namespace embree_kernel {

void log_ray(RayLog* log, RayClass ray_class, KVec3 org, KVec3 dir, float tmax, kuint ray_mask) {
  const EmbreeRay ray{{org.x, org.y, org.z}, {dir.x, dir.y, dir.z}, tmax, ray_mask};
  (ray_class == kCameraRay ? log->rays.camera : ray_class == kShadowRay ? log->rays.shadow : log->rays.bounce)
      .push_back(ray);
}

void filter_hit(const RTCFilterFunctionNArguments* args) {
  const auto* fc = reinterpret_cast<const FilterContext*>(args->context);
  const KSceneView* scene = fc->scene;
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] == 0) continue;
    kuint instance = args->context->instID[0];
    const KInstance& inst = scene->instances[instance];
    const kuint ray_mask = RTCRayN_mask(args->ray, args->N, i);
    if ((inst.mask & ray_mask) == 0u) {
      args->valid[i] = 0;
      continue;
    }
    const kuint triangle = scene_triangle(*scene, fc->split, instance, RTCHitN_geomID(args->hit, args->N, i),
                                          RTCHitN_primID(args->hit, args->N, i));
    float u = RTCHitN_u(args->hit, args->N, i), v = RTCHitN_v(args->hit, args->N, i);
    const int ray_kind = fc->occlusion ? k_shadow_ray_kind(ray_mask) : 0;
    if (k_hit_transmittance(scene, instance, triangle, u, v, ray_kind) > 0.0f) args->valid[i] = 0;
  }
}

}  // namespace embree_kernel

namespace embree_tiles {

bool has_x86_64_v3() {
#if defined(COHORT_EMBREE_X86_64_V3)
#if defined(__clang__) || (defined(__GNUC__) && __GNUC__ < 12)
  static const bool has = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") &&
                          __builtin_cpu_supports("bmi") && __builtin_cpu_supports("bmi2") &&
                          __builtin_cpu_supports("f16c");
#else
  static const bool has = __builtin_cpu_supports("x86-64-v3");
#endif
  return has;
#else
  return false;
#endif
}

#if !defined(COHORT_EMBREE_X86_64_V3)
void render_tile_x86_64_v3(const Frame& frame, const Tile& tile, Arena& arena, embree_kernel::RayLog* log,
                           uint64_t row_rays[kTileHeight]) {
  render_tile(frame, tile, arena, log, row_rays);
}
void render_wave_tile_x86_64_v3(const Frame& frame, const Tile& tile, Arena& arena, embree_kernel::RayLog* log,
                                uint64_t row_rays[kTileHeight]) {
  render_wave_tile(frame, tile, arena, log, row_rays);
}
#endif

}  // namespace embree_tiles

namespace {

// An on/off switch from the environment: 1 or unset on, 0 off; anything else is named in the error.
bool switch_from_environment(const char* variable) {
  const char* v = std::getenv(variable);
  if (!v || std::strcmp(v, "1") == 0) return true;
  if (std::strcmp(v, "0") == 0) return false;
  throw std::invalid_argument(std::string("EmbreeTracer: ") + variable + "='" + v + "' (expected 0 or 1)");
}

// COHORT_EMBREE_WAVEFRONT: 1 (the default) renders tiles as wavefronts, 0 path by path.
bool wavefront_from_environment() { return switch_from_environment("COHORT_EMBREE_WAVEFRONT"); }

// COHORT_EMBREE_PACKET_WIDTH: the wavefront's rays per packet, 8 or 16 (unset: Embree's native width); anything
// else is named in the error.
int packet_width_from_environment(int native) {
  const char* v = std::getenv("COHORT_EMBREE_PACKET_WIDTH");
  if (!v || !*v) return native;
  if (std::strcmp(v, "8") == 0) return 8;
  if (std::strcmp(v, "16") == 0) return 16;
  throw std::invalid_argument(std::string("EmbreeTracer: COHORT_EMBREE_PACKET_WIDTH='") + v + "' (expected 8 or 16)");
}

void check_device(RTCDevice device, const char* what) {
  RTCError code = rtcGetDeviceError(device);
  if (code != RTC_ERROR_NONE)
    throw std::runtime_error(std::string("EmbreeTracer: Embree error ") + std::to_string(static_cast<int>(code)) +
                             " while " + what);
}

}  // namespace

struct EmbreeTracer::Impl {
  RTCDevice device = nullptr;
  RTCScene top = nullptr;
  std::vector<RTCScene> blas_scenes;
  bool ray_masks = false;            // the device applies instance masks itself (rtcSetGeometryMask)
  std::vector<char> passing_materials;  // per BLAS: embree_filters::blases_with_passing_materials
  std::vector<char> filtered;           // per BLAS: whether its geometry 0 has filter_hit attached
  // set_split_filters (COHORT_EMBREE_SPLIT_FILTERS): a BLAS whose own materials let rays pass on some of its
  // triangles only is two geometries, the others without the filter function (embree_kernel::SplitBlas).
  bool split_filters = switch_from_environment("COHORT_EMBREE_SPLIT_FILTERS");
  std::vector<std::array<std::vector<kuint>, 2>> split_triangles;  // per BLAS; both empty where not split
  std::vector<embree_kernel::SplitBlas> split_view;                 // per BLAS, into split_triangles
  size_t blases_split = 0;
  const embree_kernel::SplitBlas* split() const { return blases_split > 0 ? split_view.data() : nullptr; }
  std::unique_ptr<tbb::global_control> thread_limit;
  uint64_t rays_traced = 0;
  bool x86_64_v3 = embree_tiles::has_x86_64_v3();
  bool wavefront = wavefront_from_environment();
  // The wavefront's packets: 16 rays where Embree traces them natively (AVX-512; 2-3% faster than 8 on the
  // test map there, docs/embree-tracer.md), else 8.
  int packet_width = 8;

  void render_tile(const embree_tiles::Frame& frame, const embree_tiles::Tile& tile, embree_tiles::Arena& arena,
                   embree_kernel::RayLog* log, uint64_t* row_rays) const {
    namespace et = embree_tiles;
    // The BVH heat map traces Cohort's own BVH per pixel (embree_bvh_view.cpp): no rays for a wavefront.
    if (wavefront && frame.params.mode != K_MODE_BVH)
      (x86_64_v3 ? et::render_wave_tile_x86_64_v3 : et::render_wave_tile)(frame, tile, arena, log, row_rays);
    else
      (x86_64_v3 ? et::render_tile_x86_64_v3 : et::render_tile)(frame, tile, arena, log, row_rays);
  }
  // Each thread's tile buffers, kept from band to band: rendering allocates nothing per tile or ray.
  tbb::enumerable_thread_specific<embree_tiles::Arena> arenas;

  ~Impl() {
    release_top();
    release_blases();
    if (device) rtcReleaseDevice(device);
  }

  void release_top() {
    if (top) rtcReleaseScene(top);
    top = nullptr;
  }
  void release_blases() {
    for (RTCScene s : blas_scenes)
      if (s) rtcReleaseScene(s);
    blas_scenes.clear();
  }

  static void set_filter(RTCGeometry g, bool on) {
    rtcSetGeometryIntersectFilterFunction(g, on ? embree_kernel::filter_hit : nullptr);
    rtcSetGeometryOccludedFilterFunction(g, on ? embree_kernel::filter_hit : nullptr);
  }

  // Whether geometry 0 of BLAS b needs filter_hit: for a split BLAS only where an instance's material
  // override may let rays pass (its passing triangles are geometry 1, always filtered).
  char geometry0_filter(size_t b, const std::vector<char>& needs, const std::vector<char>& overrides) const {
    return b < split_triangles.size() && !split_triangles[b][1].empty() ? overrides[b] : needs[b];
  }
  // Whether a split BLAS's unfiltered geometry now holds a triangle whose material may let rays pass (a
  // material changed): the BLASes must then be built again.
  bool split_outdated(const commit::TracerScene& scene) const {
    for (const auto& parts : split_triangles) {
      if (parts[1].empty()) continue;
      for (kuint t : parts[0])
        if (embree_filters::triangle_may_pass(scene, t)) return true;
    }
    return false;
  }

  // Attaches or detaches filter_hit where a BLAS's need changed (materials or overrides changed).
  // Returns whether any BLAS changed: the instance scene must then be rebuilt.
  bool update_filters(const std::vector<char>& needs, const std::vector<char>& overrides) {
    bool changed = false;
    for (size_t b = 0; b < blas_scenes.size() && b < needs.size(); ++b) {
      const char want = geometry0_filter(b, needs, overrides);
      if (filtered[b] == want) continue;
      filtered[b] = want;
      RTCGeometry g = rtcGetGeometry(blas_scenes[b], 0);
      if (!g) continue;
      set_filter(g, want != 0);
      rtcCommitGeometry(g);
      rtcCommitScene(blas_scenes[b]);
      changed = true;
    }
    return changed;
  }

  // A triangle geometry over the scene's vertices (shared, no copy).
  RTCGeometry new_triangles(const commit::TracerScene& scene) const {
    RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, scene.vertices.data(), 0,
                               sizeof(KVertex), scene.vertices.size());
    return g;
  }

  // One Embree scene per KBlas, sharing the TracerScene's vertex and triangle arrays (no copies); or, for a
  // BLAS whose own materials let rays pass on some triangles only (and no instance overrides them so, and
  // not skinned), two geometries with index buffers of their own: the triangles no ray passes (geometry 0,
  // no filter function, so Embree takes their hits without calling back) and the others (geometry 1).
  void build_blases(const commit::TracerScene& scene, const std::vector<char>& needs_filter,
                    const std::vector<char>& overrides) {
    release_blases();
    filtered = needs_filter;
    split_triangles.assign(scene.blases.size(), {});
    split_view.assign(scene.blases.size(), embree_kernel::SplitBlas{{nullptr, nullptr}});
    blases_split = 0;
    for (size_t index = 0; index < scene.blases.size(); ++index) {
      const KBlas& b = scene.blases[index];
      RTCScene s = rtcNewScene(device);
      const bool skinned = embree_skinned::is_skinned(scene, uint32_t(index));
      auto& parts = split_triangles[index];
      if (split_filters && ray_masks && !skinned && needs_filter[index] && !overrides[index]) {
        for (kuint t = b.tri_offset; t < b.tri_offset + b.tri_count && t < scene.triangles.size(); ++t)
          parts[embree_filters::triangle_may_pass(scene, t) ? 1 : 0].push_back(t);
        if (parts[0].empty() || parts[1].empty()) parts = {};  // nothing to split off
      }
      if (!parts[1].empty()) {
        for (unsigned part = 0; part < 2; ++part) {
          RTCGeometry g = new_triangles(scene);
          auto* index_buffer = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
              g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), parts[part].size()));
          for (size_t i = 0; i < parts[part].size(); ++i) {
            const KTriangle& tri = scene.triangles[parts[part][i]];
            index_buffer[3 * i] = tri.v0;
            index_buffer[3 * i + 1] = tri.v1;
            index_buffer[3 * i + 2] = tri.v2;
          }
          set_filter(g, part == 1);
          rtcCommitGeometry(g);
          rtcAttachGeometryByID(s, g, part);
          rtcReleaseGeometry(g);
        }
        filtered[index] = 0;
        split_view[index] = embree_kernel::SplitBlas{{parts[0].data(), parts[1].data()}};
        ++blases_split;
      } else if (b.tri_count > 0) {
        RTCGeometry g = new_triangles(scene);
        rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, scene.triangles.data(),
                                   size_t(b.tri_offset) * sizeof(KTriangle), sizeof(KTriangle), b.tri_count);
        set_filter(g, needs_filter[index] != 0);
        if (skinned) embree_skinned::prepare(s, g);
        rtcCommitGeometry(g);
        rtcAttachGeometryByID(s, g, 0);
        rtcReleaseGeometry(g);
      }
      rtcCommitScene(s);
      blas_scenes.push_back(s);
    }
  }
  // Every BLAS and the instance scene built again for the scene as it is now.
  void rebuild(const commit::TracerScene& scene) {
    build_blases(scene, embree_filters::blases_needing_filters(scene, passing_materials, ray_masks),
                 embree_filters::blases_with_passing_overrides(scene, ray_masks));
    check_device(device, "building the BLAS scenes");
    build_top(scene);
  }

  // Instance geometry IDs equal KInstance indices, so instID[0] indexes the instance array directly.
  void build_top(const commit::TracerScene& scene) {
    release_top();
    top = rtcNewScene(device);
    for (size_t i = 0; i < scene.instances.size(); ++i) {
      const KInstance& inst = scene.instances[i];
      if (inst.blas >= blas_scenes.size())
        throw std::runtime_error("EmbreeTracer: instance " + std::to_string(i) + " names BLAS " +
                                 std::to_string(inst.blas) + " of " + std::to_string(blas_scenes.size()));
      RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_INSTANCE);
      rtcSetGeometryInstancedScene(g, blas_scenes[inst.blas]);
      rtcSetGeometryTransform(g, 0, RTC_FORMAT_FLOAT3X4_ROW_MAJOR, inst.object_to_world);
      rtcSetGeometryMask(g, ray_masks ? inst.mask : 0xFFFFFFFFu);
      rtcCommitGeometry(g);
      rtcAttachGeometryByID(top, g, static_cast<unsigned>(i));
      rtcReleaseGeometry(g);
    }
    rtcCommitScene(top);
  }
};

EmbreeTracer::EmbreeTracer(int threads) : impl_(std::make_unique<Impl>()) {
  impl_->device = rtcNewDevice(nullptr);
  if (!impl_->device) throw std::runtime_error("EmbreeTracer: rtcNewDevice failed");
  impl_->ray_masks = rtcGetDeviceProperty(impl_->device, RTC_DEVICE_PROPERTY_RAY_MASK_SUPPORTED) != 0;
  if (rtcGetDeviceProperty(impl_->device, RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED) != 0) impl_->packet_width = 16;
  impl_->packet_width = packet_width_from_environment(impl_->packet_width);
  if (threads > 0)
    impl_->thread_limit =
        std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, size_t(threads));
}

EmbreeTracer::~EmbreeTracer() = default;

void EmbreeTracer::upload(const commit::ChangeSet& changes) {
  const bool rebuild = changes.full_resync || changes.geometry;
  if (rebuild || changes.materials)
    impl_->passing_materials = embree_filters::blases_with_passing_materials(scene());
  if (rebuild || (changes.materials && impl_->split_outdated(scene()))) {
    impl_->rebuild(scene());
  } else {
    bool top_changed = changes.instances || changes.tlas || !changes.posed_skins.empty() || !impl_->top;
    if (changes.materials || changes.instances)
      top_changed |= impl_->update_filters(
          embree_filters::blases_needing_filters(scene(), impl_->passing_materials, impl_->ray_masks),
          embree_filters::blases_with_passing_overrides(scene(), impl_->ray_masks));
    if (top_changed) {
      embree_skinned::refit(scene(), changes.posed_skins, impl_->blas_scenes);
      impl_->build_top(scene());
    }
  }
  check_device(impl_->device, "building the instance scene");
}

namespace {

embree_tiles::Frame make_frame(const KFrameParams& params, const core::BandJob& job, const KSceneView& scene,
                               const embree_kernel::SplitBlas* split, RTCScene top, const KAuxHistory& history,
                               core::BandBuffer* target, int packet_width) {
  embree_tiles::Frame frame;
  frame.params = params;
  frame.camera = job.camera;
  frame.previous_camera = job.previous_camera.width > 0 ? job.previous_camera : job.camera;
  frame.history = history;
  frame.write_aux = target && params.aux_outputs != 0u && target->has_aux();
  frame.base = embree_kernel::TraceCtx{scene, split, top, 0, nullptr, 0, v3s(0.0f), nullptr};
  frame.target = target;
  frame.shadow_slots = k_shadow_queue_slots(&params, scene.light_count, scene.emissive_count);
  frame.packet_width = packet_width;
  return frame;
}

}  // namespace

core::BandResult EmbreeTracer::render_band(const core::BandJob& job, core::BandBuffer& target) {
  if (!impl_->top) throw std::runtime_error("EmbreeTracer: render_band before any commit was applied");
  auto start = std::chrono::steady_clock::now();
  const KFrameParams params = frame_params(job);
  const int row_begin = static_cast<int>(params.row_begin);
  const int row_end = std::min(static_cast<int>(params.row_end), target.height());
  const int width = std::min(static_cast<int>(job.camera.width), target.width());
  const KSceneView scene = host_scene_view(params);
  const commit::TracerScene& s = this->scene();
  KAuxHistory history{};
  history.object_to_world = previous_transforms().empty() ? nullptr : previous_transforms().data();
  history.skins = s.skins.data();
  history.skin_vertices = s.skin_vertices.data();
  history.skin_weights = s.skin_weights.data();
  history.joints = previous_joints().empty() ? nullptr : previous_joints().data();
  history.skin_count = static_cast<kuint>(s.skins.size());
  const embree_tiles::Frame frame =
      make_frame(params, job, scene, impl_->split(), impl_->top, history, &target, impl_->packet_width);
  // Rays traced per row: the balancer's per-row work proxy (BandResult::row_work), as the GPU tracers count it.
  std::vector<std::atomic<uint64_t>> row_rays(static_cast<size_t>(std::max(row_end - row_begin, 0)));
  std::atomic<uint64_t> rays{0};
  // A grid of tiles, handed to the cores by TBB's work stealing (tiles differ widely in cost).
  const int tiles_x = (std::max(width, 0) + embree_tiles::kTileWidth - 1) / embree_tiles::kTileWidth;
  const int tiles_y = (std::max(row_end - row_begin, 0) + embree_tiles::kTileHeight - 1) / embree_tiles::kTileHeight;
  tbb::parallel_for(tbb::blocked_range<int>(0, tiles_x * tiles_y), [&](const tbb::blocked_range<int>& r) {
    embree_tiles::Arena& arena = impl_->arenas.local();
    uint64_t local = 0;
    for (int index = r.begin(); index < r.end(); ++index) {
      const int x0 = (index % tiles_x) * embree_tiles::kTileWidth;
      const int y0 = row_begin + (index / tiles_x) * embree_tiles::kTileHeight;
      const embree_tiles::Tile tile{x0, y0, std::min(x0 + embree_tiles::kTileWidth, width),
                                    std::min(y0 + embree_tiles::kTileHeight, row_end)};
      uint64_t tile_rows[embree_tiles::kTileHeight] = {};
      impl_->render_tile(frame, tile, arena, nullptr, tile_rows);
      for (int y = tile.y0; y < tile.y1; ++y) {
        row_rays[static_cast<size_t>(y - row_begin)] += tile_rows[y - tile.y0];
        local += tile_rows[y - tile.y0];
      }
    }
    rays += local;
  });
  impl_->rays_traced += rays.load();
  core::BandResult result;
  result.device_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  if (row_end == static_cast<int>(params.row_end)) {
    result.row_work.resize(row_rays.size());
    for (size_t i = 0; i < row_rays.size(); ++i) result.row_work[i] = static_cast<float>(row_rays[i].load());
  }
  return result;
}

void EmbreeTracer::set_wavefront(bool on) { impl_->wavefront = on; }

bool EmbreeTracer::wavefront() const { return impl_->wavefront; }

void EmbreeTracer::set_wave_packet_width(int rays) {
  if (rays != 8 && rays != 16)
    throw std::invalid_argument("EmbreeTracer: wave packets of " + std::to_string(rays) + " rays (expected 8 or 16)");
  impl_->packet_width = rays;
}

int EmbreeTracer::wave_packet_width() const { return impl_->packet_width; }

bool EmbreeTracer::prefer_x86_64_v3(bool prefer) {
  impl_->x86_64_v3 = prefer && embree_tiles::has_x86_64_v3();
  return impl_->x86_64_v3;
}

uint64_t EmbreeTracer::rays_traced() const { return impl_->rays_traced; }

EmbreeRaySet EmbreeTracer::record_rays(const core::BandJob& job) {
  if (!impl_->top) throw std::runtime_error("EmbreeTracer: record_rays before any commit was applied");
  const KFrameParams params = frame_params(job);
  const KSceneView scene = host_scene_view(params);
  const embree_tiles::Frame frame =
      make_frame(params, job, scene, impl_->split(), impl_->top, KAuxHistory{}, nullptr, impl_->packet_width);
  auto arena = std::make_unique<embree_tiles::Arena>();
  embree_kernel::RayLog log;
  log.camera_dir = v3s(0.0f);
  const int width = static_cast<int>(job.camera.width);
  for (int y0 = static_cast<int>(params.row_begin); y0 < static_cast<int>(params.row_end); y0 += embree_tiles::kTileHeight)
    for (int x0 = 0; x0 < width; x0 += embree_tiles::kTileWidth) {
      const embree_tiles::Tile tile{x0, y0, std::min(x0 + embree_tiles::kTileWidth, width),
                                    std::min(y0 + embree_tiles::kTileHeight, static_cast<int>(params.row_end))};
      uint64_t tile_rows[embree_tiles::kTileHeight] = {};
      impl_->render_tile(frame, tile, *arena, &log, tile_rows);
    }
  return std::move(log.rays);
}

uint64_t EmbreeTracer::trace_raw(const std::vector<EmbreeRay>& rays, bool occlusion, EmbreeRayApi api, bool coherent) {
  if (!impl_->top) throw std::runtime_error("EmbreeTracer: trace_raw before any commit was applied");
  const KFrameParams params = frame_params(core::BandJob{});
  return embree_raw::trace(impl_->top, host_scene_view(params), impl_->split(), rays, occlusion, api, coherent);
}

void EmbreeTracer::set_split_filters(bool on) {
  if (impl_->split_filters == on) return;
  impl_->split_filters = on;
  if (impl_->top) impl_->rebuild(scene());
}
bool EmbreeTracer::split_filters() const { return impl_->split_filters; }
size_t EmbreeTracer::blases_split() const { return impl_->blases_split; }

}  // namespace cohort::tracers
