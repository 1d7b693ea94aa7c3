#include "cohort/tracers/cuda_frame_post.h"

#include <algorithm>
#include <set>
#include <string>
#include <vector>

#include <cuda_fp16.h>
#include <cuda_runtime.h>

#include "cohort/kernel/atrous.h"
#include "cohort/kernel/band_pack.h"
#include "cohort/kernel/brigade_blend.h"
#include "cohort/kernel/firefly.h"
#include "cohort/kernel/reproject.h"
#include "cohort/kernel/svgf.h"
#include "cohort/kernel/upsample.h"
#include "cuda_check.h"
#include "device_array.h"
#include "host_registrations.h"

namespace cohort::tracers {

namespace {

constexpr unsigned kThreads = 256;

unsigned blocks_for(size_t n) { return static_cast<unsigned>((n + kThreads - 1) / kThreads); }

__global__ void prepare_kernel(const float* rgba, float* ycocgw, int pixels) {
  const int p = blockIdx.x * blockDim.x + threadIdx.x;
  if (p < pixels) k_reproject_prepare(rgba, ycocgw, p);
}

// With `demodulated` (the a-trous filter follows), the pixel's new history is also divided by its albedo
// into the filter's input while it is at hand, instead of a pass of its own.
__global__ void reproject_kernel(KReprojectParams params, KReprojectFresh fresh, KReprojectHistory history,
                                 KReprojectState next, double* length_sum, const float* albedo, float* demodulated) {
  const int p = blockIdx.x * blockDim.x + threadIdx.x;
  float length = 0.0f;
  if (p < params.width * params.height) {
    k_reproject_pixel(&params, &fresh, &history, &next, p % params.width, p / params.width);
    length = next.length[p];
    if (demodulated) k_atrous_modulate(next.rgba, albedo, demodulated, p, 0);
  }
  // The mean history length for stats, summed per warp then once per warp into one double.
  for (int offset = 16; offset > 0; offset /= 2) length += __shfl_down_sync(0xffffffffu, length, offset);
  if ((threadIdx.x & 31) == 0) atomicAdd(length_sum, static_cast<double>(length));
}

// The Renderer's packed merge unpacked on the device: the colour from RGB halves, RGB9E5 words or RGBA floats
// (colour_format: 1, 2, 0) and the
// aux texels (core/band_buffer.h, kernel/layout.h's KAuxTexel) into the float planes the passes read; with
// `ycocgw` and `geometry` (either may be null) also the reprojection's and the a-trous filter's own planes,
// while the pixel is at hand, instead of two more passes over the frame.
__global__ void unpack_kernel(const unsigned char* colour, int colour_format, const KAuxTexel* texels, float* rgba,
                              float* depth, float* prev_depth, float* motion, float* normal, float* albedo, kuint* id,
                              float* ycocgw, float* geometry, int pixels) {
  const int p = blockIdx.x * blockDim.x + threadIdx.x;
  if (p >= pixels) return;
  if (colour_format == 1) {
    const unsigned short* c = reinterpret_cast<const unsigned short*>(colour) + 3 * size_t(p);
    for (int k = 0; k < 3; ++k) rgba[4 * p + k] = __half2float(__ushort_as_half(c[k]));
    rgba[4 * p + 3] = 1.0f;
  } else if (colour_format == 2) {
    const kuint packed = reinterpret_cast<const kuint*>(colour)[p];
    for (kuint k = 0; k < 3; ++k) rgba[4 * p + k] = k_rgb9e5_channel(packed, k);
    rgba[4 * p + 3] = 1.0f;
  } else {
    reinterpret_cast<float4*>(rgba)[p] = reinterpret_cast<const float4*>(colour)[p];
  }
  if (!texels) return;  // Brigade's blend alone: the colour is all it reads
  const KAuxTexel t = texels[p];
  depth[p] = t.depth;
  prev_depth[p] = t.prev_depth;
  motion[2 * p] = t.motion[0];
  motion[2 * p + 1] = t.motion[1];
  for (int k = 0; k < 3; ++k) {
    normal[3 * p + k] = __half2float(__ushort_as_half(t.normal[k]));
    albedo[3 * p + k] = __half2float(__ushort_as_half(t.albedo[k]));
  }
  id[p] = t.id;
  if (ycocgw) k_reproject_prepare(rgba, ycocgw, p);
  if (geometry) k_atrous_pack_geometry(depth, normal, geometry, p);
}

__global__ void brigade_blend_kernel(float* accumulated, const float* fresh, float f, int pixels) {
  const int p = blockIdx.x * blockDim.x + threadIdx.x;
  if (p < pixels) k_brigade_blend_pixel(accumulated, fresh, f, p);
}

__global__ void modulate_kernel(const float* rgba, const float* albedo, float* out, int pixels, int multiply) {
  const int p = blockIdx.x * blockDim.x + threadIdx.x;
  if (p < pixels) k_atrous_modulate(rgba, albedo, out, p, multiply);
}

// The filter's kernels run on 16x16 tiles: a tap footprint reaches rows above and below, which a tile's
// neighbours in L1 share, where a row of 256 pixels shares only its own row.
dim3 tile_grid(int width, int height) { return dim3((width + 15) / 16, (height + 15) / 16); }
const dim3 kTile(16, 16);

// Dynamic resolution's reconstruction (kernel/upsample.h): the traced pixels' illumination, then every
// pixel's joint-bilateral mean of its traced neighbours, on tiles as the a-trous passes (a window of taps).
__global__ void upsample_demodulate_kernel(const float* rgba, const float* albedo, float* illumination,
                                           KUpsampleParams params) {
  const int x = blockIdx.x * blockDim.x + threadIdx.x, y = blockIdx.y * blockDim.y + threadIdx.y;
  if (x < params.width && y < params.height) k_upsample_demodulate_pixel(rgba, albedo, illumination, &params, x, y);
}

__global__ void upsample_kernel(const float* rgba, const float* illumination, const float* depth, const float* normal,
                                const float* albedo, const kuint* id, float* out, KUpsampleParams params, int method) {
  const int x = blockIdx.x * blockDim.x + threadIdx.x, y = blockIdx.y * blockDim.y + threadIdx.y;
  if (x < params.width && y < params.height)
    k_upsample_pixel(rgba, illumination, depth, normal, albedo, id, out, &params, method, x, y);
}

__global__ void pack_geometry_kernel(const float* depth, const float* normal, float* geometry, int pixels) {
  const int p = blockIdx.x * blockDim.x + threadIdx.x;
  if (p < pixels) k_atrous_pack_geometry(depth, normal, geometry, p);
}

__global__ void atrous_kernel(const float* in, float* out, const float* geometry, KAtrousParams params) {
  const int x = blockIdx.x * blockDim.x + threadIdx.x, y = blockIdx.y * blockDim.y + threadIdx.y;
  if (x < params.width && y < params.height) k_atrous_pixel(in, out, geometry, &params, x, y);
}

__global__ void firefly_kernel(const float* in, float* out, int width, int height, float factor) {
  const int x = blockIdx.x * blockDim.x + threadIdx.x, y = blockIdx.y * blockDim.y + threadIdx.y;
  if (x < width && y < height) k_firefly_clamp_pixel(in, out, width, height, factor, x, y);
}

// The estimate goes into the illumination's alpha, where the passes read it: each pixel writes only its
// own alpha and reads only its neighbours' RGB. A pixel with a long history reads its own moments; the
// warp's pixels with short ones (a few along edges and disocclusions) then take their 7x7 neighbourhood
// estimates one after the other, each spread over the warp's 32 lanes (a tap or two a lane, the sums
// added across the warp), where a thread of its own would walk all 49 taps while the rest of its warp
// waited (the kernel's cost before: docs/denoising.md). Same taps, summed in another order.
__global__ void svgf_variance_kernel(float* illumination, const float* moments, const float* length,
                                     const float* geometry, KSvgfVarianceParams params) {
  const int x = blockIdx.x * blockDim.x + threadIdx.x, y = blockIdx.y * blockDim.y + threadIdx.y;
  const bool inside = x < params.width && y < params.height;
  const bool spatial = inside && k_svgf_variance_is_spatial(length, &params, x, y);
  if (inside && !spatial)
    illumination[4 * (y * params.width + x) + 3] = k_svgf_temporal_variance(moments, length, &params, x, y);
  constexpr unsigned kWarp = 0xffffffffu;
  constexpr int kSide = 2 * K_SVGF_SPATIAL_RADIUS + 1;
  const int lane = int(threadIdx.y * blockDim.x + threadIdx.x) & 31;
  for (unsigned pending = __ballot_sync(kWarp, spatial); pending != 0u; pending &= pending - 1u) {
    const int owner = __ffs(pending) - 1;
    const int px = __shfl_sync(kWarp, x, owner), py = __shfl_sync(kWarp, y, owner);
    KSvgfNeighbourhood n = k_svgf_neighbourhood_begin(geometry, &params, px, py);
    for (int tap = lane; tap < kSide * kSide; tap += 32)
      k_svgf_neighbourhood_tap(&n, illumination, moments, length, geometry, &params, tap % kSide - K_SVGF_SPATIAL_RADIUS,
                               tap / kSide - K_SVGF_SPATIAL_RADIUS);
    for (int offset = 16; offset > 0; offset /= 2) {
      n.s1 += __shfl_xor_sync(kWarp, n.s1, offset);
      n.s2 += __shfl_xor_sync(kWarp, n.s2, offset);
      n.weight_sum += __shfl_xor_sync(kWarp, n.weight_sum, offset);
    }
    if (lane == owner)
      illumination[4 * (py * params.width + px) + 3] = k_svgf_neighbourhood_variance(&n, length, &params);
  }
}

__global__ void history_fix_kernel(const float* in, float* out, const float* geometry, const kuint* id,
                                   const float* length, KHistoryFixParams params) {
  const int x = blockIdx.x * blockDim.x + threadIdx.x, y = blockIdx.y * blockDim.y + threadIdx.y;
  if (x < params.width && y < params.height) k_svgf_history_fix_pixel(in, out, geometry, id, length, &params, x, y);
}

// With `modulated` (the last pass), the filtered pixel is also multiplied by its albedo into the shown image.
__global__ void svgf_atrous_kernel(const float* in, float* out, const float* geometry, KAtrousParams params,
                                   const float* albedo, float* modulated) {
  const int x = blockIdx.x * blockDim.x + threadIdx.x, y = blockIdx.y * blockDim.y + threadIdx.y;
  if (x < params.width && y < params.height) {
    k_svgf_atrous_pixel(in, out, geometry, &params, x, y);
    if (modulated) k_atrous_modulate(out, albedo, modulated, y * params.width + x, 1);
  }
}

class CudaFramePost final : public core::FramePost {
 public:
  CudaFramePost(int device, const core::FramePostOptions& options)
      : device_(device), options_(core::with_history_moments(options)) {
    int count = 0;
    if (cudaGetDeviceCount(&count) != cudaSuccess || device < 0 || device >= count) {
      cudaGetLastError();
      throw std::runtime_error("frame post on cuda:" + std::to_string(device) + ": no such CUDA device (" +
                               std::to_string(count) + " found)");
    }
    core::check_post_options(options_);
    COHORT_CUDA(cudaSetDevice(device_));
    // The highest stream priority: the passes run while the same GPU renders the next frame, and would
    // otherwise wait behind the render kernel's blocks (measured: 9.6 ms of passes at 1080p on an H100).
    int least = 0, greatest = 0;
    COHORT_CUDA(cudaDeviceGetStreamPriorityRange(&least, &greatest));
    COHORT_CUDA(cudaStreamCreateWithPriority(&stream_, cudaStreamNonBlocking, greatest));
    COHORT_CUDA(cudaMallocHost(&length_sum_host_, sizeof(double)));
    for (cudaEvent_t& e : events_) COHORT_CUDA(cudaEventCreate(&e));
    if (options_.atrous) normal_squarings_ = core::atrous_normal_squarings(options_.atrous_options.normal_power);
  }
  ~CudaFramePost() override {
    cudaSetDevice(device_);
    cudaStreamSynchronize(stream_);
    if (shown_registered_) cudaHostUnregister(shown_registered_);
    cudaFreeHost(length_sum_host_);
    for (cudaEvent_t e : events_) cudaEventDestroy(e);
    cudaStreamDestroy(stream_);
  }

