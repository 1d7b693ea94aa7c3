#include "cohort/tracers/cuda_tracer.h"

#include <cuda_runtime.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "cohort/kernel/aux_mode.h"
#include "cohort/kernel/path_state.h"
#include "cohort/tracers/enqueue_ahead.h"
#include "device_array.h"
#include "host_registrations.h"
#include "render_band_launch.h"
#include "skinning_launch.h"

namespace cohort::tracers {

int cuda_device_count() {
  int count = 0;
  if (cudaGetDeviceCount(&count) != cudaSuccess) {
    cudaGetLastError();   // clear the sticky "no driver" error so later calls start clean
    return 0;
  }
  return count;
}

std::string cuda_device_name(int device) {
  cudaDeviceProp prop{};
  if (cudaGetDeviceProperties(&prop, device) != cudaSuccess) return "unknown CUDA device";
  return prop.name;
}

PciBusId cuda_device_pci_bus_id(int device) {
  cudaDeviceProp prop{};
  if (cudaGetDeviceProperties(&prop, device) != cudaSuccess) {
    cudaGetLastError();
    return {};
  }
  return PciBusId::of(unsigned(prop.pciDomainID), unsigned(prop.pciBusID), unsigned(prop.pciDeviceID));
}

// The scene arrays a frame's commit changes without touching geometry (animated materials and lights, moving
// entities and so the TLAS): each band slot keeps its own copy, brought up to date on its stream as its band
// is enqueued, so that a commit applied while the band before renders neither waits for it nor changes what
// it reads (the test map's animated materials commit every frame).
enum SlotArray { kInstances, kTlasNodes, kMaterials, kLights, kLightNodes, kEmissive, kSlotArrays };
struct SlotScene {
  DeviceArray<KInstance> instances;
  DeviceArray<KBvhNode> tlas_nodes;
  DeviceArray<KMaterial> materials;
  DeviceArray<KLight> lights;
  DeviceArray<KLightNode> light_nodes;
  DeviceArray<KEmissiveTriangle> emissive;
  uint64_t versions[kSlotArrays] = {};  // of the host's arrays (CudaTracer::Impl::slot_array_versions) held here
};

// A band's stream, device storage, clock and way back. Two slots, used in turn: with enqueue ahead the next
// band's kernels run on the other slot's stream, into its own storage, so that they may start while this
// band's last kernels drain (band overlap, CudaTracer::set_band_overlap).
struct CudaTracer::BandSlot {
  SlotScene scene;
  cudaStream_t stream = nullptr;
  WaveLanes lanes;
  int released_lanes = 0;  // lanes.released recorded by the band's kernels (0: the next band waits for `stop`)
  cudaEvent_t start = nullptr, stop = nullptr, finished = nullptr;
  cudaEvent_t counted = nullptr;     // after its row counts' and ray totals' copies: the band is all back
  cudaEvent_t aux_copied = nullptr;  // on aux_copy_stream, once its aux texels went down
  unsigned* row_rays = nullptr;      // page-locked, row_rays_capacity rows
  size_t row_rays_capacity = 0;
  unsigned long long* counts = nullptr;  // page-locked: closest, occlusion
  // Device: the band (float4 per pixel), its packed copy for an RGB16F or RGB9E5 target, the rays per band
  // row (the balancer's per-row work), the ray totals (closest, occlusion).
  float4* band = nullptr;
  unsigned char* band_packed = nullptr;
  size_t band_capacity = 0;  // pixels
  unsigned* device_row_rays = nullptr;
  size_t device_row_rays_capacity = 0;  // rows
  unsigned long long* ray_counts = nullptr;
  // The wavefront's scratch (render_band.cu).
  DeviceArray<KPathState> wave_states;
  DeviceArray<KHit> wave_hits;
  DeviceArray<kuint> wave_active;
  DeviceArray<KVertexLight> wave_vertices;
  DeviceArray<KShadowRay> wave_shadow_rays;
  WavefrontScratch wave_scratch;
  // The aux planes' inputs (the previous frame's transforms and joints), the paths' first-hit records
  // (K_AUX_PATH_FIRST_HIT) and the texels on their way down (bands not kept on the GPU).
  DeviceArray<float> previous_transforms;
  DeviceArray<KJoint> previous_joints;
  DeviceArray<KPathFirstHit> first_hits;
  DeviceArray<KAuxTexel> aux_texels;
};

// A band whose commands are all on its slot's stream, until its finish.
struct CudaTracer::EnqueuedBand {
  core::BandJob job;
  core::BandBuffer* target = nullptr;
  BandSlot* slot = nullptr;
  size_t rows = 0;
  bool wait_aux_copy = false;
  std::optional<core::DeviceBand> kept;  // where it stays on the GPU (BandJob::keep_on_device)
  // Whether it has ended (its counters back); a failed band counts as ended.
  bool ended() const { return cudaEventQuery(slot->counted) != cudaErrorNotReady; }
  // Waits until nothing of it is still landing anywhere: its counters back and, with wait_aux_copy, its aux
  // texels too.
  cudaError_t wait() const {
    const cudaError_t error = cudaEventSynchronize(slot->counted);
    return error == cudaSuccess && wait_aux_copy ? cudaEventSynchronize(slot->aux_copied) : error;
  }
};

struct CudaTracer::Impl {
  int device = 0;
  std::string name;
  // Commits (upload) go here, behind the kernels of every band in flight; bands run on their slot's stream.
  cudaStream_t stream = nullptr;
  // The aux planes' download runs here, on the copy engine, while the band's kernel runs on its slot's stream.
  cudaStream_t aux_copy_stream = nullptr;
  cudaEvent_t aux_ready = nullptr;
  BandSlot slots[2];
  int next_slot = 0;
  BandSlot* band_before = nullptr;  // the slot of the band enqueued last
  // How many kernels before the end of a band's lanes the next band may start (COHORT_CUDA_BAND_OVERLAP;
  // 0: once the band's kernels are done).
  int band_overlap = 0;
  // Enqueue ahead (CudaTracer::set_enqueue_ahead): the next band, enqueued while the band before renders,
  // until render_band takes it; whether a commit is being applied ahead (the band before still running).
  bool enqueue_ahead = enabled_unless_zero("COHORT_CUDA_ENQUEUE_AHEAD");
  bool applying_ahead = false;
  std::optional<EnqueuedBand> ahead;
  std::atomic<size_t> enqueued_ahead{0}, finished_ahead{0}, dropped_ahead{0}, overlapping{0};
  // Wakes a worker waiting for its next job once a band is back (cudaLaunchHostFunc on a stream of its own
  // that waits for the band, so that the host function holds no band's stream).
  cudaStream_t signal_stream = nullptr;
  // render_band_in_pieces: per piece, its rows rendered (the copy stream waits for it) and downloaded.
  std::vector<cudaEvent_t> piece_rendered, piece_downloaded;
  DeviceArray<KVertex> vertices;
  DeviceArray<KVertexColor> vertex_colors;
  DeviceArray<KTriangle> triangles;
  // The triangles' corners and edges (KTriangleEdges), made on the device after every geometry upload and
  // skinning pass: the walk's leaf test reads them instead of following vertex indices (render_band.cu).
  DeviceArray<KTriangleEdges> triangle_edges;
  DeviceArray<KBvhNode> blas_nodes;
  DeviceArray<KBlas> blases;
  DeviceArray<KTexture> textures;
  DeviceArray<uint32_t> texels;
  // Bumped as commits change the slots' arrays (SlotScene); a slot whose copy is older uploads it again.
  uint64_t slot_array_versions[kSlotArrays] = {1, 1, 1, 1, 1, 1};
  DeviceArray<KSkin> skins;
  DeviceArray<KSkinVertex> skin_vertices;
  DeviceArray<KSkinWeight> skin_weights;
  DeviceArray<KSkinTriangle> skin_triangles;
  DeviceArray<uint32_t> skin_adjacency;
  DeviceArray<KSkinFace> skin_faces;
  DeviceArray<KJoint> joints;
  DeviceArray<kuint> refit_scratch;
  cudaTextureObject_t texel_texture = 0;
  bool count_rays = false;
  // The bounce rays' wavefront (render_band.cu) instead of the megakernel, unless COHORT_CUDA_WAVEFRONT=0.
  bool wavefront = enabled_unless_zero("COHORT_CUDA_WAVEFRONT");
  // Its shadow rays walked by a kernel of their own, unless COHORT_CUDA_SHADOW_WALK=0 (the shading kernels
  // walk them as they come).
  bool shadow_walk = enabled_unless_zero("COHORT_CUDA_SHADOW_WALK");
  // The wavefront's scratch in slot `s` for a band of `pixels` rendered with `params`, or null for the
  // megakernel (also for frames the wavefront does not render: no scratch allocated for them).
  const WavefrontScratch* wave(BandSlot& s, size_t pixels, const KFrameParams& params) {
    if (!wavefront || !k_wavefront_renders(&params)) return nullptr;
    WavefrontScratch& w = s.wave_scratch;
    w = {};
    w.states = s.wave_states.scratch(pixels);
    w.hits = s.wave_hits.scratch(pixels);
    w.active = s.wave_active.scratch(pixels);
    w.lanes = &s.lanes;
    const KSceneView scene = view(s, params);
    const kuint slots = shadow_walk ? k_shadow_queue_slots(&params, scene.light_count, scene.emissive_count) : 0u;
    if (slots > 0u) {
      w.vertices = s.wave_vertices.scratch(pixels);
      w.shadow_rays = s.wave_shadow_rays.scratch(pixels * slots);
      w.shadow_slots = slots;
    }
    return &w;
  }
  static bool enabled_unless_zero(const char* variable) {
    const char* v = std::getenv(variable);
    return !(v && std::strcmp(v, "0") == 0);
  }
  RayCounts last_counts;
  // The targets the band is copied into, page-locked (cudaHostRegister) so that the copy is a true
  // asynchronous DMA on the tracer's stream instead of going through the driver's pageable staging
  // (about 3 ms of a 1080p frame otherwise). The Renderer alternates two targets by frame parity (the
  // pipeline), so the last two stay registered, with their auxiliary planes when they have them.
  HostRegistrations registered{4};
  // Bands left on this GPU for the frame's post-processing (BandJob::keep_on_device): three, so that the
  // post reads frame N's while N+1 and N+2 render into the others (with two frames in flight the pipeline
  // hands N+2 out as soon as N is merged, before N's post: core/frame_pipeline.h).
  struct KeptBand {
    DeviceArray<unsigned char> colour;
    DeviceArray<KAuxTexel> aux;
  };
  static constexpr int kKeptBands = 3;
  KeptBand kept[kKeptBands];
  int next_kept = 0;

