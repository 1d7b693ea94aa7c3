// `--aux-rays`: the names the command line takes, `auto` (tracers::auto_aux_rays picks by the tracers)
// before the modes core::aux_rays_mode knows.
#pragma once

#include <string>
#include <vector>

#include "cohort/core/frame_defaults.h"

namespace cohort::app {

inline std::vector<std::string> aux_rays_choices() {
  std::vector<std::string> names = {"auto"};
  for (const std::string& name : core::aux_rays_names()) names.push_back(name);
  return names;
}

}  // namespace cohort::app