  void process(const core::FrameBuffer& fresh, const core::GBuffer& g, const core::PathPattern& traced) override {
    const bool needs_gbuffer = options_.reproject || options_.atrous || traced.sparse();
    if (needs_gbuffer && (g.width != fresh.width || g.height != fresh.height))
      throw std::invalid_argument("CudaFramePost: the G-buffer's size differs from the frame's");
    core::check_traced_pattern(options_, traced);
    if (!begin(fresh.width, fresh.height)) return;
    COHORT_CUDA(cudaEventRecord(events_[0], stream_));
    upload(fresh.rgba, frame_);
    if (options_.reproject || options_.atrous || traced.sparse()) {
      upload(g.depth, depth_);
      upload(g.normal, normal_);
    }
    if (options_.reproject) {
      upload(g.prev_depth, prev_depth_);
      upload(g.motion, motion_);
    }
    if (options_.reproject || traced.sparse()) upload(g.id, id_);
    // The history's moments read the albedo too (only with atrous); the reconstruction's weights read it.
    if (options_.atrous || traced.sparse()) upload(g.albedo, albedo_);
    COHORT_CUDA(cudaEventRecord(events_[1], stream_));
    run(fresh.width, fresh.height, traced, /*ycocgw_ready=*/false, /*geometry_ready=*/false);
  }