  // Converts `pixels` of the float band, from frame pixel `first_pixel` on, to the packed `format` on the
  // slot's stream.
  static void pack_band(const BandSlot& s, core::BandFormat format, const float4* from, void* to, size_t pixels,
                        size_t first_pixel, kuint frame) {
    if (format == core::BandFormat::rgb16f)
      launch_band_to_rgb16f(from, static_cast<unsigned short*>(to), pixels, s.stream);
    else
      launch_band_to_rgb9e5(from, static_cast<unsigned*>(to), pixels, unsigned(first_pixel), frame, s.stream);
  }
  // The slot's device storage for a band of `pixels` in `rows`, grown as bands grow, and the band's ray
  // counters cleared on its stream.
  void prepare_band(BandSlot& s, size_t pixels, size_t rows, bool packed) {
    if (pixels > s.band_capacity) {
      if (s.band) COHORT_CUDA(cudaFree(s.band));
      if (s.band_packed) COHORT_CUDA(cudaFree(s.band_packed));
      s.band_packed = nullptr;
      COHORT_CUDA(cudaMalloc(&s.band, pixels * sizeof(float4)));
      s.band_capacity = pixels;
    }
    // Room for the larger packed format (6 bytes a pixel), so a change of format needs no reallocation.
    if (packed && !s.band_packed)
      COHORT_CUDA(cudaMalloc(&s.band_packed, s.band_capacity * core::bytes_per_pixel(core::BandFormat::rgb16f)));
    if (rows > s.device_row_rays_capacity) {
      if (s.device_row_rays) COHORT_CUDA(cudaFree(s.device_row_rays));
      COHORT_CUDA(cudaMalloc(&s.device_row_rays, rows * sizeof(unsigned)));
      s.device_row_rays_capacity = rows;
    }
    COHORT_CUDA(cudaMemsetAsync(s.device_row_rays, 0, rows * sizeof(unsigned), s.stream));
    if (count_rays) {
      if (!s.ray_counts) COHORT_CUDA(cudaMalloc(&s.ray_counts, 2 * sizeof(unsigned long long)));
      COHORT_CUDA(cudaMemsetAsync(s.ray_counts, 0, 2 * sizeof(unsigned long long), s.stream));
    }
  }

