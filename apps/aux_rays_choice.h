// `--aux-rays`: the names the command line takes, `auto` (tracers::auto_aux_rays picks by the tracers)
// before the modes core::aux_rays_mode knows.
#pragma once

#include <string>
#include <vector>

#include "cohort/core/frame_defaults.h"
#include "cohort/tracers/tracer_registry.h"

namespace cohort::app {

// KFrameParams.aux_outputs for `--aux-rays` (`cohort render` and `cohort play`). `auto` with Open Image Denoise
// (`--denoise oidn|oidn-cuda`): centre rays, whatever the tracers. Their planes are noise-free, so OIDN takes
// them as clean guides (cleanAux); on the test map's scenario at 320x180 (Embree, 64-spp references) that
// gave mean FLIP 0.086 against 0.091 from first hits and 0.095 with no guides (docs/denoising.md). The extra
// ray is small beside OIDN's own milliseconds. Otherwise `auto` is tracers::auto_aux_rays's pick.
inline kuint resolve_aux_rays(const std::string& aux_rays, const std::string& denoise,
                              const std::vector<tracers::TracerSpec>& tracers) {
  if (aux_rays == "auto" && (denoise == "oidn" || denoise == "oidn-cuda")) return K_AUX_CENTRE_RAY;
  return core::aux_rays_mode(aux_rays == "auto" ? tracers::auto_aux_rays(tracers) : aux_rays);
}

inline std::vector<std::string> aux_rays_choices() {
  std::vector<std::string> names = {"auto"};
  for (const std::string& name : core::aux_rays_names()) names.push_back(name);
  return names;
}

}  // namespace cohort::app
