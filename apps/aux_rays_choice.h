// `--aux-rays`: the names the command line takes, `auto` (tracers::auto_aux_rays picks by the tracers)
// before the modes core::aux_rays_mode knows.
#pragma once

#include <string>
#include <vector>

#include "cohort/core/frame_defaults.h"

namespace cohort::app {

// `--aux-rays auto` with Open Image Denoise (`--denoise oidn|oidn-cuda`): centre rays, whatever the tracers.
// Their planes are noise-free, so OIDN takes them as clean guides (cleanAux); on the test map's scenario at
// 320x180 (Embree, 64-spp references) that gave mean FLIP 0.086 against 0.091 from first hits and 0.095
// with no guides (docs/denoising.md). The extra ray is small beside OIDN's own milliseconds.
inline bool oidn_wants_centre_rays(const std::string& aux_rays, const std::string& denoise) {
  return aux_rays == "auto" && (denoise == "oidn" || denoise == "oidn-cuda");
}

inline std::vector<std::string> aux_rays_choices() {
  std::vector<std::string> names = {"auto"};
  for (const std::string& name : core::aux_rays_names()) names.push_back(name);
  return names;
}

}  // namespace cohort::app