  // Band `b` of `rows` rows in the next slot: the slot's storage grown for it and its scene arrays brought up to
  // date.
  BandSlot& open_band(EnqueuedBand& b, const commit::TracerScene& scene, size_t pixels, size_t rows, bool packed) {
    b.rows = rows;
    b.slot = &take_slot();
    prepare_band(*b.slot, pixels, rows, packed);
    refresh_slot_scene(*b.slot, scene);
    return *b.slot;
  }
  // The next band's slot. Its band before in that slot has ended: at most two bands are in flight (the
  // current one and the one enqueued ahead), and each is finished before its slot comes round again.
  BandSlot& take_slot() {
    BandSlot& s = slots[next_slot];
    next_slot ^= 1;
    return s;
  }
  // The slot's stream waits for the band enqueued before it: for its lanes' release points (band overlap) or,
  // with `whole` or when it recorded none, for its kernels' end. Then the slot becomes the band before.
  void follow_band_before(BandSlot& s, bool whole) {
    BandSlot* before = band_before;
    band_before = &s;
    if (!before || before == &s) return;
    if (whole || before->released_lanes == 0) {
      COHORT_CUDA(cudaStreamWaitEvent(s.stream, before->stop, 0));
      return;
    }
    for (int lane = 0; lane < before->released_lanes; ++lane)
      COHORT_CUDA(cudaStreamWaitEvent(s.stream, before->lanes.released[lane], 0));
    ++overlapping;
  }
  // The band's end on the stream: its counters copied into the slot's page-locked memory behind its way
  // back, then the slot's `counted`.
  void end_band(BandSlot& s, size_t rows) {
    if (rows > s.row_rays_capacity) {
      if (s.row_rays) COHORT_CUDA(cudaFreeHost(s.row_rays));
      s.row_rays = nullptr;
      COHORT_CUDA(cudaMallocHost(&s.row_rays, rows * sizeof(unsigned)));
      s.row_rays_capacity = rows;
    }
    if (!s.counts) COHORT_CUDA(cudaMallocHost(&s.counts, 2 * sizeof(unsigned long long)));
    COHORT_CUDA(cudaEventRecord(s.finished, s.stream));  // the band's way back (after `stop`) is queued before this
    COHORT_CUDA(
        cudaMemcpyAsync(s.row_rays, s.device_row_rays, rows * sizeof(unsigned), cudaMemcpyDeviceToHost, s.stream));
    if (count_rays)
      COHORT_CUDA(
          cudaMemcpyAsync(s.counts, s.ray_counts, 2 * sizeof(unsigned long long), cudaMemcpyDeviceToHost, s.stream));
    COHORT_CUDA(cudaEventRecord(s.counted, s.stream));
  }
  // Waits for the band (with wait_aux_copy, its aux texels' copy too): the ray totals kept, and the kernels'
  // device time, its way back and the per-row work in the result.
  core::BandResult finish_band(const EnqueuedBand& b) {
    BandSlot& s = *b.slot;
    COHORT_CUDA(b.wait());
    last_counts = count_rays ? RayCounts{s.counts[0], s.counts[1]} : RayCounts{};
    float kernel_ms = 0.0f;
    COHORT_CUDA(cudaEventElapsedTime(&kernel_ms, s.start, s.stop));
    float transfer_ms = 0.0f;
    COHORT_CUDA(cudaEventElapsedTime(&transfer_ms, s.stop, s.finished));
    core::BandResult result;
    result.device_ms = kernel_ms;
    result.transfer_ms = transfer_ms;
    result.row_work.assign(s.row_rays, s.row_rays + b.rows);
    if (b.kept) result.device = *b.kept;
    return result;
  }

  void register_target(core::BandBuffer& target) {
    registered.ensure(target.data(), target.bytes(), "a band target");
    if (target.has_aux()) registered.ensure(target.aux_data(), target.aux_bytes(), "a band target's aux texels");
  }
  // Whether register_target would change nothing.
  bool target_registered(core::BandBuffer& target) const {
    return registered.contains(target.data(), target.bytes()) &&
           (!target.has_aux() || registered.contains(target.aux_data(), target.aux_bytes()));
  }

