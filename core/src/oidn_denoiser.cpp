#include "cohort/core/oidn_denoiser.h"

#include <dlfcn.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <stdexcept>
#include <vector>

#include <spdlog/spdlog.h>

#include "cohort/core/half_float.h"
#include "cohort/core/host_threads.h"

namespace cohort::core {
namespace {

// The part of OIDN's C API (oidn.h, version 2) that Cohort calls. Handles are opaque pointers; the enum
// values are the library's ABI.
using OIDNDevice = struct OIDNDeviceImpl*;
using OIDNBuffer = struct OIDNBufferImpl*;
using OIDNFilter = struct OIDNFilterImpl*;
constexpr int kOidnDeviceTypeCpu = 1;
constexpr int kOidnDeviceTypeCuda = 3;
constexpr int kOidnFormatHalf3 = 259;
constexpr int kOidnStorageHost = 1, kOidnStorageDevice = 2;
constexpr int kOidnErrorNone = 0;
constexpr int kOidnQualityFast = 4, kOidnQualityBalanced = 5, kOidnQualityHigh = 6;

struct OidnApi {
  std::string path;
  OIDNDevice (*new_device)(int type);
  void (*commit_device)(OIDNDevice);
  void (*release_device)(OIDNDevice);
  int (*get_device_error)(OIDNDevice, const char**);
  OIDNBuffer (*new_buffer_with_storage)(OIDNDevice, size_t, int storage);
  void* (*get_buffer_data)(OIDNBuffer);
  void (*release_buffer)(OIDNBuffer);
  void (*write_buffer)(OIDNBuffer, size_t, size_t, const void*);
  void (*read_buffer)(OIDNBuffer, size_t, size_t, void*);
  OIDNFilter (*new_filter)(OIDNDevice, const char*);
  void (*release_filter)(OIDNFilter);
  void (*set_filter_image)(OIDNFilter, const char*, OIDNBuffer, int, size_t, size_t, size_t, size_t, size_t);
  void (*set_filter_bool)(OIDNFilter, const char*, bool);
  void (*set_filter_int)(OIDNFilter, const char*, int);
  void (*commit_filter)(OIDNFilter);
  void (*execute_filter)(OIDNFilter);
};

std::vector<std::string> candidate_paths() {
  std::vector<std::string> paths;
  if (const char* file = std::getenv("COHORT_OIDN_LIBRARY"); file && *file) paths.emplace_back(file);
  if (const char* dir = std::getenv("COHORT_OIDN_DIR"); dir && *dir)
    paths.push_back((std::filesystem::path(dir) / "libOpenImageDenoise.so.2").string());
#ifdef COHORT_OIDN_DEFAULT_DIR
  paths.push_back((std::filesystem::path(COHORT_OIDN_DEFAULT_DIR) / "libOpenImageDenoise.so.2").string());
#endif
  paths.emplace_back("libOpenImageDenoise.so.2");  // the system's library path
  return paths;
}

template <typename Fn>
void bind(void* lib, const char* name, Fn& fn, std::string& missing) {
  fn = reinterpret_cast<Fn>(dlsym(lib, name));
  if (!fn) missing += std::string(missing.empty() ? "" : ", ") + name;
}

// Loads the library once per process and keeps it loaded (its thread pools outlive any one denoiser).
const OidnApi* load_api(std::string* failure) {
  static std::mutex mutex;
  static std::unique_ptr<OidnApi> api;
  static std::string reasons;
  std::lock_guard<std::mutex> lock(mutex);
  if (api) return api.get();
  reasons.clear();
  for (const std::string& path : candidate_paths()) {
    void* lib = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!lib) {
      const char* err = dlerror();
      reasons += "\n  " + path + ": " + (err ? err : "not loadable");
      continue;
    }
    auto loaded = std::make_unique<OidnApi>();
    loaded->path = path;
    std::string missing;
    bind(lib, "oidnNewDevice", loaded->new_device, missing);
    bind(lib, "oidnCommitDevice", loaded->commit_device, missing);
    bind(lib, "oidnReleaseDevice", loaded->release_device, missing);
    bind(lib, "oidnGetDeviceError", loaded->get_device_error, missing);
    bind(lib, "oidnNewBufferWithStorage", loaded->new_buffer_with_storage, missing);
    bind(lib, "oidnGetBufferData", loaded->get_buffer_data, missing);
    bind(lib, "oidnReleaseBuffer", loaded->release_buffer, missing);
    bind(lib, "oidnWriteBuffer", loaded->write_buffer, missing);
    bind(lib, "oidnReadBuffer", loaded->read_buffer, missing);
    bind(lib, "oidnNewFilter", loaded->new_filter, missing);
    bind(lib, "oidnReleaseFilter", loaded->release_filter, missing);
    bind(lib, "oidnSetFilterImage", loaded->set_filter_image, missing);
    bind(lib, "oidnSetFilterBool", loaded->set_filter_bool, missing);
    bind(lib, "oidnSetFilterInt", loaded->set_filter_int, missing);
    bind(lib, "oidnCommitFilter", loaded->commit_filter, missing);
    bind(lib, "oidnExecuteFilter", loaded->execute_filter, missing);
    if (!missing.empty()) {
      reasons += "\n  " + path + ": not Open Image Denoise 2 (missing " + missing + ")";
      dlclose(lib);
      continue;
    }
    api = std::move(loaded);
    return api.get();
  }
  if (failure) *failure = "Open Image Denoise not found (run tools/fetch_oidn.sh, or set COHORT_OIDN_DIR); tried:" + reasons;
  return nullptr;
}

size_t pixel_count(const FrameBuffer& f) { return static_cast<size_t>(f.width) * static_cast<size_t>(f.height); }

// The host's pool takes the per-pixel conversions in ranges of this many pixels.
constexpr size_t kPixelsPerRange = 16384;

// A colour channel as a half: clamped to the largest finite half (an infinity would spread over the
// filter's whole receptive field) and a NaN read as 0.
inline uint16_t colour_to_half(float v) { return float_to_half(std::min(65504.0f, std::max(0.0f, v))); }

}  // namespace

