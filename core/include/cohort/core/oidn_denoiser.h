// Intel Open Image Denoise as the high-quality spatial denoiser of the merged HDR frame (it runs after the
// bands are merged, so band boundaries cannot show). The library is optional and loaded at run time:
// tools/fetch_oidn.sh puts its prebuilt libraries (PyPI's pyoidn wheel) in third_party/oidn/lib, and the
// few C entry points used are declared in the .cpp rather than taken from OIDN's headers.
//
// Where the library is looked for, in order: $COHORT_OIDN_LIBRARY (a file), $COHORT_OIDN_DIR (a folder),
// the folder tools/fetch_oidn.sh filled when Cohort was configured, then the system's library path.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "cohort/core/frame_buffer.h"

namespace cohort::core {

enum class OidnDevice { kCpu, kCuda };
// OIDN's filter quality: high for offline frames, fast for interactive ones (several times quicker).
enum class OidnQuality { kHigh, kBalanced, kFast };

// Parse "high", "balanced", "fast"; throws std::invalid_argument naming the accepted values.
OidnQuality parse_oidn_quality(const std::string& name);
// Parses "cpu" or "cuda"; throws std::invalid_argument naming the accepted values.
OidnDevice parse_oidn_device(const std::string& name);
const char* oidn_device_name(OidnDevice device);

// Optional guide planes for the denoiser, 3 floats a pixel for each of the colour's pixels (GBuffer's
// layout): albedo in [0, 1], world normals in [-1, 1].
struct DenoiseGuides {
  const std::vector<float>* albedo = nullptr;
  const std::vector<float>* normal = nullptr;
  // The guides hold no noise (one ray through each pixel's centre, the same every frame): OIDN's cleanAux.
  bool clean = false;
};

class OidnDenoiser {
 public:
  // Loads the library and creates a committed device. Throws std::runtime_error saying what was tried
  // and why it failed (library not found, device not supported, ...).
  static std::unique_ptr<OidnDenoiser> open(OidnDevice device = OidnDevice::kCpu,
                                            OidnQuality quality = OidnQuality::kHigh);
  // True when the library can be loaded (the device is not checked); `where` gets the path or the reasons.
  static bool library_available(std::string* where = nullptr);

  ~OidnDenoiser();
  OidnDenoiser(const OidnDenoiser&) = delete;
  OidnDenoiser& operator=(const OidnDenoiser&) = delete;

  // Denoises the RGB of `color` (linear HDR) into `out` (resized; alpha copied). `out` may be `color`.
  // The images go to the filter as half floats: colour clamped to [0, 65504], a NaN read as 0.
  // Throws std::runtime_error with OIDN's message when the filter fails.
  void denoise(const FrameBuffer& color, FrameBuffer& out, const DenoiseGuides& guides = {});

  OidnDevice device() const { return device_; }
  const std::string& library_path() const;

 private:
  struct Impl;
  explicit OidnDenoiser(std::unique_ptr<Impl> impl, OidnDevice device);
  std::unique_ptr<Impl> impl_;
  OidnDevice device_;
};

}  // namespace cohort::core