  void rebind_texel_texture() {
    if (texel_texture) COHORT_CUDA(cudaDestroyTextureObject(texel_texture));
    cudaResourceDesc res{};
    res.resType = cudaResourceTypeLinear;
    res.res.linear.devPtr = texels.data();
    res.res.linear.desc = cudaCreateChannelDesc<unsigned int>();
    res.res.linear.sizeInBytes = texels.size() * sizeof(uint32_t);
    cudaTextureDesc tex{};
    tex.readMode = cudaReadModeElementType;
    COHORT_CUDA(cudaCreateTextureObject(&texel_texture, &res, &tex, nullptr));
    set_texel_texture(texel_texture);
  }

  // The scene as slot `s`'s bands see it: the shared arrays and the slot's own.
  KSceneView view(const BandSlot& s, const KFrameParams& params) const {
    const SlotScene& own = s.scene;
    KSceneView v = k_scene_view(vertices.data(), vertex_colors.data(), triangles.data(), blas_nodes.data(), blases.data(),
                                own.instances.data(), own.tlas_nodes.data(), own.materials.data(), textures.data(),
                                texels.data(), own.lights.data(), own.light_nodes.data(), own.emissive.data(), &params);
    v.triangle_edges = triangle_edges.data();
    return v;
  }
  // Slot `s`'s arrays made those of `scene` on its stream, where a commit changed them since. The band before
  // in this slot has ended (take_slot); the host's arrays may change once this returns (copies from pageable
  // memory are staged before cudaMemcpyAsync returns).
  void refresh_slot_scene(BandSlot& s, const commit::TracerScene& scene) {
    SlotScene& own = s.scene;
    auto refresh = [&](SlotArray which, auto& array, const auto& host) {
      if (own.versions[which] == slot_array_versions[which]) return;
      array.upload(host, 0, s.stream);
      own.versions[which] = slot_array_versions[which];
    };
    refresh(kInstances, own.instances, scene.instances);
    refresh(kTlasNodes, own.tlas_nodes, scene.tlas_nodes);
    refresh(kMaterials, own.materials, scene.materials);
    refresh(kLights, own.lights, scene.lights);
    refresh(kLightNodes, own.light_nodes, scene.light_nodes);
    refresh(kEmissive, own.emissive, scene.emissive_triangles);
  }
};

namespace {

// COHORT_CUDA_WAVE_LANES: how many lanes of rows the wavefront runs a band in (1 to kMaxWaveLanes; default 2).
int wave_lanes_from_environment() {
  const char* v = std::getenv("COHORT_CUDA_WAVE_LANES");
  if (!v || !*v) return 2;
  char* end = nullptr;
  const long lanes = std::strtol(v, &end, 10);
  if (*end != '\0' || lanes < 1 || lanes > kMaxWaveLanes)
    throw std::invalid_argument(std::string("COHORT_CUDA_WAVE_LANES=") + v + ": expected 1 to " +
                                std::to_string(kMaxWaveLanes));
  return static_cast<int>(lanes);
}

// COHORT_CUDA_BAND_OVERLAP: CudaTracer::set_band_overlap's kernels (0 to 64; default kDefaultBandOverlap).
constexpr int kDefaultBandOverlap = 2;
int band_overlap_from_environment() {
  const char* v = std::getenv("COHORT_CUDA_BAND_OVERLAP");
  if (!v || !*v) return kDefaultBandOverlap;
  char* end = nullptr;
  const long kernels = std::strtol(v, &end, 10);
  if (*end != '\0' || kernels < 0 || kernels > 64)
    throw std::invalid_argument(std::string("COHORT_CUDA_BAND_OVERLAP=") + v + ": expected 0 to 64 kernels");
  return static_cast<int>(kernels);
}

}  // namespace

CudaTracer::CudaTracer(int device) : impl_(std::make_unique<Impl>()) {
  const int count = cuda_device_count();
  if (device < 0 || device >= count)
    throw std::runtime_error("CUDA device " + std::to_string(device) + " does not exist (" + std::to_string(count) +
                             " found)");
  impl_->device = device;
  impl_->name = "cuda:" + std::to_string(device) + " (" + cuda_device_name(device) + ")";
  COHORT_CUDA(cudaSetDevice(device));
  COHORT_CUDA(cudaStreamCreateWithFlags(&impl_->stream, cudaStreamNonBlocking));
  COHORT_CUDA(cudaStreamCreateWithFlags(&impl_->aux_copy_stream, cudaStreamNonBlocking));
  COHORT_CUDA(cudaStreamCreateWithFlags(&impl_->signal_stream, cudaStreamNonBlocking));
  for (BandSlot& s : impl_->slots) {
    COHORT_CUDA(cudaStreamCreateWithFlags(&s.stream, cudaStreamNonBlocking));
    COHORT_CUDA(cudaEventCreateWithFlags(&s.lanes.forked, cudaEventDisableTiming));
    COHORT_CUDA(cudaEventCreate(&s.start));
    COHORT_CUDA(cudaEventCreate(&s.stop));
    COHORT_CUDA(cudaEventCreate(&s.finished));
    COHORT_CUDA(cudaEventCreateWithFlags(&s.counted, cudaEventDisableTiming));
    COHORT_CUDA(cudaEventCreateWithFlags(&s.aux_copied, cudaEventDisableTiming));
  }
  COHORT_CUDA(cudaEventCreateWithFlags(&impl_->aux_ready, cudaEventDisableTiming));
  set_wave_lanes(wave_lanes_from_environment());
  set_band_overlap(band_overlap_from_environment());
}

CudaTracer::~CudaTracer() {
  cudaSetDevice(impl_->device);
  // A band enqueued ahead whose job never came writes into its target until it ends.
  if (impl_->ahead) impl_->ahead->wait();
  if (impl_->texel_texture) cudaDestroyTextureObject(impl_->texel_texture);
  for (const BandSlot& s : impl_->slots) {
    if (s.stream) cudaStreamSynchronize(s.stream);
    for (cudaEvent_t e : {s.start, s.stop, s.finished, s.counted, s.aux_copied})
      if (e) cudaEventDestroy(e);
    if (s.row_rays) cudaFreeHost(s.row_rays);
    if (s.counts) cudaFreeHost(s.counts);
    for (void* p : {static_cast<void*>(s.band), static_cast<void*>(s.band_packed), static_cast<void*>(s.device_row_rays),
                    static_cast<void*>(s.ray_counts)})
      if (p) cudaFree(p);
    const WaveLanes& lanes = s.lanes;
    if (lanes.forked) cudaEventDestroy(lanes.forked);
    for (int lane = 0; lane < kMaxWaveLanes; ++lane) {
      if (lanes.streams[lane]) cudaStreamDestroy(lanes.streams[lane]);
      if (lanes.joined[lane]) cudaEventDestroy(lanes.joined[lane]);
      if (lanes.released[lane]) cudaEventDestroy(lanes.released[lane]);
    }
    if (s.stream) cudaStreamDestroy(s.stream);
  }
  if (impl_->aux_ready) cudaEventDestroy(impl_->aux_ready);
  for (cudaEvent_t e : impl_->piece_rendered) cudaEventDestroy(e);
  for (cudaEvent_t e : impl_->piece_downloaded) cudaEventDestroy(e);
  if (impl_->stream) cudaStreamDestroy(impl_->stream);
  if (impl_->signal_stream) cudaStreamDestroy(impl_->signal_stream);
  if (impl_->aux_copy_stream) cudaStreamDestroy(impl_->aux_copy_stream);
}

std::string CudaTracer::name() const { return impl_->name; }

void CudaTracer::upload(const commit::ChangeSet& changes) {
  Impl& m = *impl_;
  COHORT_CUDA(cudaSetDevice(m.device));
  const commit::TracerScene& scene = this->scene();
  const bool all = changes.full_resync;
  // The slots' own arrays: each slot uploads them as its next band is enqueued (Impl::refresh_slot_scene).
  auto changed = [&](SlotArray which, bool flag) {
    if (all || flag) ++m.slot_array_versions[which];
  };
  changed(kInstances, changes.instances || changes.tlas);
  changed(kTlasNodes, changes.instances || changes.tlas);
  changed(kMaterials, changes.materials);
  changed(kLights, changes.lights);
  changed(kLightNodes, changes.light_tree);
  changed(kEmissive, changes.emissive);
  const bool shared = all || changes.geometry || changes.textures || changes.skin_data || !changes.posed_skins.empty();
  if (!shared) return;
  cudaStream_t s = m.stream;
  // The shared arrays change under every band: copies and kernels on this stream wait for the kernels of both
  // slots' bands (applied ahead, the band before may still run; a grown array's cudaFree waits for the
  // device), and a new texel texture (its object destroyed, the kernels' constant rewritten) waits for them on
  // the host first. The host waits for the uploads at the end, so bands enqueued after this need not.
  for (const BandSlot& slot : m.slots) COHORT_CUDA(cudaStreamWaitEvent(s, slot.stop, 0));
  if (m.applying_ahead && (all || changes.textures)) COHORT_CUDA(cudaStreamSynchronize(s));
  if (all || changes.geometry) {
    // Appended BLASes upload only their new tail; anything else re-sends the array.
    m.vertices.upload(scene.vertices, all ? 0 : changes.vertices_from, s);
    m.vertex_colors.upload(scene.vertex_colors, all ? 0 : changes.vertices_from, s);
    m.triangles.upload(scene.triangles, all ? 0 : changes.triangles_from, s);
    m.blas_nodes.upload(scene.blas_nodes, all ? 0 : changes.blas_nodes_from, s);
    m.blases.upload(scene.blases, all ? 0 : changes.blases_from, s);
    // Every triangle's edges again: one short kernel (a changed vertex may belong to any earlier triangle).
    launch_triangle_edges(m.triangle_edges.scratch(scene.triangles.size()), m.triangles.data(), m.vertices.data(), 0,
                          scene.triangles.size(), s);
  }
  if (all || changes.textures) {
    m.textures.upload(scene.textures, 0, s);
    // A texture object needs storage: a scene without texels binds one unused white texel instead.
    static const std::vector<uint32_t> one_white_texel{0xffffffffu};
    m.texels.upload(scene.texels.empty() ? one_white_texel : scene.texels, 0, s);
    m.rebind_texel_texture();
  }
  if (all || changes.skin_data) {
    m.skins.upload(scene.skins, 0, s);
    m.skin_vertices.upload(scene.skin_vertices, 0, s);
    m.skin_weights.upload(scene.skin_weights, 0, s);
    m.skin_triangles.upload(scene.skin_triangles, 0, s);
    m.skin_adjacency.upload(scene.skin_adjacency, 0, s);
    m.skin_faces.upload(scene.skin_faces, 0, s);   // sized here, written by the kernels
  }
  if (all || !changes.posed_skins.empty()) m.joints.upload(scene.joints, 0, s);
  // The host copy keeps only the joints: after vertices came from it every skin runs again, otherwise
  // only those whose joints changed.
  std::vector<uint32_t> to_pose = changes.posed_skins;
  if (all || changes.geometry) {
    to_pose.resize(scene.skins.size());
    for (size_t i = 0; i < to_pose.size(); ++i) to_pose[i] = uint32_t(i);
  }
  size_t most_nodes = 0;
  for (uint32_t index : to_pose)
    if (index < scene.skins.size() && scene.skins[index].blas < scene.blases.size())
      most_nodes = std::max<size_t>(most_nodes, scene.blases[scene.skins[index].blas].node_count);
  kuint* scratch = most_nodes ? m.refit_scratch.scratch(2 * most_nodes) : nullptr;
  const RefitScratch refit{scratch, scratch + most_nodes};
  for (uint32_t index : to_pose) {
    if (index >= scene.skins.size()) continue;
    const KSkin& skin = scene.skins[index];
    if (size_t(skin.joint_offset) + skin.joint_count > scene.joints.size() || skin.blas >= scene.blases.size()) continue;
    const SkinBuffers pools{m.skin_vertices.data(), m.skin_weights.data(), m.skin_triangles.data(),
                            m.skin_adjacency.data(), m.skin_faces.data(), m.joints.data()};
    launch_skinning(m.vertices.data(), pools, skin, m.blas_nodes.data(), m.triangles.data(),
                    m.triangle_edges.data(), scene.blases[skin.blas], refit, s);
  }
  COHORT_CUDA(cudaStreamSynchronize(s));
}

namespace {

// The driver runs it once a band is back (cudaLaunchHostFunc).
void CUDART_CB band_back(void* user) { BandSignal::fire_and_release(user); }

}  // namespace

core::BandResult CudaTracer::render_band(const core::BandJob& job, core::BandBuffer& target) {
  Impl& m = *impl_;
  COHORT_CUDA(cudaSetDevice(m.device));
  if (!has_scene()) throw std::runtime_error(m.name + ": render_band before any commit was applied");
  using Clock = std::chrono::steady_clock;
  std::optional<EnqueuedBand> band;
  if (m.ahead) {
    if (m.ahead->target == &target && same_band_job(m.ahead->job, job)) {
      band = std::move(m.ahead);
      m.ahead.reset();
      ++m.finished_ahead;
    } else {
      drop_enqueued_ahead();
    }
  }
  const bool went_ahead = band.has_value();
  if (!band) band = enqueue_band(job, target);
  if (band->rows == 0) return {};
  const auto enqueued = Clock::now();
  try {
    enqueue_next_ahead(*band);
  } catch (...) {
    band->wait();  // nothing of this band may still be landing in the target once it is given up
    throw;
  }
  core::BandResult result = m.finish_band(*band);
  // A band that could not go ahead (its job came after the band before had ended) costs the balancer its wall
  // time less its enqueueing, as a band that went ahead does. Else a GPU whose bands end before the frame's
  // slowest one gets its jobs too late to go ahead, looks slower by its enqueueing, keeps fewer rows and so
  // keeps ending early: the OpenCL tracer's late-job cost (nvidia-h100-x4, four GPUs, without it: in one of two
  // runs a GPU fell to half an even share or less, the sit-out trial benched it, 0.98 ms a frame against 0.70).
  if (m.enqueue_ahead && !went_ahead && m.enqueued_ahead.load() > 0)
    result.balance_ms = std::max(1e-3, std::chrono::duration<double, std::milli>(Clock::now() - enqueued).count());
  return result;
}

CudaTracer::EnqueuedBand CudaTracer::enqueue_band(const core::BandJob& job, core::BandBuffer& target) {
  Impl& m = *impl_;
  EnqueuedBand b;
  b.job = job;
  b.target = &target;
  const KFrameParams params = frame_params(job);
  const KCamera& camera = job.camera;
  if (params.row_end <= params.row_begin) return b;
  if (camera.width != kuint(target.width()) || params.row_end > kuint(target.height()))
    throw std::invalid_argument(m.name + ": band does not fit the frame buffer");
  const size_t pixels = size_t(camera.width) * (params.row_end - params.row_begin);
  const bool packed = target.format() != core::BandFormat::rgba32f;
  const size_t rows = params.row_end - params.row_begin;
  BandSlot& slot = m.open_band(b, scene(), pixels, rows, packed);
  const cudaStream_t stream = slot.stream;
  // Kept on the GPU, the band skips both copies: nothing goes down, and the post-processing takes it
  // device to device (or over NVLink from a peer).
  Impl::KeptBand* kept = job.keep_on_device >= 0 ? &m.kept[m.next_kept] : nullptr;
  if (kept) m.next_kept = (m.next_kept + 1) % Impl::kKeptBands;
  else m.register_target(target);
  const bool write_aux = params.aux_outputs != 0u && target.has_aux();
  // Copies from pageable memory may wait for the stream: before it waits for the band before.
  if (write_aux) {
    slot.previous_transforms.upload(previous_transforms(), 0, stream);
    slot.previous_joints.upload(previous_joints(), 0, stream);
  }
  m.follow_band_before(slot, false);
  COHORT_CUDA(cudaEventRecord(slot.start, stream));
  const bool aux_from_paths = write_aux && k_aux_from_paths(&params);
  KAuxHistory history{};
  KAuxTexel* texels = nullptr;
  const KCamera previous = job.previous_camera.width > 0 ? job.previous_camera : camera;
  // The planes go down on the copy engine while the next kernel runs (after the band, on its stream,
  // they added 2.2 ms to a 1080p frame on an H100).
  auto download_aux = [&] {
    COHORT_CUDA(cudaEventRecord(m.aux_ready, stream));
    COHORT_CUDA(cudaStreamWaitEvent(m.aux_copy_stream, m.aux_ready, 0));
    COHORT_CUDA(cudaMemcpyAsync(target.aux_row(int(params.row_begin)), texels, pixels * sizeof(KAuxTexel),
                                cudaMemcpyDeviceToHost, m.aux_copy_stream));
    COHORT_CUDA(cudaEventRecord(slot.aux_copied, m.aux_copy_stream));
  };
  if (write_aux) {
    history.object_to_world = previous_transforms().empty() ? nullptr : slot.previous_transforms.data();
    history.skins = m.skins.data();
    history.skin_vertices = m.skin_vertices.data();
    history.skin_weights = m.skin_weights.data();
    history.joints = previous_joints().empty() ? nullptr : slot.previous_joints.data();
    history.skin_count = static_cast<kuint>(scene().skins.size());
    // The slot's texels: the band before in this slot, whose copy went down from them, has ended (take_slot).
    texels = kept ? kept->aux.scratch(pixels) : slot.aux_texels.scratch(pixels);
    // Centre rays: a short kernel of their own before the band's, whose texels go down while it runs.
    if (!aux_from_paths) {
      launch_aux_band(m.view(slot, params), params, camera, previous, history, texels, stream);
      if (!kept) download_aux();
    }
  }
  KPathFirstHit* first_hits = aux_from_paths ? slot.first_hits.scratch(pixels) : nullptr;
  slot.released_lanes = launch_render_band(m.view(slot, params), params, camera, slot.band,
                                           m.count_rays ? slot.ray_counts : nullptr, slot.device_row_rays, first_hits,
                                           m.wave(slot, pixels, params), stream);
  if (aux_from_paths) {
    // From the paths' first hits: after the band's kernel, no ray of their own (counted in the band's time).
    launch_aux_from_first_hits(m.view(slot, params), params, camera, previous, history, first_hits, texels, stream);
    if (!kept) download_aux();
  }
  COHORT_CUDA(cudaEventRecord(slot.stop, stream));
  // The band's rows are contiguous in the target: one copy straight into place, in its format.
  const size_t colour_bytes = pixels * core::bytes_per_pixel(target.format());
  const void* source = slot.band;
  if (packed) {
    void* to = kept ? static_cast<void*>(kept->colour.scratch(colour_bytes)) : slot.band_packed;
    Impl::pack_band(slot, target.format(), slot.band, to, pixels, size_t(params.row_begin) * camera.width,
                    params.frame_index);
    source = to;
  } else if (kept) {
    COHORT_CUDA(cudaMemcpyAsync(kept->colour.scratch(colour_bytes), slot.band, colour_bytes, cudaMemcpyDeviceToDevice,
                                stream));
    source = kept->colour.data();
  }
  if (!kept)
    COHORT_CUDA(cudaMemcpyAsync(target.row(int(params.row_begin)), source, colour_bytes, cudaMemcpyDeviceToHost, stream));
  m.end_band(slot, rows);
  b.wait_aux_copy = write_aux && !kept;
  if (kept) b.kept = core::DeviceBand{m.device, source, write_aux ? kept->aux.data() : nullptr};
  return b;
}

void CudaTracer::enqueue_next_ahead(const EnqueuedBand& current) {
  Impl& m = *impl_;
  if (!m.enqueue_ahead || m.ahead) return;
  // The worker waits for the next job until the current band is back: a host function the driver runs then
  // wakes it (it also looks at the band's event every millisecond).
  auto signal = std::make_shared<BandSignal>();
  signal->tracer = this;
  void* user = BandSignal::callback_argument(signal);
  if (cudaStreamWaitEvent(m.signal_stream, current.slot->counted, 0) != cudaSuccess ||
      cudaLaunchHostFunc(m.signal_stream, band_back, user) != cudaSuccess) {
    cudaGetLastError();
    BandSignal::release(user);
  }
  const DisarmOnExit disarm{*signal};
  const BandDone band_done = [&] { return signal->done.load() || current.ended(); };
  // The next job's commit is applied inside queued_next, on this thread, while the current band runs
  // (upload() knows: what cannot wait in the stream's order waits for the band first).
  std::optional<QueuedNext> next;
  {
    const FlagForScope applying(m.applying_ahead);
    next = queued_next(band_done);
  }
  if (!next) return;
  // A target not yet page-locked: registering it may let go of the oldest registration, which the current
  // band may still be copying into; so the current band ends first.
  if (next->job.keep_on_device < 0 && !m.target_registered(*next->target)) COHORT_CUDA(current.wait());
  EnqueuedBand b = enqueue_band(next->job, *next->target);
  if (b.rows == 0) return;
  m.ahead = std::move(b);
  ++m.enqueued_ahead;
}

bool CudaTracer::enqueues_ahead() const { return impl_->enqueue_ahead; }

void CudaTracer::drop_enqueued_ahead() {
  Impl& m = *impl_;
  if (!m.ahead) return;
  COHORT_CUDA(m.ahead->wait());
  m.ahead.reset();
  ++m.dropped_ahead;
}

core::BandResult CudaTracer::render_band_in_pieces(const core::BandJob& job, core::BandBuffer& target,
                                                  const std::vector<int>& cuts, const std::function<void(size_t)>& ready) {
  Impl& m = *impl_;
  const bool write_aux = job.params.aux_outputs != 0u && target.has_aux();
  if (cuts.size() < 3 || write_aux) return core::Tracer::render_band_in_pieces(job, target, cuts, ready);
  COHORT_CUDA(cudaSetDevice(m.device));
  drop_enqueued_ahead();  // pieces are not enqueued ahead (a remote node's bands)
  if (!has_scene()) throw std::runtime_error(m.name + ": render_band before any commit was applied");
  const KFrameParams params = frame_params(job);
  const KCamera& camera = job.camera;
  if (cuts.front() != int(params.row_begin) || cuts.back() != int(params.row_end))
    throw std::invalid_argument(m.name + ": the pieces do not cover the band");
  for (size_t i = 0; i + 1 < cuts.size(); ++i)
    if (cuts[i + 1] < cuts[i]) throw std::invalid_argument(m.name + ": the pieces' rows are out of order");
  if (params.row_end <= params.row_begin) return {};
  if (camera.width != kuint(target.width()) || params.row_end > kuint(target.height()))
    throw std::invalid_argument(m.name + ": band does not fit the frame buffer");
  const size_t width = camera.width;
  const size_t rows = params.row_end - params.row_begin;
  const size_t pixels = width * rows;
  const bool packed = target.format() != core::BandFormat::rgba32f;
  EnqueuedBand b;
  b.job = job;
  b.target = &target;
  BandSlot& slot = m.open_band(b, scene(), pixels, rows, packed);
  const cudaStream_t stream = slot.stream;
  const size_t pieces = cuts.size() - 1;
  while (m.piece_rendered.size() < pieces) {
    cudaEvent_t rendered = nullptr, downloaded = nullptr;
    COHORT_CUDA(cudaEventCreateWithFlags(&rendered, cudaEventDisableTiming));
    m.piece_rendered.push_back(rendered);
    COHORT_CUDA(cudaEventCreateWithFlags(&downloaded, cudaEventDisableTiming));
    m.piece_downloaded.push_back(downloaded);
  }
  m.register_target(target);
  // Each piece renders (and converts) into its own part of the band's device buffers, so a piece's
  // download never races the next piece's kernel: the copy stream takes piece i while `stream` runs
  // piece i + 1.
  const size_t pixel_bytes = core::bytes_per_pixel(target.format());
  const WavefrontScratch* wave = m.wave(slot, pixels, params);  // the pieces take turns with it on `stream`
  m.follow_band_before(slot, true);
  COHORT_CUDA(cudaEventRecord(slot.start, stream));
  for (size_t i = 0; i < pieces; ++i) {
    KFrameParams piece = params;
    piece.row_begin = kuint(cuts[i]);
    piece.row_end = kuint(cuts[i + 1]);
    const size_t first_row = size_t(cuts[i]) - params.row_begin;
    const size_t piece_pixels = width * size_t(cuts[i + 1] - cuts[i]);
    float4* band = slot.band + first_row * width;
    if (piece_pixels > 0)
      launch_render_band(m.view(slot, piece), piece, camera, band, m.count_rays ? slot.ray_counts : nullptr,
                         slot.device_row_rays + first_row, nullptr, wave, stream);
    const void* source = band;
    if (packed) {
      void* to = slot.band_packed + first_row * width * pixel_bytes;
      if (piece_pixels > 0)
        Impl::pack_band(slot, target.format(), band, to, piece_pixels, size_t(cuts[i]) * width, params.frame_index);
      source = to;
    }
    COHORT_CUDA(cudaEventRecord(m.piece_rendered[i], stream));
    COHORT_CUDA(cudaStreamWaitEvent(m.aux_copy_stream, m.piece_rendered[i], 0));
    if (piece_pixels > 0)
      COHORT_CUDA(cudaMemcpyAsync(target.row(cuts[i]), source, piece_pixels * pixel_bytes, cudaMemcpyDeviceToHost,
                                  m.aux_copy_stream));
    COHORT_CUDA(cudaEventRecord(m.piece_downloaded[i], m.aux_copy_stream));
  }
  slot.released_lanes = 0;  // the next band follows the whole band (its last piece's release is not the band's)
  COHORT_CUDA(cudaEventRecord(slot.stop, stream));
  m.end_band(slot, rows);
  try {
    for (size_t i = 0; i < pieces; ++i) {
      COHORT_CUDA(cudaEventSynchronize(m.piece_downloaded[i]));
      ready(i);
    }
  } catch (...) {
    // Nothing of this band may still be landing in the target once it is given up.
    cudaStreamSynchronize(stream);
    cudaStreamSynchronize(m.aux_copy_stream);
    throw;
  }
  return m.finish_band(b);
}

void CudaTracer::set_ray_counting(bool on) { impl_->count_rays = on; }
void CudaTracer::set_wavefront(bool on) { impl_->wavefront = on; }
void CudaTracer::set_shadow_walk(bool on) { impl_->shadow_walk = on; }
void CudaTracer::set_enqueue_ahead(bool on) {
  if (!on) drop_enqueued_ahead();
  impl_->enqueue_ahead = on;
}
size_t CudaTracer::bands_enqueued_ahead() const { return impl_->enqueued_ahead.load(); }
size_t CudaTracer::bands_finished_ahead() const { return impl_->finished_ahead.load(); }
size_t CudaTracer::bands_dropped_ahead() const { return impl_->dropped_ahead.load(); }
void CudaTracer::set_wave_lanes(int lanes) {
  if (lanes < 1 || lanes > kMaxWaveLanes)
    throw std::invalid_argument(impl_->name + ": wave lanes " + std::to_string(lanes) + " (expected 1 to " +
                                std::to_string(kMaxWaveLanes) + ")");
  COHORT_CUDA(cudaSetDevice(impl_->device));
  for (BandSlot& s : impl_->slots) {
    WaveLanes& w = s.lanes;
    for (int lane = 0; lane < lanes; ++lane) {  // made once, kept for later counts (lane 0 runs on the slot's stream)
      if (lane > 0 && !w.streams[lane]) COHORT_CUDA(cudaStreamCreateWithFlags(&w.streams[lane], cudaStreamNonBlocking));
      if (lane > 0 && !w.joined[lane]) COHORT_CUDA(cudaEventCreateWithFlags(&w.joined[lane], cudaEventDisableTiming));
      if (!w.released[lane]) COHORT_CUDA(cudaEventCreateWithFlags(&w.released[lane], cudaEventDisableTiming));
    }
    w.count = lanes;
  }
}
void CudaTracer::set_band_overlap(int kernels) {
  if (kernels < 0) throw std::invalid_argument(impl_->name + ": band overlap of " + std::to_string(kernels) + " kernels");
  impl_->band_overlap = kernels;
  for (BandSlot& s : impl_->slots) s.lanes.release_before_end = kernels;
}
int CudaTracer::band_overlap() const { return impl_->band_overlap; }
size_t CudaTracer::bands_overlapping() const { return impl_->overlapping.load(); }
bool CudaTracer::shadow_walk() const { return impl_->shadow_walk; }
bool CudaTracer::wavefront() const { return impl_->wavefront; }
CudaTracer::RayCounts CudaTracer::last_ray_counts() const { return impl_->last_counts; }
int CudaTracer::device() const { return impl_->device; }

}  // namespace cohort::tracers