  // About 38 bytes a pixel cross the bus (RGB halves and 32-byte aux texels) instead of 76 in floats;
  // none for rows a CUDA tracer left on its GPU (`on_device`): those are copied device to device, or from
  // a peer GPU (over NVLink where the GPUs have it).
  void process_packed(const core::BandBuffer& packed, const std::vector<core::DeviceBandRows>& on_device,
                      const core::PathPattern& traced) override {
    const bool needs_aux = options_.reproject || options_.atrous || traced.sparse();
    if (needs_aux && !packed.has_aux())
      throw std::invalid_argument("CudaFramePost: the packed frame has no aux planes (render with aux outputs)");
    core::check_traced_pattern(options_, traced);
    const int width = packed.width(), height = packed.height();
    if (!begin(width, height)) return;
    const size_t pixels = size_t(width) * size_t(height);
    const size_t row_bytes = packed.row_bytes(), aux_row_bytes = size_t(width) * sizeof(KAuxTexel);
    COHORT_CUDA(cudaEventRecord(events_[0], stream_));
    unsigned char* colour = packed_colour_.scratch(packed.bytes());
    const bool aux = packed.has_aux();
    KAuxTexel* texels = aux ? packed_aux_.scratch(pixels) : nullptr;
    auto& host = const_cast<core::BandBuffer&>(packed);
    registered_.ensure(packed.row(0), packed.bytes(), "the packed frame's colour");
    if (aux) registered_.ensure(host.aux_row(0), packed.aux_bytes(), "the packed frame's aux texels");
    // Rows from the host: every range no device band covers.
    std::vector<core::DeviceBandRows> bands = on_device;
    std::sort(bands.begin(), bands.end(), [](const auto& a, const auto& b) { return a.row_begin < b.row_begin; });
    auto upload_rows = [&](int from, int to) {
      if (to <= from) return;
      const size_t rows = size_t(to - from);
      COHORT_CUDA(cudaMemcpyAsync(colour + size_t(from) * row_bytes, packed.row(from), rows * row_bytes,
                                  cudaMemcpyHostToDevice, stream_));
      if (aux)
        COHORT_CUDA(cudaMemcpyAsync(texels + size_t(from) * width, host.aux_row(from), rows * aux_row_bytes,
                                    cudaMemcpyHostToDevice, stream_));
    };
    int row = 0;
    for (const core::DeviceBandRows& b : bands) {
      if (b.row_begin < row || b.row_end > height || b.row_end < b.row_begin || !b.band.colour || (aux && !b.band.aux))
        throw std::invalid_argument("CudaFramePost: a band on a GPU overlaps another, lies outside the frame or has no aux texels");
      upload_rows(row, b.row_begin);
      const size_t rows = size_t(b.row_end - b.row_begin);
      copy_from_device(colour + size_t(b.row_begin) * row_bytes, b.band.colour, rows * row_bytes, b.band.cuda_device);
      if (aux) copy_from_device(texels + size_t(b.row_begin) * width, b.band.aux, rows * aux_row_bytes, b.band.cuda_device);
      row = b.row_end;
    }
    upload_rows(row, height);
    COHORT_CUDA(cudaEventRecord(events_[1], stream_));
    // A sparse frame's YCoCg planes are those of its reconstruction, made after the unpack.
    float* ycocgw = options_.reproject && !traced.sparse() && aux ? ycocgw_.scratch(4 * pixels) : nullptr;
    float* geometry = options_.atrous && aux ? geometry_.scratch(4 * pixels) : nullptr;
    unpack_kernel<<<blocks_for(pixels), kThreads, 0, stream_>>>(
        colour, packed.format() == core::BandFormat::rgb16f ? 1 : packed.format() == core::BandFormat::rgb9e5 ? 2 : 0, texels, frame_.scratch(4 * pixels),
        depth_.scratch(pixels), prev_depth_.scratch(pixels), motion_.scratch(2 * pixels), normal_.scratch(3 * pixels),
        albedo_.scratch(3 * pixels), id_.scratch(pixels), ycocgw, geometry, static_cast<int>(pixels));
    COHORT_CUDA(cudaGetLastError());
    run(width, height, traced, /*ycocgw_ready=*/ycocgw != nullptr, /*geometry_ready=*/geometry != nullptr);
  }