OidnQuality parse_oidn_quality(const std::string& name) {
  if (name == "high") return OidnQuality::kHigh;
  if (name == "balanced") return OidnQuality::kBalanced;
  if (name == "fast") return OidnQuality::kFast;
  throw std::invalid_argument("unknown denoiser quality '" + name + "' (expected high, balanced or fast)");
}

OidnDevice parse_oidn_device(const std::string& name) {
  if (name == "cpu") return OidnDevice::kCpu;
  if (name == "cuda") return OidnDevice::kCuda;
  throw std::invalid_argument("unknown denoiser device '" + name + "' (expected cpu or cuda)");
}

const char* oidn_device_name(OidnDevice device) { return device == OidnDevice::kCuda ? "cuda" : "cpu"; }

struct OidnDenoiser::Impl {
  const OidnApi* api = nullptr;
  OIDNDevice device = nullptr;
  int quality = kOidnQualityHigh;
  OIDNFilter filter = nullptr;
  // Half-float RGB images in the host's memory (page-locked by OIDN for a GPU device), filled and read by
  // the host's threads. A CPU device filters them where they are; a GPU device gets copies in its own
  // memory (`on_device`), moved by DMA from the page-locked images. (Pageable float images copied by OIDN
  // took 10 ms of a 720p frame on an H100, these 4.7-5.7; the filter reading the host's images across the
  // bus itself was no faster: 5.2-5.4 ms, and 11.3-11.8 against 9.8-10.1 ms at 1080p.)
  struct Image {
    OIDNBuffer host = nullptr, device = nullptr;
    uint16_t* data = nullptr;
    OIDNBuffer filtered() const { return device ? device : host; }
  };
  Image color, albedo, normal, output;
  bool on_device = false;
  size_t image_bytes = 0;
  int width = 0, height = 0;
  bool with_albedo = false, with_normal = false, clean_aux = false;

