#include "cohort/tracers/embree_tracer.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <stdexcept>
#include <string>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include "embree_kernel.h"
#include "embree_skinned.h"

namespace cohort::tracers {

namespace embree_kernel {

void filter_hit(const RTCFilterFunctionNArguments* args) {
  const auto* fc = reinterpret_cast<const FilterContext*>(args->context);
  const KSceneView* scene = fc->scene;
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] == 0) continue;
    kuint instance = args->context->instID[0];
    const KInstance& inst = scene->instances[instance];
    if ((inst.mask & fc->ray_mask) == 0u) {
      args->valid[i] = 0;
      continue;
    }
    kuint triangle = scene->blases[inst.blas].tri_offset + RTCHitN_primID(args->hit, args->N, i);
    float u = RTCHitN_u(args->hit, args->N, i), v = RTCHitN_v(args->hit, args->N, i);
    if (k_hit_transmittance(scene, instance, triangle, u, v, fc->shadow_ray) > 0.0f) args->valid[i] = 0;
  }
}

}  // namespace embree_kernel

namespace {

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
  std::unique_ptr<tbb::global_control> thread_limit;
  uint64_t rays_traced = 0;

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

  // One Embree scene per KBlas, sharing the TracerScene's vertex and triangle arrays (no copies).
  void build_blases(const commit::TracerScene& scene) {
    release_blases();
    for (size_t index = 0; index < scene.blases.size(); ++index) {
      const KBlas& b = scene.blases[index];
      RTCScene s = rtcNewScene(device);
      if (b.tri_count > 0) {
        RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
        rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, scene.vertices.data(), 0,
                                   sizeof(KVertex), scene.vertices.size());
        rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, scene.triangles.data(),
                                   size_t(b.tri_offset) * sizeof(KTriangle), sizeof(KTriangle), b.tri_count);
        rtcSetGeometryIntersectFilterFunction(g, embree_kernel::filter_hit);
        rtcSetGeometryOccludedFilterFunction(g, embree_kernel::filter_hit);
        if (embree_skinned::is_skinned(scene, uint32_t(index))) embree_skinned::prepare(s, g);
        rtcCommitGeometry(g);
        rtcAttachGeometryByID(s, g, 0);
        rtcReleaseGeometry(g);
      }
      rtcCommitScene(s);
      blas_scenes.push_back(s);
    }
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
  if (threads > 0)
    impl_->thread_limit =
        std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, size_t(threads));
}

EmbreeTracer::~EmbreeTracer() = default;

void EmbreeTracer::upload(const commit::ChangeSet& changes) {
  if (changes.full_resync || changes.geometry) {
    impl_->build_blases(scene());
    check_device(impl_->device, "building the BLAS scenes");
    impl_->build_top(scene());
  } else if (changes.instances || changes.tlas || !changes.posed_skins.empty() || !impl_->top) {
    embree_skinned::refit(scene(), changes.posed_skins, impl_->blas_scenes);
    impl_->build_top(scene());
  }
  check_device(impl_->device, "building the instance scene");
}

core::BandResult EmbreeTracer::render_band(const core::BandJob& job, core::BandBuffer& target) {
  if (!impl_->top) throw std::runtime_error("EmbreeTracer: render_band before any commit was applied");
  auto start = std::chrono::steady_clock::now();
  const KFrameParams params = frame_params(job);
  const KCamera camera = job.camera;
  const int row_begin = static_cast<int>(params.row_begin);
  const int row_end = std::min(static_cast<int>(params.row_end), target.height());
  const int width = std::min(static_cast<int>(camera.width), target.width());
  const embree_kernel::TraceCtx base{host_scene_view(params), impl_->top, 0};
  const bool write_aux = params.aux_outputs != 0u && target.has_aux();
  const KCamera previous_camera = job.previous_camera.width > 0 ? job.previous_camera : camera;
  const float* object_history = previous_transforms().empty() ? nullptr : previous_transforms().data();
  std::atomic<uint64_t> rays{0};
  // Rays traced per row: the balancer's per-row work proxy (BandResult::row_work), as the GPU tracers count it.
  std::vector<float> row_rays(static_cast<size_t>(std::max(row_end - row_begin, 0)), 0.0f);
  tbb::parallel_for(tbb::blocked_range<int>(row_begin, row_end, 1), [&](const tbb::blocked_range<int>& rows) {
    embree_kernel::TraceCtx ctx = base;
    std::vector<float> out(static_cast<size_t>(width) * 4);  // one row, stored in the target's format
    std::vector<KAux> aux(write_aux ? static_cast<size_t>(width) : 0u);
    for (int y = rows.begin(); y < rows.end(); ++y) {
      const uint64_t rays_before = ctx.rays;
      for (int x = 0; x < width; ++x) {
        KVec3 c = k_render_pixel(&ctx, &params, &camera, static_cast<kuint>(x), static_cast<kuint>(y));
        out[4 * x + 0] = c.x;
        out[4 * x + 1] = c.y;
        out[4 * x + 2] = c.z;
        out[4 * x + 3] = 1.0f;
      }
      target.store(y, 0, out.data(), static_cast<size_t>(width));
      if (write_aux) {
        for (int x = 0; x < width; ++x)
          k_pixel_aux(&ctx, &camera, &previous_camera, object_history, static_cast<kuint>(x),
                      static_cast<kuint>(y), &aux[static_cast<size_t>(x)]);
        target.store_aux(y, 0, aux.data(), static_cast<size_t>(width));
      }
      row_rays[static_cast<size_t>(y - row_begin)] = static_cast<float>(ctx.rays - rays_before);
    }
    rays += ctx.rays;
  });
  impl_->rays_traced += rays.load();
  core::BandResult result;
  result.device_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  if (row_end == static_cast<int>(params.row_end)) result.row_work = std::move(row_rays);
  return result;
}

uint64_t EmbreeTracer::rays_traced() const { return impl_->rays_traced; }

uint64_t EmbreeTracer::trace_camera_rays_only(const core::BandJob& job) {
  if (!impl_->top) throw std::runtime_error("EmbreeTracer: trace before any commit was applied");
  const KFrameParams params = frame_params(job);
  const KCamera camera = job.camera;
  const kuint spp = params.spp > 0u ? params.spp : 1u;
  const embree_kernel::TraceCtx base{host_scene_view(params), impl_->top, 0};
  std::atomic<uint64_t> hits{0};
  tbb::parallel_for(tbb::blocked_range<int>(static_cast<int>(params.row_begin), static_cast<int>(params.row_end), 1),
                    [&](const tbb::blocked_range<int>& rows) {
                      embree_kernel::TraceCtx ctx = base;
                      uint64_t local = 0;
                      KVec3 org = v3_load(camera.origin);
                      for (int y = rows.begin(); y < rows.end(); ++y)
                        for (kuint x = 0; x < camera.width; ++x)
                          for (kuint s = 0; s < spp; ++s) {
                            KRng rng = k_rng_seed(x, static_cast<kuint>(y), params.frame_index, s);
                            float jx = k_rng_next(&rng), jy = k_rng_next(&rng);
                            KVec3 dir = k_camera_direction(&camera, float(x) + jx, float(y) + jy);
                            KHit hit;
                            local += static_cast<uint64_t>(k_trace_closest(&ctx, org, dir, K_INF, K_RAY_PRIMARY, &hit));
                          }
                      hits += local;
                    });
  return hits.load();
}

}  // namespace cohort::tracers