  int cuda_device() const override { return device_; }

 private:
  // A band's bytes from a tracer's GPU: on this one device to device; from another through peer access
  // (enabled once where the pair has it; without it the driver stages through the host).
  void copy_from_device(void* to, const void* from, size_t bytes, int from_device) {
    if (from_device == device_) {
      COHORT_CUDA(cudaMemcpyAsync(to, from, bytes, cudaMemcpyDeviceToDevice, stream_));
      return;
    }
    if (peers_.insert(from_device).second) {
      int can = 0;
      COHORT_CUDA(cudaDeviceCanAccessPeer(&can, device_, from_device));
      if (can) {
        const cudaError_t e = cudaDeviceEnablePeerAccess(from_device, 0);
        if (e != cudaSuccess && e != cudaErrorPeerAccessAlreadyEnabled) COHORT_CUDA(e);
        cudaGetLastError();
      }
    }
    COHORT_CUDA(cudaMemcpyPeerAsync(to, device_, from, from_device, bytes, stream_));
  }

  // Starts a frame on the device; false when there is nothing to do (an empty frame).
  bool begin(int width, int height) {
    COHORT_CUDA(cudaSetDevice(device_));
    if (width != width_ || height != height_) {
      width_ = width, height_ = height;
      have_history_ = false;
      have_blend_ = false;
    }
    return width > 0 && height > 0;
  }