  void check(const char* what) const {
    const char* message = nullptr;
    if (api->get_device_error(device, &message) != kOidnErrorNone)
      throw std::runtime_error(std::string("Open Image Denoise: ") + what + ": " + (message ? message : "unknown error"));
  }

  void release_buffers() {
    for (Image* image : {&color, &albedo, &normal, &output}) {
      for (OIDNBuffer b : {image->host, image->device})
        if (b) api->release_buffer(b);
      *image = Image{};
    }
  }

  Image new_image() {
    Image image;
    image.host = api->new_buffer_with_storage(device, image_bytes, kOidnStorageHost);
    check("allocating an image in host memory");
    image.data = static_cast<uint16_t*>(api->get_buffer_data(image.host));
    if (on_device) {
      image.device = api->new_buffer_with_storage(device, image_bytes, kOidnStorageDevice);
      check("allocating an image in device memory");
    }
    return image;
  }

  void to_device(const Image& image) const {
    if (image.device) api->write_buffer(image.device, 0, image_bytes, image.data);
  }

  // (Re)creates buffers and the filter when the size or the set of guide images changes: filter setup is
  // expensive, so it is done once per configuration, not per frame.
  void configure(int w, int h, bool use_albedo, bool use_normal, bool clean) {
    if (filter && w == width && h == height && use_albedo == with_albedo && use_normal == with_normal &&
        clean == clean_aux)
      return;
    if (filter) api->release_filter(filter);
    filter = nullptr;
    release_buffers();
    width = height = 0;
    image_bytes = static_cast<size_t>(w) * static_cast<size_t>(h) * 3 * sizeof(uint16_t);
    color = new_image();
    output = new_image();
    if (use_albedo) albedo = new_image();
    if (use_normal) normal = new_image();
    filter = api->new_filter(device, "RT");
    api->set_filter_image(filter, "color", color.filtered(), kOidnFormatHalf3, w, h, 0, 0, 0);
    if (use_albedo) api->set_filter_image(filter, "albedo", albedo.filtered(), kOidnFormatHalf3, w, h, 0, 0, 0);
    if (use_normal) api->set_filter_image(filter, "normal", normal.filtered(), kOidnFormatHalf3, w, h, 0, 0, 0);
    api->set_filter_image(filter, "output", output.filtered(), kOidnFormatHalf3, w, h, 0, 0, 0);
    api->set_filter_bool(filter, "hdr", true);
    if (use_albedo) api->set_filter_bool(filter, "cleanAux", clean);
    api->set_filter_int(filter, "quality", quality);
    api->commit_filter(filter);
    check("creating the RT filter");
    width = w;
    height = h;
    with_albedo = use_albedo;
    with_normal = use_normal;
    clean_aux = clean;
  }

  ~Impl() {
    if (!api) return;
    if (filter) api->release_filter(filter);
    release_buffers();
    if (device) api->release_device(device);
  }
};

bool OidnDenoiser::library_available(std::string* where) {
  std::string failure;
  const OidnApi* api = load_api(&failure);
  if (where) *where = api ? api->path : failure;
  return api != nullptr;
}

std::unique_ptr<OidnDenoiser> OidnDenoiser::open(OidnDevice device, OidnQuality quality) {
  std::string failure;
  const OidnApi* api = load_api(&failure);
  if (!api) throw std::runtime_error(failure);
  auto impl = std::make_unique<Impl>();
  impl->api = api;
  impl->quality = quality == OidnQuality::kFast       ? kOidnQualityFast
                  : quality == OidnQuality::kBalanced ? kOidnQualityBalanced
                                                      : kOidnQualityHigh;
  impl->on_device = device == OidnDevice::kCuda;
  impl->device = api->new_device(device == OidnDevice::kCuda ? kOidnDeviceTypeCuda : kOidnDeviceTypeCpu);
  if (!impl->device) {
    const char* message = nullptr;
    api->get_device_error(nullptr, &message);
    throw std::runtime_error(std::string("Open Image Denoise (") + api->path + "): no " + oidn_device_name(device) +
                             " device: " + (message ? message : "unsupported"));
  }
  api->commit_device(impl->device);
  impl->check("committing the device");
  return std::unique_ptr<OidnDenoiser>(new OidnDenoiser(std::move(impl), device));
}