  // The passes over the device planes, then the shown image back to the host. `ycocgw_ready`,
  // `geometry_ready`: the unpack kernel already wrote the YCoCg frame and the packed geometry.
  void run(int width, int height, const core::PathPattern& traced, bool ycocgw_ready, bool geometry_ready) {
    const size_t pixels = static_cast<size_t>(width) * static_cast<size_t>(height);
    float* fresh = frame_.data();
    if (traced.sparse()) fresh = reconstruct(width, height, traced);
    float* current = fresh;
    mean_length_ = 1.0;
    if (options_.reproject) {
      State& from = state_[parity_];
      State& to = state_[parity_ ^ 1];
      for (State* s : {&from, &to}) s->resize(pixels, options_.reprojection.luminance_moments);
      const KReprojectParams params = core::reproject_params(options_.reprojection, width, height, have_history_);
      float* ycocgw = ycocgw_.scratch(4 * pixels);
      if (!ycocgw_ready)
        prepare_kernel<<<blocks_for(pixels), kThreads, 0, stream_>>>(fresh, ycocgw, static_cast<int>(pixels));
      const KReprojectFresh planes{fresh, ycocgw,      depth_.data(), prev_depth_.data(),
                                   motion_.data(), normal_.data(), id_.data(),    albedo_.data()};
      const KReprojectHistory history{from.rgba.data(), from.length.data(), from.depth.data(), from.normal.data(),
                                      from.id.data(),   from.moments.data()};
      const KReprojectState next{to.rgba.data(), to.length.data(), to.depth.data(), to.normal.data(), to.id.data(),
                                 to.moments.data()};
      double* sum = length_sum_.scratch(1);
      COHORT_CUDA(cudaMemsetAsync(sum, 0, sizeof(double), stream_));
      // The a-trous filter's demodulated input comes out of the reprojection kernel.
      float* demodulated = options_.atrous ? ping_.scratch(4 * pixels) : nullptr;
      reproject_kernel<<<blocks_for(pixels), kThreads, 0, stream_>>>(params, planes, history, next, sum, albedo_.data(),
                                                                     demodulated);
      COHORT_CUDA(cudaGetLastError());
      COHORT_CUDA(cudaMemcpyAsync(length_sum_host_, sum, sizeof(double), cudaMemcpyDeviceToHost, stream_));
      parity_ ^= 1;
      have_history_ = true;
      current = to.rgba.data();
    }
    if (options_.blend) {
      float* accumulated = blended_.scratch(4 * pixels);
      if (!have_blend_ || blend_factor_ >= 1.0)
        COHORT_CUDA(cudaMemcpyAsync(accumulated, current, 4 * pixels * sizeof(float), cudaMemcpyDeviceToDevice, stream_));
      else
        brigade_blend_kernel<<<blocks_for(pixels), kThreads, 0, stream_>>>(
            accumulated, current, static_cast<float>(blend_factor_), static_cast<int>(pixels));
      COHORT_CUDA(cudaGetLastError());
      have_blend_ = true;
      current = accumulated;
    }
    if (options_.atrous) {
      float* ping = ping_.scratch(4 * pixels);
      float* pong = pong_.scratch(4 * pixels);
      if (!options_.reproject)
        modulate_kernel<<<blocks_for(pixels), kThreads, 0, stream_>>>(current, albedo_.data(), ping,
                                                                         static_cast<int>(pixels), 0);
      const core::AtrousOptions& ao = options_.atrous_options;
      const bool variance = core::atrous_guide_uses_variance(ao.guide);
      KAtrousParams params{};
      params.width = width, params.height = height;
      params.normal_squarings = normal_squarings_;
      params.depth_sigma = ao.depth_sigma;
      params.color_sigma = variance ? ao.variance_sigma : ao.color_sigma;
      float* geometry = geometry_.scratch(4 * pixels);
      if (!geometry_ready)
        pack_geometry_kernel<<<blocks_for(pixels), kThreads, 0, stream_>>>(depth_.data(), normal_.data(), geometry,
                                                                            static_cast<int>(pixels));
      if (ao.firefly_factor > 0.0f) {
        firefly_kernel<<<tile_grid(width, height), kTile, 0, stream_>>>(ping, pong, width, height, ao.firefly_factor);
        std::swap(ping, pong);
      }
      if (variance) {
        KSvgfVarianceParams v{};
        v.width = width, v.height = height, v.normal_squarings = normal_squarings_;
        v.have_history = options_.reproject ? 1 : 0;
        v.depth_sigma = ao.depth_sigma;
        v.short_history = ao.short_history;
        v.of_mean = ao.guide == core::AtrousGuide::variance_of_mean ? 1 : 0;
        const State& history = state_[parity_];  // the state the reprojection just wrote
        svgf_variance_kernel<<<tile_grid(width, height), kTile, 0, stream_>>>(
            ping, options_.reproject ? history.moments.data() : nullptr,
            options_.reproject ? history.length.data() : nullptr, geometry, v);
      }
      if (options_.reproject && ao.history_fix_frames > 0.0f) {
        const KHistoryFixParams fix = core::history_fix_params(ao, width, height, variance);
        history_fix_kernel<<<tile_grid(width, height), kTile, 0, stream_>>>(
            ping, pong, geometry, id_.data(), state_[parity_].length.data(), fix);
        std::swap(ping, pong);
      }
      float* shown = shown_device_.scratch(4 * pixels);
      const int passes = std::max(ao.passes, 0);
      bool modulated = false;  // the last SVGF pass multiplies by the albedo itself
      for (int pass = 0; pass < passes; ++pass) {
        params.step = 1 << pass;
        const bool last = pass + 1 == passes;
        if (variance) {
          svgf_atrous_kernel<<<tile_grid(width, height), kTile, 0, stream_>>>(ping, pong, geometry, params, albedo_.data(),
                                                                              last ? shown : nullptr);
          modulated = last;
        } else {
          atrous_kernel<<<tile_grid(width, height), kTile, 0, stream_>>>(ping, pong, geometry, params);
        }
        std::swap(ping, pong);
      }
      if (!modulated)
        modulate_kernel<<<blocks_for(pixels), kThreads, 0, stream_>>>(ping, albedo_.data(), shown,
                                                                         static_cast<int>(pixels), 1);
      COHORT_CUDA(cudaGetLastError());
      current = shown;
    }
    if (shown_.width != width || shown_.height != height) {
      if (shown_registered_) cudaHostUnregister(shown_registered_);
      shown_registered_ = nullptr;
      shown_.resize(width, height);
      if (cudaHostRegister(shown_.rgba.data(), shown_.rgba.size() * sizeof(float), cudaHostRegisterPortable) ==
          cudaSuccess)
        shown_registered_ = shown_.rgba.data();
      else
        cudaGetLastError();
    }
    COHORT_CUDA(cudaEventRecord(events_[2], stream_));
    COHORT_CUDA(cudaMemcpyAsync(shown_.rgba.data(), current, 4 * pixels * sizeof(float), cudaMemcpyDeviceToHost,
                                stream_));
    COHORT_CUDA(cudaEventRecord(events_[3], stream_));
    COHORT_CUDA(cudaStreamSynchronize(stream_));
    float ms[3] = {0, 0, 0};
    for (int i = 0; i < 3; ++i) COHORT_CUDA(cudaEventElapsedTime(&ms[i], events_[i], events_[i + 1]));
    times_ = {true, ms[0], ms[1], ms[2]};
    if (options_.reproject) mean_length_ = *length_sum_host_ / static_cast<double>(pixels);
  }

  // The sparse frame in frame_ filled from its traced pixels (kernel/upsample.h); returns the full frame.
  float* reconstruct(int width, int height, const core::PathPattern& traced) {
    const size_t pixels = static_cast<size_t>(width) * static_cast<size_t>(height);
    const KUpsampleParams params = k_upsample_params(width, height, traced.pixels, traced.phase);
    float* full = reconstructed_.scratch(4 * pixels);
    const float* illumination = frame_.data();  // nearest reads the colour only
    if (options_.upsample == core::UpsampleMethod::joint_bilateral) {
      float* demodulated = illumination_.scratch(4 * pixels);
      upsample_demodulate_kernel<<<tile_grid(width, height), kTile, 0, stream_>>>(frame_.data(), albedo_.data(),
                                                                                  demodulated, params);
      illumination = demodulated;
    }
    const int method = options_.upsample == core::UpsampleMethod::nearest ? K_UPSAMPLE_NEAREST : K_UPSAMPLE_JOINT_BILATERAL;
    upsample_kernel<<<tile_grid(width, height), kTile, 0, stream_>>>(frame_.data(), illumination, depth_.data(),
                                                                     normal_.data(), albedo_.data(), id_.data(), full,
                                                                     params, method);
    COHORT_CUDA(cudaGetLastError());
    return full;
  }