OidnDenoiser::OidnDenoiser(std::unique_ptr<Impl> impl, OidnDevice device) : impl_(std::move(impl)), device_(device) {}
OidnDenoiser::~OidnDenoiser() = default;

const std::string& OidnDenoiser::library_path() const { return impl_->api->path; }

void OidnDenoiser::denoise(const FrameBuffer& color, FrameBuffer& out, const DenoiseGuides& guides) {
  if (color.width <= 0 || color.height <= 0) throw std::invalid_argument("denoise: empty image");
  const size_t n = pixel_count(color);
  auto same_size = [&](const std::vector<float>* g) { return g && g->size() == 3 * n; };
  if ((guides.albedo && !same_size(guides.albedo)) || (guides.normal && !same_size(guides.normal)))
    throw std::invalid_argument("denoise: guide planes must hold 3 floats for each of the colour image's pixels");
  // OIDN accepts a normal guide only together with an albedo guide.
  const bool use_albedo = guides.albedo != nullptr;
  const bool use_normal = use_albedo && guides.normal != nullptr;
  Impl& m = *impl_;
  m.configure(color.width, color.height, use_albedo, use_normal, use_albedo && guides.clean);
  using Clock = std::chrono::steady_clock;
  const Clock::time_point started = Clock::now();
  HostThreads& threads = HostThreads::shared();
  threads.for_ranges(n, kPixelsPerRange, [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i)
      for (size_t c = 0; c < 3; ++c) m.color.data[i * 3 + c] = colour_to_half(color.rgba[i * 4 + c]);
    if (use_albedo)
      for (size_t i = 3 * begin; i < 3 * end; ++i) m.albedo.data[i] = float_to_half((*guides.albedo)[i]);
    if (use_normal)
      for (size_t i = 3 * begin; i < 3 * end; ++i) m.normal.data[i] = float_to_half((*guides.normal)[i]);
  });
  const Clock::time_point packed = Clock::now();
  for (const Impl::Image* image : {&m.color, &m.albedo, &m.normal}) m.to_device(*image);
  m.check("copying the images to the device");
  const Clock::time_point uploaded = Clock::now();
  m.api->execute_filter(m.filter);
  m.check("denoising");
  const Clock::time_point filtered = Clock::now();
  if (m.output.device) m.api->read_buffer(m.output.device, 0, m.image_bytes, m.output.data);
  m.check("reading the result");
  const Clock::time_point read = Clock::now();

  if (&out != &color) {
    out.width = color.width;
    out.height = color.height;
    out.rgba.resize(color.rgba.size());
  }
  threads.for_ranges(n, kPixelsPerRange, [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) {
      for (size_t c = 0; c < 3; ++c) out.rgba[i * 4 + c] = half_to_float(m.output.data[i * 3 + c]);
      out.rgba[i * 4 + 3] = color.rgba[i * 4 + 3];
    }
  });
  if (spdlog::should_log(spdlog::level::debug)) {
    const auto ms = [](Clock::time_point a, Clock::time_point b) {
      return std::chrono::duration<double, std::milli>(b - a).count();
    };
    spdlog::debug("oidn ({}x{}, {}): pack {:.3f} ms, to the device {:.3f}, filter {:.3f}, back {:.3f}, unpack {:.3f}",
                  color.width, color.height,
                  !use_albedo ? "no guides" : use_normal ? (m.clean_aux ? "clean albedo and normal guides" : "albedo and normal guides")
                                                         : "albedo guide",
                  ms(started, packed), ms(packed, uploaded), ms(uploaded, filtered), ms(filtered, read),
                  ms(read, Clock::now()));
  }
}

}  // namespace cohort::core