 public:
  const core::FrameBuffer& image() const override { return shown_; }
  double mean_history_length() const override { return mean_length_; }
  void reset() override { have_history_ = false, have_blend_ = false; }
  std::string where() const override { return "cuda:" + std::to_string(device_); }
  core::FramePostDeviceTimes device_times() const override { return times_; }

 private:
  // One frame's history on the device (kernel/reproject.h's state).
  struct State {
    DeviceArray<float> rgba, length, depth, normal, moments;
    DeviceArray<kuint> id;
    void resize(size_t pixels, bool with_moments) {
      rgba.scratch(4 * pixels);
      if (with_moments) moments.scratch(2 * pixels);
      length.scratch(pixels);
      depth.scratch(pixels);
      normal.scratch(3 * pixels);
      id.scratch(pixels);
    }
  };
  // Host planes are page-locked where the driver lets us (a true asynchronous DMA at full bus speed);
  // the callers keep their planes between frames, so the registrations are cached.
  template <class T>
  void upload(const std::vector<T>& host, DeviceArray<T>& device) {
    registered_.ensure(host.data(), host.size() * sizeof(T), "a G-buffer plane");
    T* d = device.scratch(host.size());
    COHORT_CUDA(cudaMemcpyAsync(d, host.data(), host.size() * sizeof(T), cudaMemcpyHostToDevice, stream_));
  }
  static constexpr size_t kRegistrations = 24;  // two frames' worth of planes (the pipeline alternates)
  int device_;
  core::FramePostOptions options_;
  cudaStream_t stream_ = nullptr;
  int width_ = 0, height_ = 0;
  bool have_history_ = false;
  bool have_blend_ = false;  // blended_ holds an accumulated image of this size
  int parity_ = 0;
  int normal_squarings_ = 0;
  State state_[2];
  DeviceArray<float> frame_, depth_, prev_depth_, motion_, normal_, albedo_, ycocgw_, ping_, pong_, shown_device_;
  DeviceArray<float> reconstructed_, illumination_;  // a sparse frame filled, and its traced pixels' illumination
  DeviceArray<float> geometry_;  // normal and depth packed for the a-trous passes (kernel/atrous.h)
  DeviceArray<float> blended_;   // Brigade's accumulated image (options.blend)
  DeviceArray<kuint> id_;
  DeviceArray<unsigned char> packed_colour_;
  DeviceArray<KAuxTexel> packed_aux_;
  DeviceArray<double> length_sum_;
  double* length_sum_host_ = nullptr;
  double mean_length_ = 1.0;
  cudaEvent_t events_[4] = {};  // before the uploads, the passes, the download; after it
  core::FramePostDeviceTimes times_;
  core::FrameBuffer shown_;
  void* shown_registered_ = nullptr;
  HostRegistrations registered_{kRegistrations};
  std::set<int> peers_;  // devices whose bands were copied here (peer access tried once)
};

}  // namespace

std::unique_ptr<core::FramePost> make_cuda_frame_post(int device, const core::FramePostOptions& options) {
  return std::make_unique<CudaFramePost>(device, options);
}

}  // namespace cohort::tracers
